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
/// estimated per pixel by (A - B)^2 / 4. Also returns their mean in `mean`.
ImageRgb half_reference_variance(const ImageRgb& a, const ImageRgb& b, ImageRgb* mean);

}  // namespace penumbra
