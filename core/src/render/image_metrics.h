// Error metrics between an estimate I and a reference R, averaged over pixels and channels
// (docs/algorithms.md, "Image error metrics"). relMSE uses (I - R)^2 / (R^2 + eps) with eps = 0.01.
#pragma once

#include <penumbra/image.h>

namespace penumbra {

inline constexpr double kRelMseEpsilon = 0.01;

struct ImageErrors {
  double mse = 0, rmse = 0, rel_mse = 0, mae = 0;
  // Outlier-robust companions of rel_mse, over the per-pixel relative squared errors e_p (mean of the
  // pixel's channels of (I - R)^2 / (R^2 + eps), reference variance subtracted):
  double rel_mse_clamped = 0;  // mean of e_p after clamping each at the 99.9th percentile of e_p
  double rel_se_median = 0;    // median of e_p
  double worst_share = 0;      // share of sum e_p held by the worst 0.1 % of pixels (fireflies)
};

/// Errors of `image` against `reference` (same size; throws Error otherwise). When `reference_variance`
/// is given (per-channel variance of the reference's own estimate, same layout), it is subtracted from
/// the squared errors, since E[(I - R)^2] = MSE_true + Var(R) for an independent reference.
ImageErrors image_errors(const ImageRgb& image, const ImageRgb& reference,
                         const ImageRgb* reference_variance = nullptr);

/// Per-pixel variance of the mean of two independent half-references: Var((A + B) / 2) = E[(A - B)^2] / 4,
/// estimated per pixel by (A - B)^2 / 4. Also returns their mean in `mean`. Halves of unequal sample
/// counts n_a, n_b are combined with w_a = n_a / (n_a + n_b): R = w_a A + (1 - w_a) B, whose variance
/// w_a (1 - w_a) E[(A - B)^2] is estimated by w_a (1 - w_a) (A - B)^2.
ImageRgb half_reference_variance(const ImageRgb& a, const ImageRgb& b, ImageRgb* mean, double w_a = 0.5);

/// A two-halves reference's noise in relMSE units, from its mean R and per-pixel variance V
/// (half_reference_variance()), averaged over pixels and channels:
struct ReferenceNoise {
  /// mean V / (R^2 + eps): what a perfect image would still show against R, and what image_errors()
  /// subtracts. Its denominator holds the noise it measures, so a firefly in one half counts about 1
  /// in its pixel however far it is from the truth: it is no estimate of R's own error.
  double floor = 0;
  /// R's own error, E[(R - mu)^2] / (mu^2 + eps), estimated by V / (m^2 + eps) with m the mean of R
  /// over the pixel's (up to 8) neighbours: samples independent of the pixel's own, so a firefly is
  /// weighed against its surroundings as the truth would weigh it. On 12 reference pairs it was 0.91-1.24x
  /// of the error measured against long references, where `floor` was 0.04-1.9x (docs/algorithms.md,
  /// "A reference's own error").
  double error = 0;
};
ReferenceNoise reference_noise(const ImageRgb& reference, const ImageRgb& variance);

}  // namespace penumbra
