// The RGB film: double-precision accumulation of filtered pixel samples, a lazily allocated
// per-thread splat buffers summed in fixed point (deterministic), and filter importance sampling for box, triangle and Gaussian filters.
#pragma once

#include "image/film_aovs.h"
#include "image/splat_buffers.h"

#include <penumbra/film.h>
#include <penumbra/params.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

namespace penumbra {

/// A separable pixel filter that the film samples exactly (box, triangle) or by tabulation (Gaussian).
class PixelFilter {
 public:
  /// type: "box", "triangle" or "gaussian"; params as pbrt-v4 names them.
  PixelFilter(const std::string& type, const ParamSet& params, const FileLoc& loc);
  FilterSample sample(Vec2 u) const;
  Vec2 radius() const { return radius_; }
  const std::string& type() const { return type_; }
  /// The filter normalised to integral 1 along one axis, at offset x from a pixel centre: the share
  /// of a splat at that offset the pixel receives, so that splats are filtered as camera samples are.
  float normalized(float x, int axis) const;
  /// A box of radius 0.5: every point belongs to exactly one pixel, with weight 1.
  bool single_pixel() const { return shape_ == Shape::Box && radius_.x == 0.5f && radius_.y == 0.5f; }

 private:
  float sample_axis(float u, int axis, float* weight) const;
  float evaluate_axis(float x, int axis) const;
  Vec2 integral_{1.f};  // per axis, the integral of evaluate_axis over [-radius, radius]
  float eval_gaussian(float x, int axis) const;
  float gaussian(float x, int axis) const;
  std::string type_;
  enum class Shape { Box, Triangle, Gaussian } shape_;  // type_ as decided once (splats ask per pixel)
  Vec2 radius_;
  float sigma_ = 0.5f;
  Vec2 gaussian_at_radius_{0.f};  // Gaussian: exp(-r^2 / (2 sigma^2)) per axis, what eval_gaussian subtracts
  // Gaussian only: per axis, the inverse CDF at kInverseSize + 1 evenly spaced probabilities, so a
  // sample costs one lookup; the density is constant between entries, so f / pdf stays exact.
  static constexpr int kInverseSize = 1024;
  std::vector<float> inverse_cdf_[2];
  // Gaussian only: per axis, eval_gaussian at kGaussianIntervals + 1 evenly spaced points over
  // [-radius, radius]. The filter is this table interpolated linearly (gaussian()): within 5e-6 of the
  // shifted Gaussian for pbrt's default sigma 0.5, radius 1.5, and no exp() per camera sample, where
  // two of them were 3-4 % of a path tracer's time (docs/benchmarks.md).
  static constexpr int kGaussianIntervals = 1024;
  std::vector<float> gaussian_table_[2];
  Vec2 gaussian_scale_{0.f};  // per axis, kGaussianIntervals / (2 radius)
};

std::span<const ParamSpec> pixel_filter_params(const std::string& type);
std::span<const ParamSpec> film_rgb_params();

struct ImageRgb;

class FilmRgb final : public Film {
 public:
  FilmRgb(Point2i resolution, PixelFilter filter, AovSet aovs = {});
  /// Bytes a film of `resolution` with `aovs` holds, plus the images made from it when the render
  /// is written (the beauty, the AOV layers, one interleaved copy for the writer); without splats.
  static uint64_t estimated_bytes(Point2i resolution, const AovSet& aovs);
  Point2i resolution() const override { return resolution_; }
  FilterSample sample_filter(Vec2 u) const override { return filter_.sample(u); }
  void add_sample(Point2i pixel, const Rgb& L, float weight) override;
  void add_splat(const Vec2& p_raster, const Rgb& v) override;
  bool wants_surface_samples() const override { return aovs_ && aovs_->set().surface(); }
  void add_surface_sample(Point2i pixel, const SurfaceSample& s, float weight) override;
  /// Counts a discarded non-finite sample for the "nonfinite" AOV; thread-safe.
  void add_nonfinite(Point2i pixel);
  /// The image: weighted pixel means plus splats divided by `splat_spp`.
  ImageRgb image(double splat_spp) const;
  bool has_splats() const { return splats_.any(); }
  /// Firefly guard: samples and splats whose largest component exceeds `threshold` are counted
  /// (not clamped: clamping would bias the image).
  void set_firefly_threshold(float threshold) { firefly_threshold_ = threshold; }
  float firefly_threshold() const { return firefly_threshold_; }
  uint64_t firefly_count() const { return fireflies_.load(std::memory_order_relaxed); }
  /// Checkpoints: pixel sums, splat sums, AOV accumulators and the firefly count, exactly; load()
  /// expects a film made from the same scene and settings (sizes are checked).
  void save(StateWriter& out) const;
  void load(StateReader& in);
  /// The requested AOVs (empty when none were).
  AovSet aovs() const { return aovs_ ? aovs_->set() : AovSet{}; }
  std::vector<ImageLayer> aov_layers() const { return aovs_ ? aovs_->layers() : std::vector<ImageLayer>{}; }

 private:
  struct Pixel {
    double rgb[3] = {0, 0, 0};
    double weight = 0;
  };
  Point2i resolution_;
  PixelFilter filter_;
  std::vector<Pixel> pixels_;
  SplatBuffers splats_;  // per-thread fixed-point sums, allocated where splats land
  float firefly_threshold_ = Infinity;
  std::atomic<uint64_t> fireflies_{0};
  std::unique_ptr<FilmAovs> aovs_;  // null unless AOVs were requested
};

}  // namespace penumbra
