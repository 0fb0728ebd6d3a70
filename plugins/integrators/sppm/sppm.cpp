// Integrator "sppm": stochastic progressive photon mapping (Hachisuka and Jensen 2009, after pbrt's
// SPPMIntegrator). Each iteration traces one camera path per pixel to a visible point (adding the
// emitted and direct light it sees), builds a hashed grid over the visible points, shoots photons from
// the lights (chosen by power) and credits each photon to the visible points within their radius,
// then shrinks every pixel's radius. Light that only photons can carry well (caustics seen through
// glass: specular-diffuse-specular paths) converges where path tracing cannot sample it.
//
// | parameter                   | default | meaning                                                |
// |-----------------------------|---------|--------------------------------------------------------|
// | integer maxdepth            | 5       | longest path in bounces, camera and photon parts together |
// | integer photonsperiteration | -1      | photons per iteration; -1: one per pixel, at most 262,144 |
// | float radius                | 0       | initial gather radius, world units; 0: from the pixel footprint |
// | integer seed                | 0       | photon random streams (the sampler's seed drives the camera side) |
// | float alpha                 | 2/3     | fraction of each iteration's photons kept in the count |
//
// Iterations are the sampler's pixel samples (--spp), rendered by the core's loop one per pass: the
// camera pass is the loop's pixel samples, the photon pass runs after it (end_pass). With --time the
// photon pass stops within one batch of photons once the budget is spent (the estimate divides by
// the photons actually emitted), and an iteration whose camera pass was cut is dropped.
// Without a "radius", the initial radius is two pixel footprints at the median visible point of the
// first iteration (docs/sppm.md); a given radius is used as it is, as pbrt-v4 does. An SPPM estimate is not a mean of per-iteration samples,
// so it cannot be accumulated in the film pass by pass: it goes to the film once, at the end, and a
// snapshot after an iteration asks the integrator for the current estimate instead.
//
// Spectral renders (docs/spectral.md): as in pbrt-v4, one set of wavelengths per iteration, shared
// by every camera path and photon of it (the loop's per-pass wavelengths), so a photon's flux and a
// visible point's throughput are values at the same wavelengths; the iteration's camera-side light
// and photon sums are turned into RGB when the iteration ends.
//
// Depth: a photon gathered at a visible point found after d camera bounces has made at most
// maxdepth - 1 - d bounces, so the image converges to exactly what "path" renders with the same
// maxdepth (pbrt lets photons add up to maxdepth - 1 bounces whatever d is).
//
// Memory per pixel: visible point 80 B, its position and gather radius 16 B, statistics 64 B,
// photon accumulator 32 B and gather point 72 B (both in the grid's slot order), plus the grid: a
// 16 B slot (position and radius), a 4 B point index, 4 B of bucket during the build and 4 to 8 B
// of buckets. About 290 to 300 B in all; photons are never stored. Deterministic: a fixed seed gives the same
// image bit for bit, whatever the number of threads (see PhotonAccumulator).
#include "camera_pass.h"
#include "photon_tracer.h"
#include "visible_point_grid.h"

#include <penumbra/integrator.h>
#include <penumbra/memory.h>
#include <penumbra/plugin.h>

#include <fmt/core.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <memory>
#include <vector>

namespace {

using namespace penumbra;
using namespace penumbra::sppm;

// The initial radius when the scene gives none: kFootprints pixel footprints (the distance between
// the rays of neighbouring pixels, at the camera path's length) at the median visible point of the
// first iteration. Small enough that the first iterations do not blur; wide enough that a pixel's
// disk gathers photons from the start.
constexpr float kFootprints = 2.f;
// Photons per iteration by default: one per pixel, up to this many, so iterations stay short at any
// resolution.
constexpr uint64_t kDefaultMaxPhotons = uint64_t{1} << 18;
// Photons traced between two looks at the time budget (a photon that lands among many visible
// points, as with a radius near the scene size, can take a millisecond).
constexpr uint64_t kPhotonBatch = 16;
// Visible points a photon hit collects (and prefetches) before it deposits into them.
constexpr int kGatherBatch = 64;
// Slots ahead whose visible point build_gather_points() prefetches.
constexpr size_t kGatherAhead = 8;

class SppmIntegrator final : public SampleIntegrator {
 public:
  SppmIntegrator(int max_depth, int64_t photons_per_iteration, float radius, uint32_t seed, float alpha)
      : max_depth_(max_depth),
        photons_per_iteration_(photons_per_iteration),
        radius_(radius),
        seed_(seed),
        alpha_(alpha) {}

  std::vector<std::string> structures_built() const override {
    if (grid_built_) return {"visible_point_grid"};
    return {};
  }
  std::vector<std::pair<std::string, double>> statistics() const override { return statistics_; }

  // One iteration per pass: the photon pass needs every pixel's visible point of that iteration.
  int max_pass_samples() const override { return 1; }
  bool film_holds_estimate() const override { return false; }
  ImageRgb estimate() const override;

  bool supports_spectral() const override { return true; }
  bool wavelengths_per_pass() const override { return true; }

  void begin_render(RenderContext& ctx) override;
  void begin_pass(RenderContext& ctx, const Pass& pass) override;
  Rgb sample(const Scene& scene, const PixelSample& ps, Sampler& sampler, SplatSink&) override;
  void end_pass(RenderContext& ctx, const Pass& pass) override;
  void end_render(RenderContext& ctx, int spp) override;
  void save_state(StateWriter& out) const override;
  void load_state(StateReader& in) override;

 private:
  void choose_initial_radius();
  void build_gather_points();
  void photon_pass(RenderContext& ctx, uint32_t iteration);

  int max_depth_;
  int64_t photons_per_iteration_;
  float radius_;  // 0: from the pixel footprint
  uint32_t seed_;
  float alpha_;
  bool grid_built_ = false;
  std::vector<std::pair<std::string, double>> statistics_;

  // State of one render.
  Point2i res_{0};
  uint64_t photons_ = 0, photon_stream_ = 0;
  double quantum_ = 1.0, inv_quantum_ = 1.0;
  bool trace_photons_ = false;
  RaysFind rays_find_ = RaysFind::Anything;  // what a BSDF-sampled direct-light ray can find
  bool spectral_ = false;
  SampledWavelengths lambda_;       // the iteration's wavelengths (spectral renders: Pass::wavelengths)
  std::vector<VisiblePoint> vps_;
  std::vector<Vec3> vp_p_;
  std::vector<float> vp_radius_;    // 0 where a pixel has no visible point this iteration
  std::vector<Rgb> vp_Ld_;          // this iteration's camera-side light, kept until the pass is whole
  std::vector<float> vp_footprint_; // first iteration only: the pixel footprint at the visible point
  std::vector<PixelStatistics> stats_;
  // In the grid's slot order (VisiblePointGrid::point_of), rebuilt with the grid: what a photon needs
  // at a visible point, and the point's photon sums. Points of one cell lie together, so a photon's
  // neighbours share cache lines instead of each costing a miss in pixel order.
  std::vector<GatherPoint> gather_;
  std::unique_ptr<PhotonAccumulator[]> acc_;
  VisiblePointGrid grid_;
  int iterations_ = 0;              // complete iterations in the statistics
  double emitted_ = 0.0;            // photons emitted over those iterations
  bool radius_chosen_ = false;
};

// The runtime's --seed reaches the sampler only. Folding one of the sampler's numbers into the photon
// seed lets a new sampler seed draw new photons too.
uint64_t photon_seed(const Sampler& prototype, uint32_t seed) {
  std::unique_ptr<Sampler> s = prototype.clone();
  s->start_pixel_sample(Point2i(0, 0), 0);
  float u = s->get_1d();
  uint32_t bits;
  std::memcpy(&bits, &u, sizeof bits);
  return hash_ints(seed, bits);
}

void SppmIntegrator::begin_render(RenderContext& ctx) {
  const Scene& scene = ctx.scene();
  res_ = ctx.film().resolution();
  const size_t n_pixels = static_cast<size_t>(res_.x) * res_.y;
  photons_ = photons_per_iteration_ > 0 ? static_cast<uint64_t>(photons_per_iteration_)
                                        : std::min<uint64_t>(n_pixels, kDefaultMaxPhotons);
  photon_stream_ = photon_seed(ctx.sampler(), seed_);
  double total_power = 0.0;
  for (const Light* light : scene.lights()) total_power += std::max(0.f, luminance(light->power()));
  quantum_ = photon_quantum(total_power);
  inv_quantum_ = 1.0 / quantum_;
  // One bounce is all direct light; photons start to matter from two.
  trace_photons_ = max_depth_ >= 2 && photons_ > 0 && total_power > 0.0;
  rays_find_ = what_rays_find(scene);
  spectral_ = ctx.options().spectral;
  // Per-pixel state, announced before it is allocated: the visible point and its split-out position,
  // radius and direct light, the statistics, the photon accumulator, the footprint, one gather point
  // and, per point in the grid, a 16-byte entry, its index, its bucket and up to 8 bytes of bucket table.
  const uint64_t per_pixel = sizeof(VisiblePoint) + sizeof(Vec3) + sizeof(float) + sizeof(Rgb) +
                             sizeof(PixelStatistics) + sizeof(PhotonAccumulator) + sizeof(float) +
                             sizeof(GatherPoint) + 16 + 4 + 4 + 8;
  require_memory(n_pixels * per_pixel, "sppm's per-pixel statistics",
                 fmt::format("{} pixels, {} bytes each", n_pixels, per_pixel));
  vps_.assign(n_pixels, VisiblePoint{});
  vp_p_.assign(n_pixels, Vec3(0.f));
  vp_radius_.assign(n_pixels, 0.f);
  vp_Ld_.assign(n_pixels, Rgb(0.f));
  stats_.assign(n_pixels, PixelStatistics{});
  acc_.reset(new PhotonAccumulator[n_pixels]);
  radius_chosen_ = radius_ > 0.f;
  for (PixelStatistics& st : stats_) st.radius = radius_;
  if (!radius_chosen_) vp_footprint_.assign(n_pixels, 0.f);
  iterations_ = 0;
  emitted_ = 0.0;
}

// The iteration's wavelengths, kept where the visible points' lookup contexts can point to them.
void SppmIntegrator::begin_pass(RenderContext&, const Pass& pass) {
  if (pass.wavelengths) lambda_ = *pass.wavelengths;
}

// Camera pass: every pixel's state is written by the one thread that renders its sample.
Rgb SppmIntegrator::sample(const Scene& scene, const PixelSample& ps, Sampler& sampler, SplatSink&) {
  size_t i = static_cast<size_t>(ps.pixel.y) * res_.x + ps.pixel.x;
  vps_[i] = VisiblePoint{};
  vp_radius_[i] = 0.f;
  vp_Ld_[i] = Rgb(0.f);
  if (!ps.ray) return Rgb(0.f);
  const SampledWavelengths* lambda = spectral_ ? &lambda_ : nullptr;
  CameraPathResult r = trace_camera_path(scene, *ps.ray, sampler, max_depth_, rays_find_, lambda);
  vp_Ld_[i] = spectral_ ? lambda_.to_rgb(r.Ld) : r.Ld;
  bool valid = r.vp.bsdf && is_finite(r.p) && is_finite(r.vp.beta) && !is_black(r.vp.beta);
  if (!valid) return Rgb(0.f);
  vps_[i] = r.vp;
  vp_p_[i] = r.p;
  vp_radius_[i] = static_cast<float>(stats_[i].radius);
  if (!radius_chosen_) {
    // The neighbouring pixel's ray through the same lens point, compared at the path's length.
    CameraSample next = ps.camera;
    next.p_film.x += ps.pixel.x + 1 < res_.x ? 1.f : -1.f;
    if (std::optional<Ray> other = scene.camera().generate_ray(next)) {
      float t = r.distance;
      vp_footprint_[i] = glm::length((other->o + t * other->d) - (ps.ray->o + t * ps.ray->d));
    }
  }
  return Rgb(0.f);
}

void SppmIntegrator::choose_initial_radius() {
  std::vector<float> f;
  for (size_t i = 0; i < vps_.size(); ++i)
    if (vps_[i].bsdf && vp_footprint_[i] > 0.f && std::isfinite(vp_footprint_[i])) f.push_back(vp_footprint_[i]);
  if (f.empty()) return;  // no visible point yet: try again at the next iteration's
  std::nth_element(f.begin(), f.begin() + f.size() / 2, f.end());
  float r0 = kFootprints * f[f.size() / 2];
  for (PixelStatistics& st : stats_) st.radius = r0;
  for (size_t i = 0; i < vps_.size(); ++i)
    if (vps_[i].bsdf) vp_radius_[i] = r0;
  statistics_.emplace_back("initial_radius", r0);
  radius_chosen_ = true;
  vp_footprint_.clear();
  vp_footprint_.shrink_to_fit();
}

// The visible points in the grid's slot order, so that the points a photon finds lie together.
void SppmIntegrator::build_gather_points() {
  const size_t n = grid_.node_count();
  if (gather_.size() < n) gather_.resize(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& b) {
    for (size_t s = b.begin(); s < b.end(); ++s) {
      // The points come in grid order, scattered over vps_: fetch those a few slots ahead (the
      // fields read span three cache lines) so the misses overlap instead of following one another.
      if (s + kGatherAhead < b.end()) {
        const char* ahead = reinterpret_cast<const char*>(&vps_[grid_.point_of(static_cast<uint32_t>(s + kGatherAhead))]);
        for (size_t off = 0; off < sizeof(VisiblePoint); off += 64) __builtin_prefetch(ahead + off);
      }
      const VisiblePoint& vp = vps_[grid_.point_of(static_cast<uint32_t>(s))];
      bool textured = vp.tex.dpdx != Vec3(0.f) || vp.tex.dpdy != Vec3(0.f);
      gather_[s] = GatherPoint{vp.shading, vp.wo, vp.tex.uv, vp.bsdf, vp.max_photon_depth, textured};
    }
  });
}

// Photon pass: each photon has its own random stream; deposits are order-independent integers.
// Batches of photons, so a time budget that runs out stops the pass within one batch per thread.
void SppmIntegrator::photon_pass(RenderContext& ctx, uint32_t iteration) {
  const Scene& scene = ctx.scene();
  const SampledWavelengths* lambda = spectral_ ? &lambda_ : nullptr;
  std::atomic<uint64_t> traced{0};
  const uint64_t batches = (photons_ + kPhotonBatch - 1) / kPhotonBatch;
  tbb::parallel_for(tbb::blocked_range<uint64_t>(0, batches, 1), [&](const tbb::blocked_range<uint64_t>& b) {
    for (uint64_t batch = b.begin(); batch < b.end(); ++batch) {
      if (ctx.should_stop()) return;
      uint64_t k0 = batch * kPhotonBatch, k1 = std::min(photons_, k0 + kPhotonBatch);
      for (uint64_t k = k0; k < k1; ++k) {
        Pcg32 rng = photon_rng(photon_stream_, iteration, k);
        trace_photon(scene, rng, max_depth_, lambda, [&](const SurfaceInteraction& hit, const Vec3& wi, const Rgb& beta, int depth) {
          if (depth == 0) return;  // direct light: the camera pass sampled it
          auto gather = [&](uint32_t slot) {
            const GatherPoint& g = gather_[slot];
            if (depth > g.max_photon_depth) return;
            ShadingContext sc;
            if (g.textured) sc.tex = vps_[grid_.point_of(slot)].tex;
            else sc.tex.uv = g.uv;
            sc.tex.wavelengths = lambda;
            Rgb phi = beta * g.bsdf->f(g.wo, g.shading.to_local(wi), sc);
            if (!is_finite(phi)) {
              uint32_t i = grid_.point_of(slot);
              ctx.report_nonfinite(Point2i(static_cast<int>(i % res_.x), static_cast<int>(i / res_.x)));
              return;
            }
            acc_[slot].add(phi, inv_quantum_);
          };
          // Two steps: find the points and start loading their data, then gather. The atomic adds
          // order memory like fences, so gathering while scanning would wait for each point's data
          // in turn; this way the loads overlap.
          uint32_t found[kGatherBatch];
          int n_found = 0;
          grid_.for_each_entry_within(hit.p, [&](uint32_t slot) {
            if (n_found == kGatherBatch) {
              for (int j = 0; j < n_found; ++j) gather(found[j]);
              n_found = 0;
            }
            __builtin_prefetch(&gather_[slot]);
            __builtin_prefetch(reinterpret_cast<const char*>(&gather_[slot]) + 64);
            __builtin_prefetch(&acc_[slot], 1);
            found[n_found++] = slot;
          });
          for (int j = 0; j < n_found; ++j) gather(found[j]);
        });
      }
      traced.fetch_add(k1 - k0, std::memory_order_relaxed);
      ctx.progress(static_cast<uint64_t>(iterations_ + 1) * vps_.size(),
                   static_cast<uint64_t>(ctx.options().spp) * vps_.size());
    }
  });
  // Photons that a cut pass did not trace were never emitted: the estimate divides by those traced.
  emitted_ += static_cast<double>(traced.load());
}

void SppmIntegrator::end_pass(RenderContext& ctx, const Pass& pass) {
  // A camera pass cut short by the time budget leaves some pixels without this iteration's sample:
  // the iteration is dropped whole, so every pixel's statistics hold the same iterations.
  if (!pass.complete) return;
  const size_t n_pixels = vps_.size();
  if (!radius_chosen_) choose_initial_radius();
  bool photons_found = false;
  if (trace_photons_ && radius_chosen_) {
    grid_.build(vp_p_, vp_radius_);
    grid_built_ = true;
    // Without visible points (the camera sees only sky or glass) the photons would find nothing.
    if (grid_.bucket_count() > 0) {
      build_gather_points();
      photon_pass(ctx, pass.first_index);
      photons_found = true;
    }
  }
  if (!photons_found && trace_photons_) emitted_ += static_cast<double>(photons_);
  // The camera-side light of the whole iteration.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n_pixels, 4096), [&](const tbb::blocked_range<size_t>& b) {
    for (size_t i = b.begin(); i < b.end(); ++i) {
      const Rgb& Ld = vp_Ld_[i];
      if (is_finite(Ld))
        for (int c = 0; c < 3; ++c) stats_[i].Ld[c] += Ld[c];
      else
        ctx.report_nonfinite(Point2i(static_cast<int>(i % res_.x), static_cast<int>(i / res_.x)));
    }
  });
  // Progressive update of N, r and tau (the visible point's throughput applies to all its photons),
  // over the grid's slots: each holds one pixel's visible point and its photon sums.
  if (photons_found)
    tbb::parallel_for(tbb::blocked_range<size_t>(0, grid_.node_count(), 4096), [&](const tbb::blocked_range<size_t>& b) {
      for (size_t s = b.begin(); s < b.end(); ++s) {
        PhotonAccumulator& acc = acc_[s];
        int64_t M = acc.M.load(std::memory_order_relaxed);
        if (M <= 0) continue;
        size_t i = grid_.point_of(static_cast<uint32_t>(s));
        double Phi[3];
        for (int c = 0; c < 3; ++c)
          Phi[c] = static_cast<double>(acc.phi[c].load(std::memory_order_relaxed)) * quantum_ * vps_[i].beta[c];
        if (spectral_) {  // values at the iteration's wavelengths, in double until the conversion
          Rgb rgb = lambda_.to_rgb(Rgb(static_cast<float>(Phi[0]), static_cast<float>(Phi[1]), static_cast<float>(Phi[2])));
          for (int c = 0; c < 3; ++c) Phi[c] = rgb[c];
        }
        update_statistics(stats_[i], static_cast<double>(M), Phi, alpha_);
        acc.reset();
      }
    });
  ++iterations_;
}

// Between iterations the per-pixel statistics are the whole state (visible points, the grid and
// the photon sums are rebuilt by every iteration).
void SppmIntegrator::save_state(StateWriter& out) const {
  out.value<int32_t>(iterations_);
  out.value<double>(emitted_);
  out.value<uint8_t>(radius_chosen_ ? 1 : 0);
  out.vector(stats_);
  out.vector(vp_footprint_);
}

void SppmIntegrator::load_state(StateReader& in) {
  iterations_ = in.value<int32_t>();
  emitted_ = in.value<double>();
  radius_chosen_ = in.value<uint8_t>() != 0;
  in.vector(stats_, stats_.size());
  in.vector(vp_footprint_, radius_chosen_ ? 0 : stats_.size());
}

ImageRgb SppmIntegrator::estimate() const {
  ImageRgb img{res_.x, res_.y, std::vector<float>(stats_.size() * 3)};
  const double photons = trace_photons_ ? emitted_ : 0.0;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, stats_.size(), 4096), [&](const tbb::blocked_range<size_t>& b) {
    for (size_t i = b.begin(); i < b.end(); ++i) {
      Rgb L = iterations_ > 0 ? pixel_estimate(stats_[i], iterations_, photons) : Rgb(0.f);
      for (int c = 0; c < 3; ++c) img.pixels[3 * i + c] = L[c];
    }
  });
  return img;
}

// The final estimate goes to the film once per pixel, with the iteration count as its weight, so the
// film's weighted mean is the estimate (and `penumbra merge` weighs parts by it).
void SppmIntegrator::end_render(RenderContext& ctx, int) {
  if (iterations_ == 0) return;
  Film& film = ctx.film();
  ImageRgb image = estimate();
  for (int y = 0; y < res_.y; ++y)
    for (int x = 0; x < res_.x; ++x) {
      const float* v = &image.pixels[3 * (static_cast<size_t>(y) * res_.x + x)];
      Rgb L(v[0], v[1], v[2]);
      if (!is_finite(L)) {
        ctx.report_nonfinite(Point2i(x, y));
        L = Rgb(0.f);
      }
      film.add_sample(Point2i(x, y), L, static_cast<float>(iterations_));
    }
  statistics_.emplace_back("iterations", iterations_);
  statistics_.emplace_back("photons_emitted", emitted_);
  // Free the per-pixel state of this render.
  vps_ = {};
  vp_p_ = {};
  vp_radius_ = {};
  vp_Ld_ = {};
}

const ParamSpec kParams[] = {
    {"integer", "maxdepth", "5", "longest path in bounces, camera and photon parts together"},
    {"integer", "photonsperiteration", "-1", "photons per iteration (-1: one per pixel, at most 262144)"},
    {"float", "radius", "0", "initial gather radius in world units (0: two pixel footprints at the median visible point)"},
    {"integer", "seed", "0", "seed of the photon random streams"},
    {"float", "alpha", "0.6666667", "fraction of each iteration's photons kept in the photon count"},
};

Object* create(const CreateContext& ctx) {
  const ParamSet& p = ctx.params;
  int max_depth = p.get_int("maxdepth");
  if (max_depth < 0) throw Error(p.loc_of("maxdepth"), "maxdepth must be >= 0");
  int photons = p.get_int("photonsperiteration");
  if (photons == 0 || photons < -1)
    throw Error(p.loc_of("photonsperiteration"), "photonsperiteration must be positive (or -1: one per pixel)");
  float radius = p.get_float("radius");
  if (!(radius >= 0.f) || !std::isfinite(radius))
    throw Error(p.loc_of("radius"), "radius must be positive and finite (or 0: from the pixel footprint)");
  float alpha = p.get_float("alpha");
  if (!(alpha > 0.f && alpha < 1.f)) throw Error(p.loc_of("alpha"), "alpha must be in (0, 1)");
  return new SppmIntegrator(max_depth, photons, radius, static_cast<uint32_t>(p.get_int("seed")), alpha);
}

}  // namespace

PENUMBRA_PLUGIN(Integrator, "sppm", "stochastic progressive photon mapping with a hashed visible-point grid",
                kParams, create)
