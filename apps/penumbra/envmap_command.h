// `penumbra envmap`: converts an environment image between pbrt-v4's equal-area octahedral map and
// the equirectangular (latitude-longitude) layout, resampling by exact area weighting so that the
// mean radiance over the sphere is kept (docs/environment-maps.md).
#pragma once

#include <string>

namespace penumbra::cli {

struct EnvmapSettings {
  std::string input, output;
  std::string to;           // "equalarea" or "equirectangular"
  std::string from;         // empty: by the input's shape, as the "infinite" light decides
  int size = 0;             // output width; 0: about as many texels as the input
};

/// Converts and writes the image; prints the sphere means before and after. Returns the exit status.
int run_envmap(const EnvmapSettings& settings);

}  // namespace penumbra::cli
