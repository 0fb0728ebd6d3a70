// Full spheres, placed by a similarity transform (rotation, uniform scale, translation): intersected
// (as Embree user geometry, or by EmbreeScene's own loop for up to four), sampled and parameterised here.
#pragma once

#include <penumbra/interaction.h>
#include <penumbra/shape.h>

#include <optional>

namespace penumbra {

/// Float arithmetic that says "missed" only when the ray o + t d surely misses the sphere of centre c
/// and squared radius r2: its line passes the centre farther than the radius by a margin far above
/// float rounding, or the origin is clearly outside and the ray points away. Scenes that test their
/// few spheres for every ray (EmbreeScene, "spheres outside Embree") spent 8 % of bdpt's time in the
/// out-of-line solve() without it. Without branches and generic in F: for float it answers a bool,
/// for a GCC vector of floats (EmbreeScene's four spheres at once) a lane mask.
template <class F>
inline auto sphere_surely_missed(F ox, F oy, F oz, F dx, F dy, F dz, F cx, F cy, F cz, F r2) {
  F ocx = ox - cx, ocy = oy - cy, ocz = oz - cz;
  F oc2 = ocx * ocx + ocy * ocy + ocz * ocz;
  F oc_d = ocx * dx + ocy * dy + ocz * dz;
  // |oc x d|^2 = a * (squared distance of the line from the centre); its float error is a few ulps of
  // a * |oc|^2, so a margin of 1e-4 of that is safe.
  F wx = ocy * dz - dy * ocz, wy = ocz * dx - dz * ocx, wz = ocx * dy - dx * ocy;
  F w2 = wx * wx + wy * wy + wz * wz;
  F a = dx * dx + dy * dy + dz * dz;
  return ((oc2 > r2 * 1.01f) & (oc_d >= 0.f)) | (w2 > a * (r2 + 1e-4f * oc2));
}

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
  bool surely_missed(const Ray& ray) const {
    return sphere_surely_missed<float>(ray.o.x, ray.o.y, ray.o.z, ray.d.x, ray.d.y, ray.d.z, center_.x,
                                       center_.y, center_.z, radius_ * radius_);
  }
  Vec3 center_;
  float radius_;
  bool inward_;
  glm::mat3 world_to_object_rotation_;
};

}  // namespace penumbra
