// Shapes as area-light plugins see them: one sampleable primitive (a triangle or a sphere) with an
// oriented surface normal (pbrt's rules: mesh normals decide a triangle's side when given, otherwise
// the winding, flipped by ReverseOrientation or a handedness-changing transform).
#pragma once

#include <penumbra/math.h>

#include <optional>

namespace penumbra {

/// A point on a shape chosen for a reference point; `pdf` is per unit area or per unit solid angle
/// as the function says.
struct ShapeSample {
  Vec3 p;
  Vec3 n;  // oriented geometric normal at p
  Vec2 uv;
  float pdf = 0.f;
  // sample_solid_angle() only (sample_area() leaves them zero): the unit direction from the
  // context's point to p and the distance between them, which the shape computed for the density;
  // a light takes them instead of a second square root and division per sample.
  Vec3 wi{0.f};
  float distance = 0.f;
};

/// Where a shape is sampled from: a point, and its surface normal when it lies on a surface.
struct ShapeSampleContext {
  Vec3 p;
  Vec3 n{0.f};  // zero when the point is not on a surface
  /// Set by a caller that can use only points whose front (the side the shape's oriented normal
  /// faces) p sees, such as a one-sided emitter. A shape may then sample nothing, and give density 0,
  /// where p is behind all of it (a flat shape's back); shapes that ignore it stay correct.
  bool front_only = false;
};

class Shape {
 public:
  virtual ~Shape();
  virtual float area() const = 0;
  /// Uniform by area; pdf per unit area.
  virtual ShapeSample sample_area(Vec2 u) const = 0;
  /// A point seen from ctx; pdf per unit solid angle at ctx.p. Empty when nothing can be sampled.
  virtual std::optional<ShapeSample> sample_solid_angle(const ShapeSampleContext& ctx, Vec2 u) const = 0;
  /// Density of sample_solid_angle() producing the point p_hit (normal n_hit) in direction wi.
  virtual float pdf_solid_angle(const ShapeSampleContext& ctx, const Vec3& wi, const Vec3& p_hit,
                                const Vec3& n_hit) const = 0;
  /// Whether the surface is there at a sampled point. False where the shape's alpha cut-out removes
  /// it (pbrt-v4's AlphaMasked: alpha 0 never there, 1 always, in between when a hash of the point is
  /// at most alpha). Area lights emit nothing from such samples; rays never hit there. The samplers
  /// above stay uniform over the whole shape, as pbrt-v4's.
  virtual bool present(const ShapeSample&) const { return true; }
};

/// Converts a per-area density at p_light (normal n_light) to per solid angle at p. Where given, wi
/// and distance receive the unit direction from p to p_light and the distance (set where the
/// density is not 0), computed on the way.
inline float area_to_solid_angle_pdf(float pdf_area, const Vec3& p, const Vec3& p_light, const Vec3& n_light,
                                     Vec3* wi = nullptr, float* distance = nullptr) {
  Vec3 d = p_light - p;
  float dist2 = glm::dot(d, d);
  float dist = std::sqrt(dist2);
  float cos_l = std::abs(glm::dot(n_light, d)) / dist;
  if (cos_l == 0.f || dist2 == 0.f) return 0.f;
  if (wi) *wi = d / dist;
  if (distance) *distance = dist;
  return pdf_area * dist2 / cos_l;
}

}  // namespace penumbra
