// Colour: Penumbra renders in linear RGB with Rec.709 primaries (scene-linear sRGB).
#pragma once

#include <penumbra/math.h>

namespace penumbra {

/// Linear Rec.709 RGB radiance, reflectance or weight.
using Rgb = glm::vec3;

/// Relative luminance (Y) of linear Rec.709 RGB.
inline float luminance(const Rgb& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }
inline bool is_black(const Rgb& c) { return c.r == 0.f && c.g == 0.f && c.b == 0.f; }

}  // namespace penumbra
