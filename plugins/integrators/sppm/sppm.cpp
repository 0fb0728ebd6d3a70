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
// | integer photonsperiteration | -1      | photons per iteration; -1: one per pixel               |
// | float radius                | 1       | initial gather radius, world units (capped at the scene's diagonal) |
// | integer seed                | 0       | photon random streams (the sampler's seed drives the camera side) |
// | float alpha                 | 2/3     | fraction of each iteration's photons kept in the count |
//
// Iterations are the sampler's pixel samples (--spp); with --time the render stops after the
// iteration during which the budget ran out. An SPPM estimate is not a mean of per-iteration samples,
// so it cannot be accumulated in the film pass by pass: it goes to the film once, at the end, and a
// snapshot after an iteration asks the integrator for the current estimate instead.
//
// Depth: a photon gathered at a visible point found after d camera bounces has made at most
// maxdepth - 1 - d bounces, so the image converges to exactly what "path" renders with the same
// maxdepth (pbrt lets photons add up to maxdepth - 1 bounces whatever d is).
//
// Memory per pixel: visible point 80 B, its position and gather radius 16 B, statistics 64 B and
// photon accumulator 32 B (192 B), plus the grid: 8 B per cell a point's disk overlaps (12 to 27
// cells, as cells are one maximum radius wide: 100 to 220 B) and about 10 B of buckets and offsets.
// About 300 to 420 B in all; photons are never stored. Deterministic: a fixed seed gives the same
// image bit for bit, whatever the number of threads (see PhotonAccumulator).
#include "camera_pass.h"
#include "photon_tracer.h"
#include "visible_point_grid.h"

#include <penumbra/integrator.h>
#include <penumbra/plugin.h>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cstring>
#include <memory>
#include <vector>

namespace {

using namespace penumbra;
using namespace penumbra::sppm;

class SppmIntegrator final : public Integrator {
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

  void render(RenderContext& ctx) override;

 private:
  int max_depth_;
  int64_t photons_per_iteration_;
  float radius_;
  uint32_t seed_;
  float alpha_;
  bool grid_built_ = false;
};

// The largest gather radius worth having: a disk wider than the scene gathers every photon already,
// and a larger one only spreads them thinner.
float initial_radius(float radius, const Scene& scene) {
  Bounds3 b = scene.bounds();
  float diagonal = glm::length(b.max - b.min);
  if (std::isfinite(diagonal) && diagonal > 0.f) return std::min(radius, diagonal);
  return radius;
}

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

ImageRgb estimate_image(const std::vector<PixelStatistics>& stats, Point2i res, int iterations, double photons) {
  ImageRgb img{res.x, res.y, std::vector<float>(stats.size() * 3)};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, stats.size(), 4096), [&](const tbb::blocked_range<size_t>& b) {
    for (size_t i = b.begin(); i < b.end(); ++i) {
      Rgb L = pixel_estimate(stats[i], iterations, photons);
      for (int c = 0; c < 3; ++c) img.pixels[3 * i + c] = L[c];
    }
  });
  return img;
}

void SppmIntegrator::render(RenderContext& ctx) {
  const Scene& scene = ctx.scene();
  Film& film = ctx.film();
  const RenderOptions& opt = ctx.options();
  const Point2i res = film.resolution();
  const size_t n_pixels = static_cast<size_t>(res.x) * res.y;
  const uint64_t photons = photons_per_iteration_ > 0 ? static_cast<uint64_t>(photons_per_iteration_) : n_pixels;
  const uint64_t photon_stream = photon_seed(ctx.sampler(), seed_);

  double total_power = 0.0;
  for (const Light* light : scene.lights()) total_power += std::max(0.f, luminance(light->power()));
  const double quantum = photon_quantum(total_power), inv_quantum = 1.0 / quantum;
  // One bounce is all direct light; photons start to matter from two.
  const bool trace_photons = max_depth_ >= 2 && photons > 0 && total_power > 0.0;

  std::vector<VisiblePoint> vps(n_pixels);
  std::vector<Vec3> vp_p(n_pixels);
  std::vector<float> vp_radius(n_pixels, 0.f);  // 0 where a pixel has no visible point this iteration
  std::vector<PixelStatistics> stats(n_pixels);
  std::unique_ptr<PhotonAccumulator[]> acc(new PhotonAccumulator[n_pixels]);
  const float r0 = initial_radius(radius_, scene);
  for (PixelStatistics& s : stats) s.radius = r0;
  VisiblePointGrid grid;
  auto emitted_photons = [&](int iterations) {
    return trace_photons ? static_cast<double>(iterations) * static_cast<double>(photons) : 0.0;
  };

  tbb::enumerable_thread_specific<std::unique_ptr<Sampler>> samplers([&] { return ctx.sampler().clone(); });
  const uint64_t progress_total = static_cast<uint64_t>(n_pixels) * static_cast<uint64_t>(opt.spp);

  int done = 0;
  while (done < opt.spp) {
    // A part of a split render runs its own iterations [first_sample, first_sample + spp): streams
    // independent of the other parts', so the parts are independent SPPM renders.
    const uint32_t iteration = static_cast<uint32_t>(opt.first_sample + done);

    // Camera pass: rows in parallel; every pixel's state is written by one thread only.
    tbb::parallel_for(tbb::blocked_range<int>(0, res.y), [&](const tbb::blocked_range<int>& rows) {
      Sampler& sampler = *samplers.local();
      for (int y = rows.begin(); y < rows.end(); ++y)
        for (int x = 0; x < res.x; ++x) {
          size_t i = static_cast<size_t>(y) * res.x + x;
          CameraPathResult r = trace_camera_path(scene, film, sampler, Point2i(x, y), iteration, max_depth_);
          if (is_finite(r.Ld))
            for (int c = 0; c < 3; ++c) stats[i].Ld[c] += r.Ld[c];
          else
            ctx.report_nonfinite(Point2i(x, y));
          bool valid = r.vp.bsdf && is_finite(r.p) && is_finite(r.vp.beta) && !is_black(r.vp.beta);
          vps[i] = valid ? r.vp : VisiblePoint{};
          vp_p[i] = r.p;
          vp_radius[i] = valid ? static_cast<float>(stats[i].radius) : 0.f;
        }
    });

    if (trace_photons) {
      grid.build(vp_p, vp_radius);
      grid_built_ = true;
    }
    // Photon pass: each photon has its own random stream; deposits are order-independent integers.
    // Without visible points (the camera sees only sky or glass) the photons would find nothing.
    if (trace_photons && grid.bucket_count() > 0) {
      tbb::parallel_for(tbb::blocked_range<uint64_t>(0, photons, 256), [&](const tbb::blocked_range<uint64_t>& b) {
        for (uint64_t k = b.begin(); k < b.end(); ++k) {
          Pcg32 rng = photon_rng(photon_stream, iteration, k);
          trace_photon(scene, rng, max_depth_, [&](const SurfaceInteraction& hit, const Vec3& wi, const Rgb& beta, int depth) {
            if (depth == 0) return;  // direct light: the camera pass sampled it
            grid.for_each_within(hit.p, [&](uint32_t i) {
              const VisiblePoint& vp = vps[i];
              if (depth > vp.max_photon_depth) return;
              Rgb phi = beta * vp.bsdf->f(vp.wo, vp.shading.to_local(wi), ShadingContext{vp.uv, TransportMode::Radiance});
              if (!is_finite(phi)) {
                ctx.report_nonfinite(Point2i(static_cast<int>(i % res.x), static_cast<int>(i / res.x)));
                return;
              }
              acc[i].add(phi, inv_quantum);
            });
          });
        }
      });
    }

    // Progressive update of N, r and tau (the visible point's throughput applies to all its photons).
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n_pixels, 1024), [&](const tbb::blocked_range<size_t>& b) {
      for (size_t i = b.begin(); i < b.end(); ++i) {
        int64_t M = acc[i].M.load(std::memory_order_relaxed);
        if (M > 0) {
          double Phi[3];
          for (int c = 0; c < 3; ++c)
            Phi[c] = static_cast<double>(acc[i].phi[c].load(std::memory_order_relaxed)) * quantum * vps[i].beta[c];
          update_statistics(stats[i], static_cast<double>(M), Phi, alpha_);
          acc[i].reset();
        }
      }
    });

    ++done;
    ctx.progress(static_cast<uint64_t>(done) * n_pixels, progress_total);
    // The film only receives the estimate at the end; a snapshot asks for it now.
    ctx.set_completed_spp(done, [&] { return estimate_image(stats, res, done, emitted_photons(done)); });
    if (opt.time_budget > 0.0 && ctx.elapsed() >= opt.time_budget) break;
  }

  // The final estimate, once per pixel with the iteration count as its weight, so the film's weighted
  // mean is the estimate.
  ImageRgb image = estimate_image(stats, res, done, emitted_photons(done));
  for (int y = 0; y < res.y; ++y)
    for (int x = 0; x < res.x; ++x) {
      const float* v = &image.pixels[3 * (static_cast<size_t>(y) * res.x + x)];
      Rgb L(v[0], v[1], v[2]);
      if (!is_finite(L)) {
        ctx.report_nonfinite(Point2i(x, y));
        L = Rgb(0.f);
      }
      film.add_sample(Point2i(x, y), L, static_cast<float>(done));  // `penumbra merge` weighs parts by it
    }
}

const ParamSpec kParams[] = {
    {"integer", "maxdepth", "5", "longest path in bounces, camera and photon parts together"},
    {"integer", "photonsperiteration", "-1", "photons per iteration (-1: one per pixel)"},
    {"float", "radius", "1", "initial gather radius in world units (capped at the scene diagonal)"},
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
  if (!(radius > 0.f) || !std::isfinite(radius)) throw Error(p.loc_of("radius"), "radius must be positive and finite");
  float alpha = p.get_float("alpha");
  if (!(alpha > 0.f && alpha < 1.f)) throw Error(p.loc_of("alpha"), "alpha must be in (0, 1)");
  return new SppmIntegrator(max_depth, photons, radius, static_cast<uint32_t>(p.get_int("seed")), alpha);
}

}  // namespace

PENUMBRA_PLUGIN(Integrator, "sppm", "stochastic progressive photon mapping with a hashed visible-point grid",
                kParams, create)
