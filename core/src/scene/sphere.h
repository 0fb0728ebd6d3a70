// Full spheres, placed by a similarity transform (rotation, uniform scale, translation): intersected
// (as Embree user geometry, or by EmbreeScene's own loop for up to four), sampled and parameterised here.
#pragma once

#include <penumbra/interaction.h>
#include <penumbra/shape.h>

#include <optional>

namespace penumbra {

class Sphere final : public Shape {
 public:
  /// `object_to_world` must be a similarity transform; `inward` flips the normal inside.
  Sphere(const Mat4& object_to_world, float radius, bool inward);
  Vec3 center() const { return center_; }
  float radius() const { return radius_; }
  /// Normal at a point on the surface, oriented (outward unless ReverseOrientation).
  Vec3 normal_at(const Vec3& p) const;
  /// The nearest hit of the ray o + t d with t in (t_min, t_max), solved in double precision with
  /// the discriminant taken from the ray's closest approach to the centre (pbrt-v4's form, which
  /// stays accurate for small spheres far from the origin).
  std::optional<float> intersect(const Ray& ray, float t_min, float t_max) const {
    if (surely_missed(ray)) return std::nullopt;
    return solve(ray, t_min, t_max);
  }
  /// intersect() without its float pre-test for rays that surely miss: the same answer, slower.
  std::optional<float> solve(const Ray& ray, float t_min, float t_max) const;
  /// Moves a point near the surface exactly onto it (removes the error of o + t d).
  Vec3 reproject(const Vec3& p) const;
  Vec2 uv_at(const Vec3& p) const;
  /// dp/du and dp/dv of uv_at() at a surface point (pbrt's full-sphere parameterisation).
  void uv_derivatives(const Vec3& p, Vec3* dpdu, Vec3* dpdv) const;

  float area() const override { return 4.f * Pi * radius_ * radius_; }
  ShapeSample sample_area(Vec2 u) const override;
  /// Uniform within the cone the sphere subtends from outside; by area from inside.
  std::optional<ShapeSample> sample_solid_angle(const ShapeSampleContext& ctx, Vec2 u) const override;
  float pdf_solid_angle(const ShapeSampleContext& ctx, const Vec3& wi, const Vec3& p_hit,
                        const Vec3& n_hit) const override;

 private:
  // Float arithmetic that says "missed" only when the ray surely misses: the line passes the centre
  // farther than the radius by a margin far above float rounding, or the origin is clearly outside
  // and the ray points away. A scene that tests its few spheres for every ray (EmbreeScene, "spheres
  // outside Embree") spent 8 % of bdpt's time in the out-of-line solve() otherwise, much of it
  // returning the optional through memory. Inline, so a miss costs no call.
  bool surely_missed(const Ray& ray) const {
    Vec3 oc = ray.o - center_;
    float r2 = radius_ * radius_, oc2 = glm::dot(oc, oc);
    if (oc2 > r2 * 1.01f && glm::dot(oc, ray.d) >= 0.f) return true;  // outside, moving away
    // |oc x d|^2 = a * (squared distance of the line from the centre); its float error is a few
    // ulps of a * |oc|^2, so a margin of 1e-4 of that is safe.
    Vec3 w = glm::cross(oc, ray.d);
    float a = glm::dot(ray.d, ray.d);
    return glm::dot(w, w) > a * (r2 + 1e-4f * oc2);
  }
  Vec3 center_;
  float radius_;
  bool inward_;
  glm::mat3 world_to_object_rotation_;
};

}  // namespace penumbra
