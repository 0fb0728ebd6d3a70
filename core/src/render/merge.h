// `penumbra merge`: combines the parts of a split render (docs/farm.md) into one image.
#pragma once

#include "image/exr_layers.h"

#include <string>
#include <vector>

namespace penumbra {

struct MergeResult {
  LayeredImage image;
  int samples = 0, spp_total = 0;
  std::vector<std::string> notes;  // layers dropped, samples missing
};

/// Reads the parts and combines them: beauty, albedo and normal as means weighted by each part's
/// per-pixel filter-weight sum (samples.weight), sample counts, weights and non-finite counts
/// summed, depth as the nearest, variance by Chan et al.'s pairwise formula. Refuses (Error naming
/// the files) parts of another Penumbra version, scene, resolution, seed, integrator or sampler,
/// parts whose sample ranges overlap, and parts without the "samples" layer.
MergeResult merge_parts(const std::vector<std::string>& paths);

}  // namespace penumbra
