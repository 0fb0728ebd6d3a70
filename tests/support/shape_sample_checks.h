// Checks of what a shape's solid-angle sample carries besides its point and density.
#pragma once

#include <penumbra/shape.h>

#include <cmath>

namespace penumbra::test {

/// Whether s.wi and s.distance are the unit direction and the distance from `ref` to s.p (relative
/// 1e-5): lights take them instead of recomputing them (ShapeSample).
inline bool direction_fields_match(const ShapeSample& s, const Vec3& ref) {
  Vec3 d = s.p - ref;
  float len = glm::length(d);
  return std::abs(s.distance - len) <= 1e-5f * len && glm::length(s.wi - d / len) <= 1e-5f;
}

}  // namespace penumbra::test
