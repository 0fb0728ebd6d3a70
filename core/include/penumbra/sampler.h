// Samplers produce the random or quasi-random numbers of every pixel sample. A sample is a pure
// function of (pixel, sample index, dimension, seed), so images do not depend on thread scheduling.
// Integrators consume dimensions in a fixed order: get_pixel_2d() first, then the camera lens, then a
// fixed number per bounce.
#pragma once

#include <penumbra/math.h>
#include <penumbra/object.h>

#include <algorithm>
#include <cstdint>
#include <memory>

namespace penumbra {

class Sampler : public Object {
 public:
  ~Sampler() override;
  /// Samples per pixel the scene asked for ("integer pixelsamples"); the runtime may render more or
  /// fewer (--spp, --time), so any sample index must work.
  virtual int samples_per_pixel() const = 0;
  /// Starts sample `index` of `pixel`, with the dimension counter at `dimension`.
  virtual void start_pixel_sample(Point2i pixel, uint32_t index, uint32_t dimension = 0) = 0;
  virtual float get_1d() = 0;
  virtual Vec2 get_2d() = 0;
  /// The sample for the position inside the pixel (used for filter importance sampling).
  virtual Vec2 get_pixel_2d() = 0;
  /// An independent copy for another thread.
  virtual std::unique_ptr<Sampler> clone() const = 0;
};

/// Base for samplers whose every value is a function of (pixel, sample index, dimension), like
/// Halton and Sobol: implement start() (key the pixel and index) and value(dimension); this class keeps
/// the dimension counter and gives the pixel position dimensions 0 and 1, the best-stratified pair.
class DimensionSampler : public Sampler {
 public:
  void start_pixel_sample(Point2i pixel, uint32_t index, uint32_t dimension) final {
    dimension_ = dimension;
    start(pixel, index);
  }
  float get_1d() final { return value(dimension_++); }
  Vec2 get_2d() final {
    float x = value(dimension_++);
    return Vec2(x, value(dimension_++));
  }
  Vec2 get_pixel_2d() final {
    dimension_ = std::max(dimension_, 2u);
    return Vec2(value(0), value(1));
  }

 protected:
  virtual void start(Point2i pixel, uint32_t index) = 0;
  /// The sample's value in `dimension`, in [0, 1).
  virtual float value(uint32_t dimension) const = 0;

 private:
  uint32_t dimension_ = 0;
};

}  // namespace penumbra
