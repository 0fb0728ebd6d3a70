// What the core's shapes set on a solid-angle sample besides its density: ShapeSample::wi and
// ShapeSample::distance, seen from the context's point.
#pragma once

#include <penumbra/shape.h>

namespace penumbra {

/// Sets s.wi and s.distance for a sample seen from p.
inline void set_direction_from(ShapeSample& s, const Vec3& p) {
  Vec3 d = s.p - p;
  s.distance = glm::length(d);
  s.wi = d / s.distance;
}

/// area_to_solid_angle_pdf() on a sample from Shape::sample_area(): its density per solid angle at p,
/// its wi and distance.
inline void area_sample_seen_from(ShapeSample& s, const Vec3& p) {
  s.pdf = area_to_solid_angle_pdf(s.pdf, p, s.p, s.n, &s.wi, &s.distance);
}

}  // namespace penumbra
