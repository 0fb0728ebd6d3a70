// Vector math for plugins: GLM types under short names, constants, an orthonormal frame and a few
// helpers every renderer needs. Geometry is single precision; accumulation is done in double by the film.
#pragma once

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace penumbra {

using Vec2 = glm::vec2;
using Vec3 = glm::vec3;
using Vec4 = glm::vec4;
using Point2i = glm::ivec2;
using Mat4 = glm::mat4;

inline constexpr float Pi = 3.14159265358979323846f;
inline constexpr float InvPi = 0.31830988618379067154f;
inline constexpr float Inv2Pi = 0.15915494309189533577f;
inline constexpr float Inv4Pi = 0.07957747154594766788f;
inline constexpr float Infinity = std::numeric_limits<float>::infinity();
/// Largest float below 1: samples live in [0, OneMinusEpsilon].
inline constexpr float OneMinusEpsilon = 0x1.fffffep-1f;

inline float sqr(float x) { return x * x; }
inline float safe_sqrt(float x) { return std::sqrt(std::max(0.f, x)); }
inline float radians(float deg) { return deg * (Pi / 180.f); }
inline bool is_finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
inline float max_component(const Vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }
/// |v| per component by clearing the sign bits. glm::abs computes x >= 0 ? x : -x, which keeps the
/// sign of -0 and so compiles to a compare and a blend per component.
inline Vec3 abs_each(const Vec3& v) { return Vec3(std::abs(v.x), std::abs(v.y), std::abs(v.z)); }

/// Orthonormal basis around a unit normal (Duff et al. 2017, branchless).
struct Frame {
  Vec3 s, t, n;
  Frame() : s(1, 0, 0), t(0, 1, 0), n(0, 0, 1) {}
  explicit Frame(const Vec3& normal) : n(normal) {
    float sign = std::copysign(1.f, n.z);
    float a = -1.f / (sign + n.z);
    float b = n.x * n.y * a;
    s = Vec3(1.f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    t = Vec3(b, sign + n.y * n.y * a, -n.y);
  }
  Vec3 to_local(const Vec3& v) const { return {glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)}; }
  Vec3 to_world(const Vec3& v) const { return s * v.x + t * v.y + n * v.z; }
};

/// Direction helpers in a local shading frame where the normal is +z.
inline float cos_theta(const Vec3& w) { return w.z; }
inline float abs_cos_theta(const Vec3& w) { return std::abs(w.z); }
inline bool same_hemisphere(const Vec3& a, const Vec3& b) { return a.z * b.z > 0.f; }

}  // namespace penumbra
