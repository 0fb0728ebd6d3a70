// Auxiliary outputs (AOVs) the film can keep next to the beauty, each allocated only when asked for
// (Film "rgb" "string aovs" [ ... ] or --aov): first-hit albedo, shading normal and depth, the
// per-pixel sample count and filter-weight sum, the variance of the pixel estimate, and the count
// of discarded non-finite samples. docs/scene-format.md names the EXR channels.
#pragma once

#include "image/exr_layers.h"

#include <penumbra/error.h>
#include <penumbra/film.h>
#include <penumbra/integrator.h>

#include <atomic>
#include <memory>
#include <string>
#include <vector>

namespace penumbra {

struct AovSet {
  bool albedo = false, normal = false, depth = false, samples = false, variance = false, nonfinite = false;
  bool any() const { return albedo || normal || depth || samples || variance || nonfinite; }
  bool surface() const { return albedo || normal || depth; }
  /// Names in the documented order, e.g. "albedo,depth".
  std::string names() const;
};

inline constexpr const char* kAovNames = "albedo, normal, depth, samples, variance, nonfinite, all";

/// Parses AOV names; each string may hold a comma-separated list. Throws Error at `loc` for an
/// unknown name, listing the valid ones.
AovSet parse_aovs(const std::vector<std::string>& lists, const FileLoc& loc = {});

class FilmAovs {
 public:
  FilmAovs(Point2i resolution, AovSet set);
  const AovSet& set() const { return set_; }
  // Same threading rule as Film::add_sample, except add_nonfinite, which any thread may call.
  void add_sample(size_t pixel, const Rgb& L, float weight);
  void add_surface(size_t pixel, const SurfaceSample& s, float weight);
  void add_nonfinite(size_t pixel);
  /// Checkpoints: every accumulator, exactly.
  void save(StateWriter& out) const;
  void load(StateReader& in);
  /// The requested layers, in the documented order.
  std::vector<ImageLayer> layers() const;
  /// Bytes per pixel of the buffers for `set` plus the float layers made from them for the output.
  static uint64_t bytes_per_pixel(const AovSet& set);

 private:
  struct Moments {  // West's weighted incremental mean and sum of squared deviations, per channel
    double mean[3] = {0, 0, 0};
    double m2[3] = {0, 0, 0};
  };
  AovSet set_;
  size_t pixels_;
  std::vector<double> weight_;    // filter-weight sum (samples, variance, albedo, normal)
  std::vector<uint32_t> count_;   // finite samples added
  std::vector<Moments> moments_;  // variance
  std::vector<double> albedo_, normal_;  // weighted sums, 3 per pixel
  std::vector<float> depth_;      // nearest hit
  std::unique_ptr<std::atomic<uint32_t>[]> nonfinite_;
};

}  // namespace penumbra
