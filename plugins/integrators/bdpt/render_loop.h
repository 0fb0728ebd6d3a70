// The render loop of integrators that splat (light tracing, bidirectional path tracing): the passes
// and tiles of PixelIntegrator, but each pixel sample may also deposit values anywhere on the film.
// Splats are collected per tile and committed in tile order by a serial stage of a TBB pipeline, so
// the image is the same bit for bit for a given seed whatever the thread count or scheduling (the
// film's atomic adds alone would make the summation order, hence the rounding, vary).
#pragma once

#include <penumbra/integrator.h>

#include <functional>
#include <vector>

namespace penumbra::bdpt {

struct Splat {
  Vec2 p_raster;
  Rgb value;
};

/// A record for an integrator's own buffers (strategy images), committed in the same order.
struct TaggedSplat {
  int tag;
  Vec2 p_raster;
  Rgb weighted, unweighted;
  float weight;
};

struct SampleOutputs {
  std::vector<Splat> splats;
  std::vector<TaggedSplat> tagged;
};

/// One pixel sample: `sampler` has been started at (pixel, index) and has given the film and lens
/// positions of `cs`; returns the radiance for the pixel and appends any splats to `out`.
using PixelSampleFn = std::function<Rgb(Point2i pixel, uint32_t index, const CameraSample& cs, Sampler& sampler,
                                        SampleOutputs& out)>;
/// Receives tagged splats in a deterministic order (serially).
using TaggedCommitFn = std::function<void(const TaggedSplat&)>;

/// Integrators that share state across the pixel samples of one sample index (a light-vertex cache)
/// render one sample per pixel per pass and prepare that state before each pass.
struct PassOptions {
  bool one_sample_per_pass = false;
  std::function<void(uint32_t sample_index)> before_pass;  // called with the pass's sample index
};

/// Returns the samples per pixel completed (what the film divides splats by).
int render_with_splats(RenderContext& ctx, const PixelSampleFn& sample, const TaggedCommitFn& commit_tagged = {},
                       const PassOptions& pass_options = {});

}  // namespace penumbra::bdpt
