// The film accumulates pixel samples in double precision. Pixel samples are placed by filter
// importance sampling: the integrator asks the film for an offset inside the filter's support and a
// weight, and adds the sample to the pixel it was taken for. Splats (light tracing, photons) may land
// anywhere and are thread-safe.
#pragma once

#include <penumbra/color.h>
#include <penumbra/math.h>

namespace penumbra {

struct FilterSample {
  Vec2 offset;   // from the pixel centre, in pixels
  float weight;  // filter value over sampling density (1 for box, tent and Gaussian sampled exactly)
};

class Film {
 public:
  virtual ~Film();
  virtual Point2i resolution() const = 0;
  /// Maps a uniform 2D sample to a position in the filter's support.
  virtual FilterSample sample_filter(Vec2 u) const = 0;
  /// Adds a weighted sample to a pixel. Only the thread that owns the pixel's tile may call this.
  virtual void add_sample(Point2i pixel, const Rgb& L, float weight) = 0;
  /// Adds radiance at a raster position from any thread; splats are divided by the total number of
  /// samples per pixel when the image is written.
  virtual void add_splat(const Vec2& p_raster, const Rgb& v) = 0;
};

}  // namespace penumbra
