// pbrt-v4's disk and cylinder: analytic surfaces in object space under any affine transform, traced
// by Embree as user geometry (EmbreeScene::add_quadric), intersected in double precision, and sampled
// uniformly by area for area lights.
//
// Disk: the annulus innerradius <= r <= radius in the plane z = height, azimuth 0 <= phi <= phimax;
// normal +z. Cylinder: x^2 + y^2 = radius^2 for zmin <= z <= zmax, 0 <= phi <= phimax; normal
// outward. Both normals flip with ReverseOrientation or a handedness-changing transform (pbrt's rule).
// uv as pbrt-v4: u = phi / phimax; v = (radius - r) / (radius - innerradius) on a disk,
// (z - zmin) / (zmax - zmin) on a cylinder.
#pragma once

#include <penumbra/interaction.h>
#include <penumbra/scene.h>
#include <penumbra/shape.h>

#include <optional>

namespace penumbra {

class Quadric : public Shape {
 public:
  Quadric(const Mat4& object_to_world, bool flip_normal);

  /// Parametric distance of the first hit of the world-space ray in (t_min, t_max).
  std::optional<float> intersect(const Ray& ray, float t_min, float t_max) const;

  struct Surface {
    Vec3 p, p_error, n;
    Vec2 uv;
    Vec3 dpdu, dpdv;  // world-space derivatives of p by u and v (texture footprints)
  };
  /// The surface point of a hit that intersect() found at distance t.
  Surface surface_at(const Ray& ray, float t) const;
  Bounds3 world_bounds() const;
  /// Whether uniform sampling in the object-space parameters is uniform by world area (always for a
  /// disk; for a cylinder unless the transform stretches its cross-section unevenly). Area lights
  /// need it: their emission density is 1 / area.
  virtual bool area_is_uniform() const = 0;

  std::optional<ShapeSample> sample_solid_angle(const ShapeSampleContext& ctx, Vec2 u) const override;
  float pdf_solid_angle(const ShapeSampleContext& ctx, const Vec3& wi, const Vec3& p_hit,
                        const Vec3& n_hit) const override;

 protected:
  /// First hit in object space (o + t d, t in (t_min, t_max)), or none.
  virtual std::optional<double> intersect_object(const glm::dvec3& o, const glm::dvec3& d, double t_min,
                                                 double t_max) const = 0;
  /// Moves a point near the surface onto it; its normal (unnormalised, unflipped) and uv there.
  virtual glm::dvec3 reproject(const glm::dvec3& p) const = 0;
  virtual glm::dvec3 object_normal(const glm::dvec3& p) const = 0;
  virtual Vec2 uv_at(const glm::dvec3& p) const = 0;
  /// Object-space dp/du and dp/dv at a surface point.
  virtual void object_uv_derivatives(const glm::dvec3& p, glm::dvec3* dpdu, glm::dvec3* dpdv) const = 0;
  virtual void object_bounds(glm::dvec3* lo, glm::dvec3* hi) const = 0;
  /// A surface sample from an object-space point on the surface (pdf 1 / area).
  ShapeSample make_sample(const glm::dvec3& p_object) const;

  glm::dmat4 to_world_, to_object_;
  glm::dmat3 normal_to_world_;
  bool flip_normal_;
};

class Disk final : public Quadric {
 public:
  Disk(const Mat4& object_to_world, bool flip_normal, float height, float radius, float inner_radius,
       float phi_max_degrees);
  float area() const override { return area_; }
  ShapeSample sample_area(Vec2 u) const override;
  bool area_is_uniform() const override { return true; }

 private:
  std::optional<double> intersect_object(const glm::dvec3& o, const glm::dvec3& d, double t_min,
                                         double t_max) const override;
  glm::dvec3 reproject(const glm::dvec3& p) const override { return {p.x, p.y, height_}; }
  glm::dvec3 object_normal(const glm::dvec3&) const override { return {0.0, 0.0, 1.0}; }
  Vec2 uv_at(const glm::dvec3& p) const override;
  void object_uv_derivatives(const glm::dvec3& p, glm::dvec3* dpdu, glm::dvec3* dpdv) const override;
  void object_bounds(glm::dvec3* lo, glm::dvec3* hi) const override;

  double height_, radius_, inner_, phi_max_;
  float area_;
};

class Cylinder final : public Quadric {
 public:
  Cylinder(const Mat4& object_to_world, bool flip_normal, float radius, float z_min, float z_max,
           float phi_max_degrees);
  float area() const override { return area_; }
  ShapeSample sample_area(Vec2 u) const override;
  bool area_is_uniform() const override { return uniform_; }

 private:
  std::optional<double> intersect_object(const glm::dvec3& o, const glm::dvec3& d, double t_min,
                                         double t_max) const override;
  glm::dvec3 reproject(const glm::dvec3& p) const override;
  glm::dvec3 object_normal(const glm::dvec3& p) const override { return {p.x, p.y, 0.0}; }
  Vec2 uv_at(const glm::dvec3& p) const override;
  void object_uv_derivatives(const glm::dvec3& p, glm::dvec3* dpdu, glm::dvec3* dpdv) const override;
  void object_bounds(glm::dvec3* lo, glm::dvec3* hi) const override;

  double radius_, z_min_, z_max_, phi_max_;
  float area_;
  bool uniform_;
};

}  // namespace penumbra
