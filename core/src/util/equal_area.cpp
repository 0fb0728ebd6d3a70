#include <penumbra/equal_area.h>

namespace penumbra {

Vec3 equal_area_square_to_sphere(Vec2 p) {
  float a = 2.f * p.x - 1.f, b = 2.f * p.y - 1.f;
  float abs_a = std::abs(a), abs_b = std::abs(b);
  // Positive inside the diamond (upper hemisphere), negative outside it.
  float signed_distance = 1.f - (abs_a + abs_b);
  float r = 1.f - std::abs(signed_distance);
  // Azimuth within the quadrant: 0 on the a axis, pi/2 on the b axis, linear along |a| + |b| = const.
  float phi = r == 0.f ? Pi / 4.f : (Pi / 4.f) * ((abs_b - abs_a) / r + 1.f);
  float z = std::copysign(1.f - r * r, signed_distance);
  float sin_theta = r * safe_sqrt(2.f - r * r);
  return Vec3(std::copysign(std::cos(phi) * sin_theta, a), std::copysign(std::sin(phi) * sin_theta, b), z);
}

Vec2 equal_area_sphere_to_square(const Vec3& d) {
  float x = std::abs(d.x), y = std::abs(d.y), z = std::abs(d.z);
  // r^2 = 1 - |z|, without the cancellation near the poles.
  float one_minus_z = z > 0.5f ? (x * x + y * y) / (1.f + z) : 1.f - z;
  float r = safe_sqrt(one_minus_z);
  // Fraction of the quadrant's azimuth, 0 on the x axis and 1 on the y axis.
  float t = (x == 0.f && y == 0.f) ? 0.f : std::atan2(y, x) * (2.f / Pi);
  float abs_b = t * r, abs_a = r - abs_b;
  if (d.z < 0.f) {
    // Lower hemisphere: the corner triangle, mirrored about the diamond's edge.
    float mirrored_a = 1.f - abs_b, mirrored_b = 1.f - abs_a;
    abs_a = mirrored_a;
    abs_b = mirrored_b;
  }
  float a = std::copysign(abs_a, d.x), b = std::copysign(abs_b, d.y);
  return Vec2(0.5f * (a + 1.f), 0.5f * (b + 1.f));
}

Vec2 wrap_equal_area_square(Vec2 p) {
  if (p.x < 0.f) {
    p = Vec2(-p.x, 1.f - p.y);
  } else if (p.x > 1.f) {
    p = Vec2(2.f - p.x, 1.f - p.y);
  }
  if (p.y < 0.f) {
    p = Vec2(1.f - p.x, -p.y);
  } else if (p.y > 1.f) {
    p = Vec2(1.f - p.x, 2.f - p.y);
  }
  return p;
}

}  // namespace penumbra
