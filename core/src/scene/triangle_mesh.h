// Triangle meshes in world space, and their triangles as sampleable shapes for area lights.
#pragma once

#include <penumbra/shape.h>

#include <vector>

namespace penumbra {

struct SurfaceInteraction;

struct TriangleMesh {
  std::vector<Vec3> P;       // world-space positions
  std::vector<Vec3> N;       // world-space shading normals (optional), already flipped by ReverseOrientation
  std::vector<Vec2> uv;      // optional
  std::vector<uint32_t> indices;
  bool flip_normal = false;  // ReverseOrientation xor a handedness-swapping transform (used without N)
  std::vector<Vec3> face_normals;  // unit normals by the winding (finish() fills them)

  /// Computes what hits need per triangle (the face normals); call once the mesh is complete.
  void finish();

  size_t triangle_count() const { return indices.size() / 3; }
  /// Geometric normal of triangle i, oriented by pbrt's rules (towards N when given, else by the
  /// winding, flipped by flip_normal).
  Vec3 geometric_normal(size_t i, const Vec3& b) const;
  Vec3 shading_normal(size_t i, const Vec3& b) const;  // interpolated N, or zero without N
  Vec2 uv_at(size_t i, const Vec3& b) const;
  Vec3 position(size_t i, const Vec3& b) const;
  /// Error bound of position(): gamma_7 (|b0 p0| + |b1 p1| + |b2 p2|) per component (pbrt-v3).
  Vec3 position_error(size_t i, const Vec3& b) const;
  float area(size_t i) const;

  /// What a hit at barycentrics b of triangle i needs (point, error bound, oriented geometric and
  /// shading normals, uv), written into si; embree_ng is the unnormalised normal Embree reports for
  /// the hit (RTCHit::Ng).
  void surface(size_t i, const Vec3& b, const Vec3& embree_ng, SurfaceInteraction& si) const;
  /// surface(), always inlined (scene/triangle_surface.h): for the scene's hit path, which then
  /// calls nothing for a triangle hit.
  [[gnu::always_inline]] inline void fill_surface(size_t i, const Vec3& b, const Vec3& embree_ng,
                                                  SurfaceInteraction& si) const;
  /// dp/du and dp/dv of triangle i (constant over it); for a degenerate uv mapping, two axes
  /// perpendicular to the face normal.
  void uv_derivatives(size_t i, Vec3* dpdu, Vec3* dpdv) const;

 private:
  Vec3 face_normal(size_t i) const;
  Vec3 oriented(const Vec3& n, const Vec3& ns) const;
};

class Triangle final : public Shape {
 public:
  Triangle(const TriangleMesh* mesh, uint32_t index);
  float area() const override { return area_; }
  ShapeSample sample_area(Vec2 u) const override;
  std::optional<ShapeSample> sample_solid_angle(const ShapeSampleContext& ctx, Vec2 u) const override;
  float pdf_solid_angle(const ShapeSampleContext& ctx, const Vec3& wi, const Vec3& p_hit,
                        const Vec3& n_hit) const override;

 private:
  bool spherical_worthwhile(const Vec3& p) const;
  /// ctx asks for the front only and cannot see it: nothing to sample (density 0).
  bool unseen_front(const ShapeSampleContext& ctx) const;
  /// sample_solid_angle() where spherical_worthwhile(): by solid angle where that is numerically safe.
  std::optional<ShapeSample> sample_spherical(const ShapeSampleContext& ctx, Vec2 u) const;
  std::optional<ShapeSample> sample_by_area(const ShapeSampleContext& ctx, Vec2 u) const;
  void area_sample_into(Vec2 u, ShapeSample& s) const;
  /// A sample uniform in area and its density per solid angle, direction and distance seen from
  /// `ref`; false where that density is zero or infinite.
  bool sample_area_seen_from(const Vec3& ref, Vec2 u, ShapeSample& s) const;
  /// Point, oriented normal and uv at barycentrics b, from the copies below.
  void fill_at(const Vec3& b, ShapeSample& s) const;
  const TriangleMesh* mesh_;
  uint32_t index_;
  // Copies of what every light sample reads, so that sampling does not go through the mesh's index
  // and vertex arrays (the same values, so the same samples as reading the mesh).
  Vec3 p_[3];
  Vec2 uv_[3];         // the mesh's, or pbrt's default (default_uv() in the .cpp)
  Vec3 n_flat_{0.f};   // the oriented face normal, for a mesh without shading normals (else zero)
  Vec3 n_front_;       // the face normal oriented as at the centroid: the side spherical sampling serves
  Vec3 centroid_;
  float area_, inv_area_;
};

}  // namespace penumbra
