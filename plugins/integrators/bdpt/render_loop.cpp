#include "render_loop.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_pipeline.h>

#include <algorithm>
#include <atomic>
#include <memory>

namespace penumbra::bdpt {

namespace {

constexpr int kTileSize = 16;

struct TileResult {
  int tile = 0;
  Point2i first_pixel{0};  // where non-finite splats are reported
  SampleOutputs out;
};

}  // namespace

int render_with_splats(RenderContext& ctx, const PixelSampleFn& sample, const TaggedCommitFn& commit_tagged,
                       const PassOptions& pass_options) {
  Film& film = ctx.film();
  const RenderOptions& opt = ctx.options();
  Point2i res = film.resolution();
  int tiles_x = (res.x + kTileSize - 1) / kTileSize, tiles_y = (res.y + kTileSize - 1) / kTileSize;
  int tiles = tiles_x * tiles_y;
  uint64_t total = static_cast<uint64_t>(res.x) * res.y * static_cast<uint64_t>(opt.spp);
  size_t tokens = static_cast<size_t>(std::max(1, opt.threads)) * 4;

  tbb::enumerable_thread_specific<std::unique_ptr<Sampler>> samplers([&] { return ctx.sampler().clone(); });
  std::atomic<uint64_t> done_samples{0};
  int done_spp = 0, pass_spp = 1;
  while (done_spp < opt.spp) {
    int begin = done_spp, end = std::min(opt.spp, done_spp + pass_spp);
    double pass_start = ctx.elapsed();
    if (pass_options.before_pass) pass_options.before_pass(static_cast<uint32_t>(opt.first_sample + begin));
    int next_tile = 0;

    auto source = [&](tbb::flow_control& fc) -> std::shared_ptr<TileResult> {
      if (next_tile >= tiles) {
        fc.stop();
        return nullptr;
      }
      auto r = std::make_shared<TileResult>();
      r->tile = next_tile++;
      return r;
    };
    auto render_tile = [&](std::shared_ptr<TileResult> r) -> std::shared_ptr<TileResult> {
      Sampler& sampler = *samplers.local();
      int x0 = (r->tile % tiles_x) * kTileSize, y0 = (r->tile / tiles_x) * kTileSize;
      int x1 = std::min(x0 + kTileSize, res.x), y1 = std::min(y0 + kTileSize, res.y);
      r->first_pixel = Point2i(x0, y0);
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          Point2i pixel(x, y);
          for (int s = begin; s < end; ++s) {
            // A part of a split render takes its own range of the one global sequence.
            uint32_t index = static_cast<uint32_t>(opt.first_sample + s);
            sampler.start_pixel_sample(pixel, index);
            FilterSample fs = film.sample_filter(sampler.get_pixel_2d());
            CameraSample cs{Vec2(x + 0.5f, y + 0.5f) + fs.offset, sampler.get_2d()};
            size_t first_splat = r->out.splats.size();
            Rgb L = sample(pixel, index, cs, sampler, r->out);
            // Splats are checked here, while the pixel that produced them is known.
            for (size_t i = first_splat; i < r->out.splats.size(); ++i)
              if (!is_finite(r->out.splats[i].value)) {
                ctx.report_nonfinite(pixel);
                r->out.splats[i].value = Rgb(0.f);
              }
            if (!is_finite(L)) {
              ctx.report_nonfinite(pixel);
              continue;
            }
            film.add_sample(pixel, L, fs.weight);
          }
        }
      uint64_t n = static_cast<uint64_t>(x1 - x0) * (y1 - y0) * (end - begin);
      ctx.progress(done_samples.fetch_add(n) + n, total);
      return r;
    };
    auto commit = [&](std::shared_ptr<TileResult> r) {
      for (const Splat& sp : r->out.splats)
        if (!is_black(sp.value)) film.add_splat(sp.p_raster, sp.value);
      if (commit_tagged)
        for (const TaggedSplat& t : r->out.tagged) commit_tagged(t);
    };

    tbb::parallel_pipeline(
        tokens,
        tbb::make_filter<void, std::shared_ptr<TileResult>>(tbb::filter_mode::serial_in_order, source) &
            tbb::make_filter<std::shared_ptr<TileResult>, std::shared_ptr<TileResult>>(tbb::filter_mode::parallel,
                                                                                     render_tile) &
            tbb::make_filter<std::shared_ptr<TileResult>, void>(tbb::filter_mode::serial_in_order, commit));

    done_spp = end;
    ctx.set_completed_spp(done_spp);
    double now = ctx.elapsed();
    if (opt.time_budget > 0.0 && now >= opt.time_budget) break;
    // As in PixelIntegrator: short passes first, then longer ones, never much past a time budget.
    pass_spp = pass_options.one_sample_per_pass ? 1 : std::min(pass_spp * 2, 16);
    if (opt.time_budget > 0.0) {
      double per_spp = (now - pass_start) / (end - begin);
      if (per_spp > 0.0) pass_spp = std::clamp(static_cast<int>((opt.time_budget - now) / per_spp), 1, pass_spp);
    }
  }
  return done_spp;
}

}  // namespace penumbra::bdpt
