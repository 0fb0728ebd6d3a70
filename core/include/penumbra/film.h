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

/// What a pixel sample's camera ray first hit, for the auxiliary outputs (AOVs).
struct SurfaceSample {
  bool hit = false;
  Rgb albedo{0.f};   // one-sample estimate of the directional albedo (exact for diffuse surfaces)
  Vec3 normal{0.f};  // world-space shading normal
  float depth = 0.f; // distance along the unit-length camera ray
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
  /// Whether the albedo, normal or depth outputs were requested; only then need an integrator that
  /// owns its sample loop trace first hits for add_surface_sample().
  virtual bool wants_surface_samples() const { return false; }
  /// Adds the first hit of a pixel sample that add_sample() received with the same weight (same
  /// thread rule as add_sample).
  virtual void add_surface_sample(Point2i pixel, const SurfaceSample& s, float weight) {}
};

}  // namespace penumbra
