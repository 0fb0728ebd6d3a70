// Rays and surface hits, with robust spawning of secondary rays. Every hit point carries a
// conservative bound on its floating-point error (pbrt's approach); a new ray starts just outside
// that error box along the geometric normal, rounded away from the surface, so it neither re-hits
// its own surface nor starts far from it, at any distance from the origin or any scene scale.
#pragma once

#include <bit>
#include <cstdint>

#include <penumbra/color.h>
#include <penumbra/math.h>
#include <penumbra/texture.h>

#include <cmath>

namespace penumbra {

class Bsdf;
class Light;

/// A medium not known at this point: the medium is whatever the ray was in.
constexpr int kMediumUnknown = -2;

/// The media on the two sides of a surface (pbrt-v4's MediumInterface): indices into the scene's
/// media, -1 for vacuum. A surface whose two sides differ bounds a medium (a transition); one with
/// the same medium on both sides sits inside it; one with vacuum on both (the default) says nothing,
/// and rays keep the medium they were in, as in pbrt-v4.
struct MediumInterface {
  int16_t inside = -1, outside = -1;
  bool is_transition() const { return inside != outside; }
  /// The medium on the side that `d` points into (outside is where the geometric normal `ng`
  /// points), or kMediumUnknown when the surface says nothing.
  int toward(const Vec3& ng, const Vec3& d) const {
    if (!is_transition()) return inside >= 0 ? inside : kMediumUnknown;
    return d.x * ng.x + d.y * ng.y + d.z * ng.z > 0.f ? outside : inside;
  }
  /// The medium of a ray leaving the surface towards `d`, for a path that arrived in `current`.
  int leaving(const Vec3& ng, const Vec3& d, int current) const {
    int m = toward(ng, d);
    return m != kMediumUnknown ? m : current;
  }
};

/// The medium a straight segment runs through, from what its two ends say: `from` is the medium
/// the segment leaves its first end into (MediumInterface::leaving(), or kMediumUnknown for a
/// camera or light point), `to_side` MediumInterface::toward() at the end it reaches, looking back.
/// The leaving end decides, as it does for a ray in pbrt-v4; else the reached end; else vacuum (-1).
constexpr int segment_medium(int from, int to_side) {
  return from != kMediumUnknown ? from : to_side != kMediumUnknown ? to_side : -1;
}

struct Ray {
  Vec3 o;
  Vec3 d;
  float tmax = Infinity;
};

/// Bound on the relative error of a value computed by n float operations (pbrt's gamma_n).
constexpr float error_gamma(int n) {
  constexpr float eps = 0x1p-24f;
  return n * eps / (1.f - n * eps);
}

/// Error bound of a point known only by its coordinates (a light sample, a point handed to the SDK):
/// that of a barycentric interpolation of vertices of its own magnitude, plus a tiny absolute floor
/// for points near the origin.
inline Vec3 point_error_bound(const Vec3& p) { return error_gamma(7) * abs_each(p) + Vec3(1e-7f); }

/// The next float above (below) v, for finite v (pbrt's NextFloatUp/Down; std::nextafter is a libm
/// call several times slower, and this runs six times per spawned ray).
inline float next_float_up(float v) {
  if (std::isinf(v) && v > 0.f) return v;
  if (v == -0.f) v = 0.f;
  uint32_t u = std::bit_cast<uint32_t>(v);
  u = v >= 0.f ? u + 1 : u - 1;
  return std::bit_cast<float>(u);
}
inline float next_float_down(float v) {
  if (std::isinf(v) && v < 0.f) return v;
  if (v == 0.f) v = -0.f;
  uint32_t u = std::bit_cast<uint32_t>(v);
  u = v > 0.f ? u - 1 : u + 1;
  return std::bit_cast<float>(u);
}

/// Moves `p` (absolute error at most p_error per component) off a surface with geometric normal `n`
/// towards the side `w` points to: past the error box along n, each coordinate rounded away.
inline Vec3 offset_ray_origin(const Vec3& p, const Vec3& p_error, Vec3 n, const Vec3& w) {
  float d = glm::dot(abs_each(n), p_error);
  Vec3 offset = d * n;
  if (glm::dot(w, n) < 0.f) offset = -offset;
  Vec3 po = p + offset;
  for (int k = 0; k < 3; ++k) {
    if (offset[k] > 0.f) po[k] = next_float_up(po[k]);
    else if (offset[k] < 0.f) po[k] = next_float_down(po[k]);
  }
  return po;
}

inline Vec3 offset_ray_origin(const Vec3& p, const Vec3& n, const Vec3& w) {
  return offset_ray_origin(p, point_error_bound(p), n, w);
}

/// A ray from a surface point (p, ng) in direction d.
inline Ray spawn_ray(const Vec3& p, const Vec3& ng, const Vec3& d) {
  return Ray{offset_ray_origin(p, ng, d), d, Infinity};
}

/// A shadow ray between two points with error bounds e0, e1, both ends offset along their normals
/// (a zero normal for a point not on a surface: point light, camera); it stops just short of the target.
inline Ray spawn_ray_to(const Vec3& p0, const Vec3& e0, const Vec3& n0, const Vec3& p1, const Vec3& e1,
                        const Vec3& n1) {
  Vec3 o = n0 == Vec3(0.f) ? p0 : offset_ray_origin(p0, e0, n0, p1 - p0);
  Vec3 target = n1 == Vec3(0.f) ? p1 : offset_ray_origin(p1, e1, n1, o - p1);
  return Ray{o, target - o, 1.f - 1e-4f};
}

inline Ray spawn_ray_to(const Vec3& p0, const Vec3& n0, const Vec3& p1, const Vec3& n1) {
  return spawn_ray_to(p0, point_error_bound(p0), n0, p1, point_error_bound(p1), n1);
}

/// Everything an integrator needs about a ray hit.
struct SurfaceInteraction {
  // Every member starts at zero (the frame at the axes) through its own initialiser. The constructor
  // is user-provided so that value-initialisation (std::optional::emplace(), `SurfaceInteraction{}`)
  // runs just these stores: with an implicit one, GCC first zero-fills the whole object with
  // `rep stos`, whose start-up cost was 3-4 % of a path tracer's time (docs/benchmarks.md).
  SurfaceInteraction() {}

  Vec3 p{0.f};       // hit point, reconstructed from the primitive (not o + t d)
  Vec3 p_error{0.f}; // bound on the absolute error of p, per component
  Vec3 ng{0.f};      // geometric normal, oriented as the shape defines its outside
  Vec3 ns{0.f};      // shading normal, in the same hemisphere as ng
  Vec2 uv{0.f};      // surface parameterisation
  // Texture lookups, filled only where the hit's material has textured parameters (otherwise zero):
  // the footprint of a pixel at the hit, estimated from the camera (Camera::approximate_dp_dxy)
  // and turned into (u, v) differences by least squares with the parameterisation's dp/du, dp/dv.
  Vec3 dpdx{0.f}, dpdy{0.f};
  float dudx = 0.f, dudy = 0.f, dvdx = 0.f, dvdy = 0.f;
  Vec3 wo{0.f};      // unit direction back along the incoming ray
  float t = 0.f;     // ray parameter of the hit
  Frame shading;     // frame around ns: BSDFs work in it
  const Bsdf* bsdf = nullptr;         // material at the hit (never null for scene geometry)
  const Light* area_light = nullptr;  // emitter on this primitive, if any
  uint32_t shape_id = 0, prim_id = 0;
  MediumInterface media;              // media on the two sides (vacuum on both unless the scene says)

  TextureEvalContext texture_context() const {
    return TextureEvalContext{p, ng, uv, dpdx, dpdy, dudx, dudy, dvdx, dvdy};
  }

  Ray spawn_ray(const Vec3& d) const { return Ray{offset_ray_origin(p, p_error, ng, d), d, Infinity}; }
  /// Shadow ray to a point p1 (normal n1, zero if none) whose error is estimated from its magnitude.
  Ray spawn_ray_to(const Vec3& p1, const Vec3& n1) const {
    return penumbra::spawn_ray_to(p, p_error, ng, p1, point_error_bound(p1), n1);
  }
};

}  // namespace penumbra
