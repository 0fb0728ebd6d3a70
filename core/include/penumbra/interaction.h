// Rays and surface hits, with robust spawning of secondary rays: origins are pushed off the surface
// along the geometric normal by a few ULPs (Waechter and Binder, Ray Tracing Gems ch. 6), so a new
// ray neither re-hits its own surface nor leaks through thin geometry, whatever the distance from the
// origin.
#pragma once

#include <penumbra/color.h>
#include <penumbra/math.h>

#include <cstring>

namespace penumbra {

class Bsdf;
class Light;

struct Ray {
  Vec3 o;
  Vec3 d;
  float tmax = Infinity;
};

/// Moves `p` off a surface with geometric normal `n` towards the side `w` points to.
inline Vec3 offset_ray_origin(const Vec3& p, Vec3 n, const Vec3& w) {
  constexpr float origin = 1.f / 32.f, float_scale = 1.f / 65536.f, int_scale = 256.f;
  if (glm::dot(n, w) < 0.f) n = -n;
  Vec3 out;
  for (int k = 0; k < 3; ++k) {
    int32_t of_i = static_cast<int32_t>(int_scale * n[k]);
    int32_t bits;
    std::memcpy(&bits, &p[k], sizeof bits);
    bits += (p[k] < 0.f) ? -of_i : of_i;
    float p_i;
    std::memcpy(&p_i, &bits, sizeof p_i);
    out[k] = std::abs(p[k]) < origin ? p[k] + float_scale * n[k] : p_i;
  }
  return out;
}

/// A ray from a surface point (p, ng) in direction d.
inline Ray spawn_ray(const Vec3& p, const Vec3& ng, const Vec3& d) {
  return Ray{offset_ray_origin(p, ng, d), d, Infinity};
}

/// A shadow ray between two surface points, both ends offset; it stops just short of the target.
/// Pass a zero normal for a point not on a surface (point light, camera).
inline Ray spawn_ray_to(const Vec3& p0, const Vec3& n0, const Vec3& p1, const Vec3& n1) {
  Vec3 o = n0 == Vec3(0.f) ? p0 : offset_ray_origin(p0, n0, p1 - p0);
  Vec3 target = n1 == Vec3(0.f) ? p1 : offset_ray_origin(p1, n1, o - p1);
  return Ray{o, target - o, 1.f - 1e-4f};
}

/// Everything an integrator needs about a ray hit.
struct SurfaceInteraction {
  Vec3 p;            // hit point, reconstructed from the primitive (not o + t d)
  Vec3 ng;           // geometric normal, oriented as the shape defines its outside
  Vec3 ns;           // shading normal, in the same hemisphere as ng
  Vec2 uv;           // surface parameterisation
  Vec3 wo;           // unit direction back along the incoming ray
  float t = 0.f;     // ray parameter of the hit
  Frame shading;     // frame around ns: BSDFs work in it
  const Bsdf* bsdf = nullptr;         // material at the hit (never null for scene geometry)
  const Light* area_light = nullptr;  // emitter on this primitive, if any
  uint32_t shape_id = 0, prim_id = 0;

  Ray spawn_ray(const Vec3& d) const { return penumbra::spawn_ray(p, ng, d); }
};

}  // namespace penumbra
