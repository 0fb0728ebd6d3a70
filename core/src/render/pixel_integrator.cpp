// The render loop of PixelIntegrator: passes of samples over 16x16 tiles in parallel. Each pixel's
// samples are taken in index order by one thread at a time, and every sample is a pure function of
// (pixel, index, seed), so the image is the same bit for bit whatever the thread count, and a part
// of a split render (indices [first_sample, first_sample + spp)) takes exactly its share of them.
#include "render/surface_sample.h"

#include <penumbra/integrator.h>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>

namespace penumbra {

namespace {
constexpr int kTileSize = 16;
}

void PixelIntegrator::render(RenderContext& ctx) {
  const Scene& scene = ctx.scene();
  Film& film = ctx.film();
  const Camera& camera = scene.camera();
  const RenderOptions& opt = ctx.options();
  Point2i res = film.resolution();
  int tiles_x = (res.x + kTileSize - 1) / kTileSize, tiles_y = (res.y + kTileSize - 1) / kTileSize;
  uint64_t total = static_cast<uint64_t>(res.x) * res.y * static_cast<uint64_t>(opt.spp);
  const bool surface_aovs = film.wants_surface_samples();

  tbb::enumerable_thread_specific<std::unique_ptr<Sampler>> samplers(
      [&] { return ctx.sampler().clone(); });

  std::atomic<uint64_t> done_samples{0};
  int done_spp = 0, pass_spp = 1;
  while (done_spp < opt.spp) {
    int begin = done_spp, end = std::min(opt.spp, done_spp + pass_spp);
    double pass_start = ctx.elapsed();
    tbb::parallel_for(tbb::blocked_range<int>(0, tiles_x * tiles_y), [&](const tbb::blocked_range<int>& r) {
      Sampler& sampler = *samplers.local();
      for (int tile = r.begin(); tile < r.end(); ++tile) {
        int x0 = (tile % tiles_x) * kTileSize, y0 = (tile / tiles_x) * kTileSize;
        int x1 = std::min(x0 + kTileSize, res.x), y1 = std::min(y0 + kTileSize, res.y);
        for (int y = y0; y < y1; ++y)
          for (int x = x0; x < x1; ++x) {
            Point2i pixel(x, y);
            for (int s = begin; s < end; ++s) {
              // A part of a split render takes its own range of the one global sequence.
              uint32_t index = static_cast<uint32_t>(opt.first_sample + s);
              sampler.start_pixel_sample(pixel, index);
              FilterSample fs = film.sample_filter(sampler.get_pixel_2d());
              CameraSample cs{Vec2(x + 0.5f, y + 0.5f) + fs.offset, sampler.get_2d()};
              std::optional<Ray> ray = camera.generate_ray(cs);
              Rgb L = ray ? Li(*ray, sampler, scene) : Rgb(0.f);
              if (!is_finite(L)) {
                ctx.report_nonfinite(pixel);
                continue;
              }
              film.add_sample(pixel, L, fs.weight);
              if (surface_aovs)
                film.add_surface_sample(pixel, ray ? trace_surface_sample(scene, *ray, pixel, index) : SurfaceSample{},
                                        fs.weight);
            }
          }
        uint64_t n = static_cast<uint64_t>(x1 - x0) * (y1 - y0) * (end - begin);
        ctx.progress(done_samples.fetch_add(n) + n, total);
      }
    });
    done_spp = end;
    ctx.set_completed_spp(done_spp);
    double now = ctx.elapsed();
    if (opt.time_budget > 0.0 && now >= opt.time_budget) break;
    // Short passes first so a time budget is met closely, longer ones later for less overhead;
    // with a budget, a pass never takes much more than the time that is left.
    pass_spp = std::min(pass_spp * 2, 16);
    if (opt.time_budget > 0.0) {
      double per_spp = (now - pass_start) / (end - begin);
      if (per_spp > 0.0)
        pass_spp = std::clamp(static_cast<int>((opt.time_budget - now) / per_spp), 1, pass_spp);
    }
  }
}

}  // namespace penumbra
