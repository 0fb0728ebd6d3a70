#include "scene/sphere.h"

#include "scene/shape_sample_direction.h"

#include <penumbra/sampling.h>

namespace penumbra {

Sphere::Sphere(const Mat4& m, float radius, bool inward) : inward_(inward) {
  center_ = Vec3(m[3]);
  float scale = glm::length(Vec3(m[0]));
  radius_ = radius * scale;
  world_to_object_rotation_ = glm::transpose(glm::mat3(m) / scale);
}

Vec3 Sphere::normal_at(const Vec3& p) const {
  Vec3 n = glm::normalize(p - center_);
  return inward_ ? -n : n;
}

std::optional<float> Sphere::solve(const Ray& ray, float t_min, float t_max) const {
  glm::dvec3 oc = glm::dvec3(ray.o) - glm::dvec3(center_);
  glm::dvec3 d(ray.d);
  double a = glm::dot(d, d);
  if (!(a > 0.0)) return std::nullopt;
  double b = glm::dot(oc, d);  // half the linear coefficient
  double r = radius_;
  // b^2 - a c without the cancellation: a |v|^2 = |oc x d|^2 (Lagrange's identity), v the line's
  // closest approach to the centre. The cross product needs no division, so a miss is known after a
  // few products; the division by a that v would take sat on the path of every query (perf).
  glm::dvec3 w = glm::cross(oc, d);
  double disc = a * r * r - glm::dot(w, w);
  if (disc < 0.0) return std::nullopt;
  double q = -(b + std::copysign(std::sqrt(disc), b));
  double c = glm::dot(oc, oc) - r * r;
  double t0 = q / a, t1 = q != 0.0 ? c / q : t0;
  if (t0 > t1) std::swap(t0, t1);
  for (double t : {t0, t1}) {  // compared after rounding, as Embree compares the float it is given
    float tf = static_cast<float>(t);
    if (tf > t_min && tf < t_max) return tf;
  }
  return std::nullopt;
}

Vec3 Sphere::reproject(const Vec3& p) const {
  Vec3 d = p - center_;
  return center_ + d * (radius_ / glm::length(d));
}

Vec2 Sphere::uv_at(const Vec3& p) const {
  Vec3 q = world_to_object_rotation_ * glm::normalize(p - center_);
  float phi = std::atan2(q.y, q.x);
  if (phi < 0.f) phi += 2.f * Pi;
  float theta = std::acos(std::clamp(q.z, -1.f, 1.f));
  return Vec2(phi * Inv2Pi, 1.f - theta * InvPi);
}

// u = phi / 2pi and v = 1 - theta / pi: dp/du = 2pi (-y, x, 0) and dp/dv = -pi dp/dtheta in object
// space, dp/dtheta = (z cos phi, z sin phi, -r sin theta).
void Sphere::uv_derivatives(const Vec3& p, Vec3* dpdu, Vec3* dpdv) const {
  Vec3 q = world_to_object_rotation_ * (p - center_);
  float rxy = std::sqrt(q.x * q.x + q.y * q.y);
  Vec3 du(-2.f * Pi * q.y, 2.f * Pi * q.x, 0.f), dv;
  if (rxy > 0.f) {
    float cos_phi = q.x / rxy, sin_phi = q.y / rxy;
    dv = -Pi * Vec3(q.z * cos_phi, q.z * sin_phi, -rxy);
  } else {  // at a pole: any tangent
    du = Vec3(2.f * Pi * radius_, 0.f, 0.f);
    dv = Vec3(0.f, Pi * radius_, 0.f);
  }
  glm::mat3 to_world = glm::transpose(world_to_object_rotation_);
  *dpdu = to_world * du;
  *dpdv = to_world * dv;
}

ShapeSample Sphere::sample_area(Vec2 u) const {
  Vec3 p = center_ + radius_ * sample_uniform_sphere(u);
  return ShapeSample{p, normal_at(p), uv_at(p), 1.f / area()};
}

// Cone sampling (pbrt's approach): the cone of directions from ctx.p that hit the sphere is sampled
// uniformly and the point on the sphere is found geometrically, which avoids a ray-sphere test.
std::optional<ShapeSample> Sphere::sample_solid_angle(const ShapeSampleContext& ctx, Vec2 u) const {
  Vec3 to_center = center_ - ctx.p;
  float dc2 = glm::dot(to_center, to_center);
  if (dc2 <= radius_ * radius_ * 1.0001f) {  // inside (or on) the sphere: sample by area
    ShapeSample s = sample_area(u);
    area_sample_seen_from(s, ctx.p);
    if (!(s.pdf > 0.f) || std::isinf(s.pdf)) return std::nullopt;
    return s;
  }
  float dc = std::sqrt(dc2);
  float sin2_max = radius_ * radius_ / dc2;
  float cos_max = safe_sqrt(1.f - sin2_max);
  float one_minus_cos_max = 1.f - cos_max;
  float cos_theta = (cos_max - 1.f) * u.x + 1.f;
  float sin2_theta = 1.f - cos_theta * cos_theta;
  // For cones under 1.5 degrees, 1 - cos loses its precision in float: use the Taylor series.
  if (sin2_max < 0.00068523f) {
    sin2_theta = sin2_max * u.x;
    cos_theta = std::sqrt(1.f - sin2_theta);
    one_minus_cos_max = sin2_max / 2.f;
  }
  // Angle alpha from the sphere centre to the sampled point.
  float cos_alpha = sin2_theta / std::sqrt(sin2_max) +
                    cos_theta * safe_sqrt(1.f - sin2_theta / sin2_max);
  float sin_alpha = safe_sqrt(1.f - cos_alpha * cos_alpha);
  float phi = u.y * 2.f * Pi;
  Frame frame(-to_center / dc);  // frame around the direction from the centre to ctx.p
  Vec3 n_obj = frame.to_world(Vec3(sin_alpha * std::cos(phi), sin_alpha * std::sin(phi), cos_alpha));
  Vec3 p = center_ + radius_ * n_obj;
  ShapeSample s{p, inward_ ? -n_obj : n_obj, uv_at(p), 1.f / (2.f * Pi * one_minus_cos_max)};
  set_direction_from(s, ctx.p);
  return s;
}

float Sphere::pdf_solid_angle(const ShapeSampleContext& ctx, const Vec3& wi, const Vec3& p_hit,
                              const Vec3& n_hit) const {
  Vec3 to_center = center_ - ctx.p;
  float dc2 = glm::dot(to_center, to_center);
  if (dc2 <= radius_ * radius_ * 1.0001f) {
    float pdf = area_to_solid_angle_pdf(1.f / area(), ctx.p, p_hit, n_hit);
    return std::isinf(pdf) ? 0.f : pdf;
  }
  float sin2_max = radius_ * radius_ / dc2;
  float one_minus_cos_max = sin2_max < 0.00068523f ? sin2_max / 2.f : 1.f - safe_sqrt(1.f - sin2_max);
  return 1.f / (2.f * Pi * one_minus_cos_max);
}

}  // namespace penumbra
