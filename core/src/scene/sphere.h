// Full spheres, placed by a similarity transform (rotation, uniform scale, translation): intersected
// (as Embree user geometry, EmbreeScene::add_sphere), sampled and parameterised here.
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
  std::optional<float> intersect(const Ray& ray, float t_min, float t_max) const;
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
  Vec3 center_;
  float radius_;
  bool inward_;
  glm::mat3 world_to_object_rotation_;
};

}  // namespace penumbra
