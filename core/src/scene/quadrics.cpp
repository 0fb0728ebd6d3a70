#include "scene/quadrics.h"

#include "scene/shape_sample_direction.h"

#include <cmath>

namespace penumbra {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Azimuth in [0, 2 pi).
double azimuth(const glm::dvec3& p) {
  double phi = std::atan2(p.y, p.x);
  return phi < 0.0 ? phi + 2.0 * kPi : phi;
}

}  // namespace

Quadric::Quadric(const Mat4& object_to_world, bool flip_normal)
    : to_world_(object_to_world), to_object_(glm::inverse(glm::dmat4(object_to_world))),
      normal_to_world_(glm::transpose(glm::inverse(glm::dmat3(object_to_world)))), flip_normal_(flip_normal) {}

std::optional<float> Quadric::intersect(const Ray& ray, float t_min, float t_max) const {
  glm::dvec3 o = glm::dvec3(to_object_ * glm::dvec4(glm::dvec3(ray.o), 1.0));
  glm::dvec3 d = glm::dmat3(to_object_) * glm::dvec3(ray.d);
  std::optional<double> t = intersect_object(o, d, t_min, t_max);
  if (!t) return std::nullopt;
  return static_cast<float>(*t);
}

Quadric::Surface Quadric::surface_at(const Ray& ray, float t) const {
  glm::dvec3 o = glm::dvec3(to_object_ * glm::dvec4(glm::dvec3(ray.o), 1.0));
  glm::dvec3 d = glm::dmat3(to_object_) * glm::dvec3(ray.d);
  glm::dvec3 p_object = reproject(o + double(t) * d);
  Surface s;
  s.p = Vec3(to_world_ * glm::dvec4(p_object, 1.0));
  // The point is exact in double before rounding; the bound also covers the float transform.
  s.p_error = point_error_bound(s.p);
  Vec3 n = Vec3(glm::normalize(normal_to_world_ * object_normal(p_object)));
  s.n = flip_normal_ ? -n : n;
  s.uv = uv_at(p_object);
  glm::dvec3 dpdu, dpdv;
  object_uv_derivatives(p_object, &dpdu, &dpdv);
  s.dpdu = Vec3(glm::dmat3(to_world_) * dpdu);
  s.dpdv = Vec3(glm::dmat3(to_world_) * dpdv);
  return s;
}

Bounds3 Quadric::world_bounds() const {
  glm::dvec3 lo, hi;
  object_bounds(&lo, &hi);
  Bounds3 b;
  for (int k = 0; k < 8; ++k) {
    glm::dvec3 c((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
    Vec3 w(to_world_ * glm::dvec4(c, 1.0));
    b.extend(w - point_error_bound(w));
    b.extend(w + point_error_bound(w));
  }
  return b;
}

ShapeSample Quadric::make_sample(const glm::dvec3& p_object) const {
  ShapeSample s;
  s.p = Vec3(to_world_ * glm::dvec4(p_object, 1.0));
  Vec3 n = Vec3(glm::normalize(normal_to_world_ * object_normal(p_object)));
  s.n = flip_normal_ ? -n : n;
  s.uv = uv_at(p_object);
  s.pdf = 1.f / area();
  return s;
}

// By area, converted to solid angle at ctx.p (as pbrt-v4 does for disks and cylinders).
std::optional<ShapeSample> Quadric::sample_solid_angle(const ShapeSampleContext& ctx, Vec2 u) const {
  ShapeSample s = sample_area(u);
  area_sample_seen_from(s, ctx.p);
  if (!(s.pdf > 0.f) || std::isinf(s.pdf)) return std::nullopt;
  return s;
}

float Quadric::pdf_solid_angle(const ShapeSampleContext& ctx, const Vec3&, const Vec3& p_hit, const Vec3& n_hit) const {
  float pdf = area_to_solid_angle_pdf(1.f / area(), ctx.p, p_hit, n_hit);
  return std::isinf(pdf) ? 0.f : pdf;
}

// ---- Disk ----------------------------------------------------------------------------------------

Disk::Disk(const Mat4& m, bool flip_normal, float height, float radius, float inner_radius, float phi_max_degrees)
    : Quadric(m, flip_normal), height_(height), radius_(radius), inner_(inner_radius),
      phi_max_(phi_max_degrees * kPi / 180.0) {
  // An affine map scales every area in the plane z = height by |M e_x x M e_y|.
  glm::dmat3 l(to_world_);
  double scale = glm::length(glm::cross(l[0], l[1]));
  area_ = static_cast<float>(0.5 * phi_max_ * (radius_ * radius_ - inner_ * inner_) * scale);
}

std::optional<double> Disk::intersect_object(const glm::dvec3& o, const glm::dvec3& d, double t_min,
                                             double t_max) const {
  if (d.z == 0.0) return std::nullopt;
  double t = (height_ - o.z) / d.z;
  if (!(t > t_min && t < t_max)) return std::nullopt;
  glm::dvec3 p = o + t * d;
  double r2 = p.x * p.x + p.y * p.y;
  if (r2 > radius_ * radius_ || r2 < inner_ * inner_) return std::nullopt;
  if (phi_max_ < 2.0 * kPi && azimuth(p) > phi_max_) return std::nullopt;
  return t;
}

Vec2 Disk::uv_at(const glm::dvec3& p) const {
  double r = std::sqrt(p.x * p.x + p.y * p.y);
  return Vec2(static_cast<float>(azimuth(p) / phi_max_), static_cast<float>((radius_ - r) / (radius_ - inner_)));
}

// u = phi / phi_max, v = (radius - r) / (radius - inner), as pbrt-v4.
void Disk::object_uv_derivatives(const glm::dvec3& p, glm::dvec3* dpdu, glm::dvec3* dpdv) const {
  double r = std::sqrt(p.x * p.x + p.y * p.y);
  *dpdu = glm::dvec3(-phi_max_ * p.y, phi_max_ * p.x, 0.0);
  *dpdv = r > 0.0 ? glm::dvec3(p.x, p.y, 0.0) * ((inner_ - radius_) / r) : glm::dvec3(inner_ - radius_, 0.0, 0.0);
}

void Disk::object_bounds(glm::dvec3* lo, glm::dvec3* hi) const {
  *lo = glm::dvec3(-radius_, -radius_, height_);
  *hi = glm::dvec3(radius_, radius_, height_);
}

// Uniform over the annulus sector: r^2 uniform in [inner^2, radius^2], phi uniform.
ShapeSample Disk::sample_area(Vec2 u) const {
  double r = std::sqrt(inner_ * inner_ + double(u.x) * (radius_ * radius_ - inner_ * inner_));
  double phi = double(u.y) * phi_max_;
  return make_sample(glm::dvec3(r * std::cos(phi), r * std::sin(phi), height_));
}

// ---- Cylinder ------------------------------------------------------------------------------------

Cylinder::Cylinder(const Mat4& m, bool flip_normal, float radius, float z_min, float z_max, float phi_max_degrees)
    : Quadric(m, flip_normal), radius_(radius), z_min_(std::min(z_min, z_max)), z_max_(std::max(z_min, z_max)),
      phi_max_(phi_max_degrees * kPi / 180.0) {
  // The world area element is radius |M t(phi) x M e_z| dphi dz, t(phi) the unit tangent: constant
  // in phi for similarity-like cross-sections, otherwise integrated numerically (and then sampling
  // uniformly in phi is not uniform by area).
  glm::dmat3 l(to_world_);
  constexpr int kSteps = 1024;
  double sum = 0.0, lo = INFINITY, hi = 0.0;
  for (int k = 0; k < kSteps; ++k) {
    double phi = (k + 0.5) / kSteps * phi_max_;
    double j = glm::length(glm::cross(l * glm::dvec3(-std::sin(phi), std::cos(phi), 0.0), l[2]));
    sum += j;
    lo = std::min(lo, j);
    hi = std::max(hi, j);
  }
  area_ = static_cast<float>(radius_ * (z_max_ - z_min_) * phi_max_ * sum / kSteps);
  uniform_ = hi <= lo * (1.0 + 1e-5);
}

std::optional<double> Cylinder::intersect_object(const glm::dvec3& o, const glm::dvec3& d, double t_min,
                                                 double t_max) const {
  double a = d.x * d.x + d.y * d.y;
  if (a == 0.0) return std::nullopt;
  double b = 2.0 * (d.x * o.x + d.y * o.y), c = o.x * o.x + o.y * o.y - radius_ * radius_;
  double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) return std::nullopt;
  // The numerically stable pair of roots.
  double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
  double t0 = q / a, t1 = q != 0.0 ? c / q : t0;
  if (t0 > t1) std::swap(t0, t1);
  for (double t : {t0, t1}) {
    if (!(t > t_min && t < t_max)) continue;
    glm::dvec3 p = o + t * d;
    if (p.z < z_min_ || p.z > z_max_) continue;
    if (phi_max_ < 2.0 * kPi && azimuth(p) > phi_max_) continue;
    return t;
  }
  return std::nullopt;
}

glm::dvec3 Cylinder::reproject(const glm::dvec3& p) const {
  double r = std::sqrt(p.x * p.x + p.y * p.y);
  return r > 0.0 ? glm::dvec3(p.x * radius_ / r, p.y * radius_ / r, p.z) : glm::dvec3(radius_, 0.0, p.z);
}

Vec2 Cylinder::uv_at(const glm::dvec3& p) const {
  return Vec2(static_cast<float>(azimuth(p) / phi_max_), static_cast<float>((p.z - z_min_) / (z_max_ - z_min_)));
}

void Cylinder::object_uv_derivatives(const glm::dvec3& p, glm::dvec3* dpdu, glm::dvec3* dpdv) const {
  *dpdu = glm::dvec3(-phi_max_ * p.y, phi_max_ * p.x, 0.0);
  *dpdv = glm::dvec3(0.0, 0.0, z_max_ - z_min_);
}

void Cylinder::object_bounds(glm::dvec3* lo, glm::dvec3* hi) const {
  *lo = glm::dvec3(-radius_, -radius_, z_min_);
  *hi = glm::dvec3(radius_, radius_, z_max_);
}

ShapeSample Cylinder::sample_area(Vec2 u) const {
  double z = z_min_ + double(u.x) * (z_max_ - z_min_);
  double phi = double(u.y) * phi_max_;
  return make_sample(glm::dvec3(radius_ * std::cos(phi), radius_ * std::sin(phi), z));
}

}  // namespace penumbra
