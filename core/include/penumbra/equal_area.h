// Clarberg's equal-area octahedral map between the unit square and the unit sphere, the
// parameterisation pbrt-v4 uses for environment images ("Fast Equal-Area Mapping of the (Hemi)Sphere
// using SIMD", Journal of Graphics Tools 13(3), 2008), used by environment images and the spherical
// camera. docs/environment-maps.md derives it.
//
// The square [0,1]^2 is moved to [-1,1]^2 with coordinates (a, b). The diamond |a| + |b| <= 1 holds
// the hemisphere z >= 0, the four corner triangles outside it hold z < 0; the corners are -z. With
// r = |a| + |b| inside the diamond (2 - |a| - |b| outside), z = +-(1 - r^2) and the azimuth within a
// quadrant grows linearly along the line of constant r, so equal areas of the square map to equal
// solid angles: the Jacobian is 4 pi everywhere.
#pragma once

#include <penumbra/math.h>

namespace penumbra {

/// Direction (unit length) of a point of [0,1]^2.
Vec3 equal_area_square_to_sphere(Vec2 p);

/// Point of [0,1]^2 of a unit direction. Accurate near the poles (1 - |z| is computed as
/// (x^2 + y^2) / (1 + |z|) there), so square -> sphere -> square round trips to float precision.
Vec2 equal_area_sphere_to_square(const Vec3& d);

/// A point up to one square width outside [0,1]^2 moved to the point inside that continues the map
/// across the border: the edges u = 0, u = 1 fold about v = 1/2 and the edges v = 0, v = 1 about
/// u = 1/2 (each edge is one half-meridian of the lower hemisphere, traversed from both ends). For
/// filters and pixel footprints that reach over the border.
Vec2 wrap_equal_area_square(Vec2 p);

}  // namespace penumbra
