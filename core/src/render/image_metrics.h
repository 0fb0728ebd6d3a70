// Error metrics between an estimate I and a reference R, averaged over pixels and channels
// (docs/algorithms.md, "Image error metrics"). relMSE uses (I - R)^2 / (R^2 + eps) with eps = 0.01.
#pragma once

#include <penumbra/image.h>

namespace penumbra {

inline constexpr double kRelMseEpsilon = 0.01;

struct ImageErrors {
  double mse = 0, rmse = 0, rel_mse = 0, mae = 0;
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
