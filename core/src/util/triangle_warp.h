// The square-to-triangle map behind sample_uniform_triangle() (penumbra/sampling.h), inline for the
// core's hot caller (light samples on triangles); the SDK function returns the same values.
#pragma once

#include <penumbra/math.h>

#include <bit>
#include <cstdint>

namespace penumbra {

/// Heitz's low-distortion map (used by pbrt-v4): fold the square along its diagonal and shear each
/// half onto the triangle. Unlike the sqrt map it keeps neighbouring strata neighbours. Returns the
/// barycentrics of the second and third vertex. Both halves are computed and one is selected: a
/// branch on u would go either way at random. (GCC turns `?:` on floats back into a branch in the
/// baseline build, so the selects are on bits.)
inline Vec2 uniform_triangle_barycentrics(Vec2 u) {
  const uint32_t upper = -static_cast<uint32_t>(u.x < u.y);  // all ones or zero
  const float half_x = u.x / 2.f, half_y = u.y / 2.f;
  auto select = [upper](float if_upper, float otherwise) {
    return std::bit_cast<float>((std::bit_cast<uint32_t>(if_upper) & upper) |
                                (std::bit_cast<uint32_t>(otherwise) & ~upper));
  };
  return Vec2(select(half_x, u.x - half_y), select(u.y - half_x, half_y));
}

}  // namespace penumbra
