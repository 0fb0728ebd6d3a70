// Small statistics over rendered images for whole-render tests.
#pragma once

#include "image/image_io.h"

#include <algorithm>
#include <cmath>
#include <functional>

namespace penumbra::test {

inline double mean_channel(const ImageRgb& img, int c) {
  double s = 0;
  for (int i = 0; i < img.width * img.height; ++i) s += img.pixels[3 * i + c];
  return s / (img.width * img.height);
}

inline double mean_luminance_free(const ImageRgb& img) {
  return (mean_channel(img, 0) + mean_channel(img, 1) + mean_channel(img, 2)) / 3.0;
}

/// Standard error of mean_channel(img, c) from the spread of the pixels (independent pixels: each
/// is its own mean of independent samples, so the pixels' variance over their count measures it).
inline double standard_error_of_mean(const ImageRgb& img, int c) {
  double mean = mean_channel(img, c), sum2 = 0.0;
  size_t n = img.pixels.size() / 3;
  for (size_t i = 0; i < n; ++i) sum2 += (img.pixels[3 * i + c] - mean) * (img.pixels[3 * i + c] - mean);
  return std::sqrt(sum2 / (n - 1) / n);
}

struct SeedMean {
  double mean = 0.0;
  double standard_error = 0.0;  // of the mean, from the spread of the runs
};

/// The mean of measure(seed) over seeds 1..runs (runs >= 2) and its standard error: for agreement
/// tests whose tolerance comes from measured variance. Whole-image means of independent renders
/// measure the error even where splats correlate neighbouring pixels.
inline SeedMean mean_over_seeds(int runs, const std::function<double(int seed)>& measure) {
  double sum = 0.0, sum2 = 0.0;
  for (int seed = 1; seed <= runs; ++seed) {
    double m = measure(seed);
    sum += m;
    sum2 += m * m;
  }
  double mean = sum / runs, var = std::max(0.0, (sum2 - runs * mean * mean) / (runs - 1));
  return SeedMean{mean, std::sqrt(var / runs)};
}

inline int count_nonfinite(const ImageRgb& img) {
  int n = 0;
  for (float v : img.pixels) n += std::isfinite(v) ? 0 : 1;
  return n;
}

inline float max_abs_pixel_deviation(const ImageRgb& img, double expected) {
  float m = 0;
  for (float v : img.pixels) m = std::max(m, static_cast<float>(std::abs(v - expected)));
  return m;
}

}  // namespace penumbra::test
