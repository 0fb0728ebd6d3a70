// The core's one render loop (SampleIntegrator::render): passes of samples over 16x16 tiles in
// parallel, for every integrator. Each pixel's samples are taken in index order by one thread at a
// time and every sample is a pure function of (pixel, index, seed), so the image is the same bit for
// bit whatever the thread count, and a part of a split render (indices [first_sample, first_sample +
// spp)) takes exactly its share of them. Splats go to the film's per-thread fixed-point buffers,
// whose integer sums do not depend on the order of the additions. Pixel integrators that take their
// camera ray's first hit are walked in blocks of 4x4 pixels (4x2 where Embree has no native 16-wide
// packets) whose camera rays are traced as one packet, four blocks at a time.
#include "image/splat_buffers.h"
#include "render/checkpoint.h"
#include "render/surface_sample.h"
#include "scene/embree_scene.h"

#include <penumbra/integrator.h>
#include <penumbra/memory.h>

#include <fmt/core.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <memory>
#include <new>
#include <optional>
#include <type_traits>

namespace penumbra {

namespace {

constexpr int kTileSize = 16;

// Per-thread splat sink of one pixel sample: checks values while the pixel that made them is known.
class CheckedSplats final : public SplatSink {
 public:
  CheckedSplats(RenderContext& ctx, Film& film) : ctx_(ctx), film_(film) {}
  void start(Point2i pixel) { pixel_ = pixel; }
  /// The wavelengths of the sample whose splats follow (spectral renders), or null.
  void set_wavelengths(const SampledWavelengths* w) { wavelengths_ = w; }
  void splat(const Vec2& p_raster, const Rgb& value) override {
    if (!is_finite(value)) {
      ctx_.report_nonfinite(pixel_);
      return;
    }
    if (is_black(value)) return;
    film_.add_splat(p_raster, wavelengths_ ? wavelengths_->to_rgb(value) : value);
  }

 private:
  RenderContext& ctx_;
  Film& film_;
  Point2i pixel_{0};
  const SampledWavelengths* wavelengths_ = nullptr;
};

// Pixel integrators whose Li() starts by tracing the camera ray get it traced by the loop, as one
// Embree packet per block of pixels at one sample index (EmbreeScene::intersect_coherent()): 4x4
// pixels where Embree traces 16-wide packets natively (AVX-512), 4x2 otherwise. 16-wide packets
// took 2 % off the path tracer's time on the Cornell box and 3 % on cornell-water at 256x256 against
// 8-wide ones (docs/benchmarks.md). The block is a fixed set of pixels (tiles are 16x16 and start at
// multiples of 16), so a pixel's packet does not depend on passes, threads or split renders.
constexpr int kBlockWidth = 4, kMaxLanes = 16;
// Blocks are taken in groups of 2x2 (8x8 pixels for 4x4 blocks): the camera samples and packets of
// all four blocks, then Li for each of the group's pixels. Against block by block, the path tracer
// renders the Cornell box 5.5 % faster on two threads and as fast on one (why two threads gain was
// not found; docs/benchmarks.md, "The path integrator without GCC's SLP vectorizer").
constexpr int kGroupSide = 2, kGroupLanes = kMaxLanes * kGroupSide * kGroupSide;

struct ThreadState {
  std::vector<std::unique_ptr<Sampler>> samplers;  // one per pixel of a group of blocks
  CheckedSplats splats;
};

// One pixel sample of a block between the camera and the integrator.
struct Lane {
  Point2i pixel;
  PixelSample ps;
  FilterSample fs;
  std::optional<Ray> ray;
  SampledWavelengths wavelengths;
};
// start_lanes() constructs a lane's ray over the last one without destroying it.
static_assert(std::is_trivially_destructible_v<std::optional<Ray>>);

// Starts the pixel samples at `index` of n lanes (a group of blocks): the film position, the lens
// position and, in a spectral render, the wavelengths (in that order of each lane's sampler
// dimensions), then each lane's filter sample and camera ray. Each step runs over all lanes before
// the next: one lane's chain from its sampler's start through the filter to its ray is dependent
// from end to end, and lanes taken one after the other left the processor little to overlap (lane
// by lane, the camera samples were about a tenth of the path tracer's time on the Cornell box;
// docs/benchmarks.md). Each lane's values are the same either way.
void start_lanes(Lane* lanes, int n, const std::unique_ptr<Sampler>* samplers, uint32_t index, const Film& film,
                 const Camera& camera, bool spectral, const SampledWavelengths* pass_wavelengths) {
  Vec2 u_film[kGroupLanes];
  for (int k = 0; k < n; ++k) {
    Lane& lane = lanes[k];
    Sampler& sampler = *samplers[k];
    sampler.start_pixel_sample(lane.pixel, index);
    u_film[k] = sampler.get_pixel_2d();
    PixelSample& ps = lane.ps;
    ps = PixelSample{};
    ps.pixel = lane.pixel;
    ps.index = index;
    ps.camera.p_lens = sampler.get_2d();
    if (spectral) {
      // Drawn in either case, so the sampler's dimensions do not depend on the choice.
      float u = sampler.get_1d();
      lane.wavelengths = pass_wavelengths ? *pass_wavelengths : SampledWavelengths::sample(u);
      ps.wavelengths = &lane.wavelengths;
    }
  }
  for (int k = 0; k < n; ++k) {
    lanes[k].fs = film.sample_filter(u_film[k]);
    lanes[k].ps.camera.p_film = Vec2(lanes[k].pixel) + Vec2(0.5f) + lanes[k].fs.offset;
  }
  for (int k = 0; k < n; ++k) {
    Lane& lane = lanes[k];
    // Constructed in place (the camera writes the ray into the lane): assigned, the ray the camera
    // had just stored in floats was copied on in 16-byte loads, which stalls store forwarding.
    ::new (&lane.ray) std::optional<Ray>(camera.generate_ray(lane.ps.camera));
    lane.ps.ray = lane.ray ? &*lane.ray : nullptr;
  }
}

// Per-pass wavelengths: the base-2 radical inverse of the pass's first sample index, rotated (mod 1)
// by a number that follows the seed, so that passes stratify the spectrum and seeds differ.
float pass_wavelength_number(uint32_t first_index, float rotation) {
  uint32_t i = first_index;
  i = (i << 16) | (i >> 16);
  i = ((i & 0x00ff00ffu) << 8) | ((i & 0xff00ff00u) >> 8);
  i = ((i & 0x0f0f0f0fu) << 4) | ((i & 0xf0f0f0f0u) >> 4);
  i = ((i & 0x33333333u) << 2) | ((i & 0xccccccccu) >> 2);
  i = ((i & 0x55555555u) << 1) | ((i & 0xaaaaaaaau) >> 1);
  float u = static_cast<float>(i >> 8) * 0x1p-24f + rotation;
  return u >= 1.f ? u - 1.f : u;
}

// The rotation: a number of the prototype sampler at a sample index no render reaches.
float wavelength_rotation_of(const Sampler& prototype) {
  std::unique_ptr<Sampler> s = prototype.clone();
  s->start_pixel_sample(Point2i(0, 0), 0xffffffe0u);
  return std::min(s->get_1d(), OneMinusEpsilon);
}

}  // namespace

void SampleIntegrator::render(RenderContext& ctx) {
  const Scene& scene = ctx.scene();
  Film& film = ctx.film();
  const Camera& camera = scene.camera();
  const RenderOptions& opt = ctx.options();
  const Point2i res = film.resolution();
  const int tiles_x = (res.x + kTileSize - 1) / kTileSize, tiles_y = (res.y + kTileSize - 1) / kTileSize;
  const uint64_t pixels = static_cast<uint64_t>(res.x) * res.y;
  const uint64_t total = pixels * static_cast<uint64_t>(opt.spp);
  const bool surface_aovs = film.wants_surface_samples();
  const bool spectral = opt.spectral;
  begin_render(ctx);
  const bool per_pass_wavelengths = spectral && wavelengths_per_pass();
  const float wavelength_rotation = per_pass_wavelengths ? wavelength_rotation_of(ctx.sampler()) : 0.f;
  // The runtime's context takes checkpoints between passes and may resume from one.
  CheckpointHost* host = dynamic_cast<CheckpointHost*>(&ctx);
  std::optional<ResumePoint> resumed = host ? host->resume(*this) : std::nullopt;
  // Asked after begin_render(), since they may depend on what it set up.
  const bool to_film = film_holds_estimate();
  const int max_pass = std::max(1, max_pass_samples());
  // Splats from every thread may reach every pixel (bidirectional integrators do): their buffers'
  // worst case is announced before the first sample. Integrators along the camera ray never splat.
  if (to_film && !dynamic_cast<const PixelIntegrator*>(this)) {
    int threads = opt.threads > 0 ? opt.threads : tbb::this_task_arena::max_concurrency();
    require_memory(SplatBuffers::worst_case_bytes(res, threads), "the film's splat buffers",
                   fmt::format("{}x{} pixels, 48 bytes each in 2 MiB chunks, for each of {} threads", res.x, res.y, threads));
  }

  const auto* pixel_integrator = dynamic_cast<const PixelIntegrator*>(this);
  const EmbreeScene* packets = pixel_integrator && pixel_integrator->takes_first_hit()
                                   ? dynamic_cast<const EmbreeScene*>(&scene) : nullptr;
  const int block_w = packets ? kBlockWidth : 1, block_h = packets ? packets->packet_width() / kBlockWidth : 1;
  const int group_side = packets ? kGroupSide : 1;
  const int group_w = block_w * group_side, group_h = block_h * group_side;
  tbb::enumerable_thread_specific<ThreadState> threads([&] {
    ThreadState ts{{}, CheckedSplats(ctx, film)};
    for (int k = 0; k < group_w * group_h; ++k) ts.samplers.push_back(ctx.sampler().clone());
    return ts;
  });

  // What the runtime learns after each pass: whole passes done, what the splats are divided by (the
  // pixel samples actually taken over the pixel count) and, when the film does not hold it, where
  // the estimate comes from.
  int done_spp = resumed ? resumed->spp : 0;
  std::atomic<uint64_t> samples_taken{static_cast<uint64_t>(done_spp) * pixels};  // cut passes included
  const std::function<ImageRgb()> estimate_fn = to_film ? std::function<ImageRgb()>() : [this] { return estimate(); };
  auto report = [&] {
    ctx.set_completed_spp(done_spp, estimate_fn, static_cast<double>(samples_taken.load()) / static_cast<double>(pixels));
  };

  int pass_spp = resumed ? resumed->pass_spp : 1;
  if (resumed) report();
  auto stop_requested = [&] { return host && host->stop_requested(); };
  while (done_spp < opt.spp && !ctx.should_stop() && !stop_requested()) {
    Pass pass;
    pass.first_index = static_cast<uint32_t>(opt.first_sample + done_spp);
    pass.count = std::min({opt.spp - done_spp, pass_spp, max_pass});
    SampledWavelengths pass_wavelengths;
    if (per_pass_wavelengths) {
      pass_wavelengths = SampledWavelengths::sample(pass_wavelength_number(pass.first_index, wavelength_rotation));
      pass.wavelengths = &pass_wavelengths;
    }
    double pass_start = ctx.elapsed();
    begin_pass(ctx, pass);
    std::atomic<bool> cut{false};
    tbb::parallel_for(tbb::blocked_range<int>(0, tiles_x * tiles_y), [&](const tbb::blocked_range<int>& r) {
      ThreadState& ts = threads.local();
      for (int tile = r.begin(); tile < r.end(); ++tile) {
        if (ctx.should_stop()) {
          cut.store(true, std::memory_order_relaxed);
          return;
        }
        int x0 = (tile % tiles_x) * kTileSize, y0 = (tile / tiles_x) * kTileSize;
        int x1 = std::min(x0 + kTileSize, res.x), y1 = std::min(y0 + kTileSize, res.y);
        for (int gy = y0; gy < y1; gy += group_h)
          for (int gx = x0; gx < x1; gx += group_w) {
            Lane lanes[kGroupLanes];
            int block_start[kGroupSide * kGroupSide + 1];
            int n = 0, blocks = 0;
            for (int by = gy; by < std::min(gy + group_h, y1); by += block_h)
              for (int bx = gx; bx < std::min(gx + group_w, x1); bx += block_w) {
                block_start[blocks++] = n;
                for (int y = by; y < std::min(by + block_h, y1); ++y)
                  for (int x = bx; x < std::min(bx + block_w, x1); ++x) lanes[n++].pixel = Point2i(x, y);
              }
            block_start[blocks] = n;
            // Each pixel's samples in index order; the pixels of a group take turns. The packets'
            // hits are declared once per group: intersect_coherent() sets all of them, and an
            // array declared per sample cost a `rep stos` zero-fill of all of it each time (GCC 12).
            std::optional<SurfaceInteraction> hits[kGroupLanes];
            for (int s = 0; s < pass.count; ++s) {
              uint32_t index = pass.first_index + static_cast<uint32_t>(s);
              start_lanes(lanes, n, ts.samplers.data(), index, film, camera, spectral, pass.wavelengths);
              if (packets) {
                const Ray* rays[kGroupLanes];
                for (int k = 0; k < n; ++k) {
                  rays[k] = lanes[k].ps.ray;
                  lanes[k].ps.first_hit = &hits[k];
                }
                for (int b = 0; b < blocks; ++b)
                  packets->intersect_coherent(
                      std::span<const Ray* const>(rays + block_start[b], block_start[b + 1] - block_start[b]),
                      hits + block_start[b]);
              }
              for (int k = 0; k < n; ++k) {
                Lane& lane = lanes[k];
                ts.splats.start(lane.pixel);
                if (spectral) ts.splats.set_wavelengths(&lane.wavelengths);
                Rgb L = sample(scene, lane.ps, *ts.samplers[k], ts.splats);
                if (spectral) L = lane.wavelengths.to_rgb(L);
                if (surface_aovs) {  // the packet's hit where there was one, else the ray once more
                  SurfaceSample aov = !lane.ray ? SurfaceSample{}
                                      : packets ? describe_surface_sample(hits[k], lane.pixel, index)
                                                : trace_surface_sample(scene, *lane.ray, lane.pixel, index);
                  film.add_surface_sample(lane.pixel, aov, lane.fs.weight);
                }
                if (!to_film) continue;
                if (!is_finite(L)) {
                  ctx.report_nonfinite(lane.pixel);
                  continue;
                }
                film.add_sample(lane.pixel, L, lane.fs.weight);
              }
            }
          }
        uint64_t n = static_cast<uint64_t>(x1 - x0) * (y1 - y0) * pass.count;
        ctx.progress(samples_taken.fetch_add(n) + n, total);
      }
    });
    pass.complete = !cut.load();
    end_pass(ctx, pass);
    if (!pass.complete) break;
    done_spp += pass.count;
    report();
    // Short passes first so a time budget is met closely, longer ones later for less overhead;
    // with a budget, a pass never takes much more than the time that is left.
    double now = ctx.elapsed();
    pass_spp = std::min(pass_spp * 2, max_pass);
    if (opt.time_budget > 0.0) {
      double per_spp = (now - pass_start) / pass.count;
      if (per_spp > 0.0) pass_spp = std::clamp(static_cast<int>((opt.time_budget - now) / per_spp), 1, pass_spp);
    }
    if (host) host->pass_complete(ResumePoint{done_spp, pass_spp}, *this);
    if (ctx.should_stop()) break;
  }
  // A pass cut short still adds its samples: pixel means stay unbiased, and the splats are divided
  // by the samples actually taken.
  if (samples_taken.load() > static_cast<uint64_t>(done_spp) * pixels) report();
  end_render(ctx, done_spp);
}

}  // namespace penumbra
