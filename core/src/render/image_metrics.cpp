#include "render/image_metrics.h"

#include <penumbra/error.h>

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace penumbra {

static void check_same_size(const ImageRgb& a, const ImageRgb& b) {
  if (a.width != b.width || a.height != b.height || a.pixels.size() != b.pixels.size())
    throw Error(fmt::format("images differ in size: {}x{} and {}x{}", a.width, a.height, b.width, b.height));
}

ImageErrors image_errors(const ImageRgb& image, const ImageRgb& reference, const ImageRgb* reference_variance) {
  check_same_size(image, reference);
  if (reference_variance) check_same_size(image, *reference_variance);
  double se = 0, rel = 0, ae = 0;
  size_t n = image.pixels.size();
  std::vector<double> per_pixel(n / 3, 0.0);
  for (size_t i = 0; i < n; ++i) {
    double r = reference.pixels[i], d = image.pixels[i] - r;
    double d2 = d * d - (reference_variance ? reference_variance->pixels[i] : 0.0);
    se += d2;
    rel += d2 / (r * r + kRelMseEpsilon);
    ae += std::abs(d);
    per_pixel[i / 3] += d2 / (r * r + kRelMseEpsilon) / 3.0;
  }
  ImageErrors e;
  if (!per_pixel.empty()) {
    std::vector<double> sorted = per_pixel;
    std::sort(sorted.begin(), sorted.end());
    size_t m = sorted.size();
    e.rel_se_median = m % 2 ? sorted[m / 2] : 0.5 * (sorted[m / 2 - 1] + sorted[m / 2]);
    double cap = sorted[std::min(m - 1, static_cast<size_t>(std::ceil(0.999 * m)) - 1)];
    size_t worst = std::max<size_t>(1, m / 1000);
    double total = 0, clamped = 0, top = 0;
    for (size_t k = 0; k < m; ++k) {
      total += sorted[k];
      clamped += std::min(sorted[k], cap);
      if (k >= m - worst) top += sorted[k];
    }
    e.rel_mse_clamped = clamped / m;
    e.worst_share = total > 0 ? std::clamp(top / total, 0.0, 1.0) : 0.0;
  }
  e.mse = n ? se / n : 0.0;
  e.rmse = std::sqrt(std::max(0.0, e.mse));
  e.rel_mse = n ? rel / n : 0.0;
  e.mae = n ? ae / n : 0.0;
  return e;
}

ImageRgb half_reference_variance(const ImageRgb& a, const ImageRgb& b, ImageRgb* mean, double w_a) {
  check_same_size(a, b);
  if (!(w_a > 0.0 && w_a < 1.0)) throw Error(fmt::format("half-reference weight {} is not in (0, 1)", w_a));
  ImageRgb var = a;
  if (mean) *mean = a;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    double d = a.pixels[i] - b.pixels[i];
    var.pixels[i] = static_cast<float>(w_a * (1.0 - w_a) * d * d);
    if (mean) mean->pixels[i] = static_cast<float>(w_a * a.pixels[i] + (1.0 - w_a) * b.pixels[i]);
  }
  return var;
}

ReferenceNoise reference_noise(const ImageRgb& reference, const ImageRgb& variance) {
  check_same_size(reference, variance);
  ReferenceNoise n;
  const int w = reference.width, h = reference.height;
  if (reference.pixels.empty()) return n;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        const size_t i = 3 * (static_cast<size_t>(y) * w + x) + c;
        double r = reference.pixels[i], v = std::max(0.0, static_cast<double>(variance.pixels[i]));
        double sum = 0;
        int count = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            int nx = x + dx, ny = y + dy;
            if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
            sum += reference.pixels[3 * (static_cast<size_t>(ny) * w + nx) + c];
            ++count;
          }
        double m = count ? sum / count : r;  // a 1x1 image has no neighbours
        n.floor += v / (r * r + kRelMseEpsilon);
        n.error += v / (m * m + kRelMseEpsilon);
      }
  n.floor /= static_cast<double>(reference.pixels.size());
  n.error /= static_cast<double>(reference.pixels.size());
  return n;
}

}  // namespace penumbra
