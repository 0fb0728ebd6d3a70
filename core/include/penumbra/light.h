// Lights as plugins. Area lights are attached to one primitive of a shape (a triangle or a sphere)
// and receive it at creation; other lights are placed by the transform of their directive.
#pragma once

#include <penumbra/color.h>
#include <penumbra/interaction.h>
#include <penumbra/math.h>
#include <penumbra/object.h>
#include <penumbra/shape.h>

#include <cstdint>
#include <optional>

namespace penumbra {

enum class LightType { DeltaPosition, DeltaDirection, Area, Infinite };

inline bool is_delta_light(LightType t) {
  return t == LightType::DeltaPosition || t == LightType::DeltaDirection;
}

/// The receiving point of a light sample: position, geometric normal (zero if none). A light may
/// shape its samples by the normal: a constant sky draws cosine-weighted directions about it, on
/// both sides.
///
/// allow_incomplete_pdf (pbrt-v4's allowIncompletePDF): the caller combines sample_li() with BSDF
/// sampling by MIS, asking pdf_li() with the same context for the weights, and n is the geometric
/// normal turned to the side the light is gathered on. A light may then leave directions to BSDF
/// sampling, with sample_li() and pdf_li() agreeing on them (density 0 there): a constant sky then
/// samples n's side only. Estimators that need every path from light sampling alone (bidirectional
/// MIS, light tracing) leave it false.
struct LightSampleContext {
  Vec3 p;
  Vec3 n{0.f};
  bool allow_incomplete_pdf = false;
};

/// The geometric normal of a surface hit, turned to the side of wo.
inline Vec3 ng_towards_wo(const SurfaceInteraction& si) { return glm::dot(si.ng, si.wo) < 0.f ? -si.ng : si.ng; }

/// The context for light sampling at a surface hit that is combined with BSDF sampling by MIS: the
/// geometric normal on the side of wo, allow_incomplete_pdf set.
inline LightSampleContext mis_light_context(const SurfaceInteraction& si) {
  return LightSampleContext{si.p, ng_towards_wo(si), true};
}

struct LightLiSample {
  Rgb L{0.f};      // incident radiance (before visibility)
  Vec3 wi;         // unit direction towards the light
  float pdf = 0.f; // solid angle density (delta lights: 1)
  Vec3 p_light;    // sampled point (for the shadow ray)
  Vec3 n_light{0.f};  // its normal (zero for points not on a surface)
};

/// Makes `out` hold a light sample, built in place: the LightLiSample counterpart of
/// emplace_sample() in penumbra/bsdf.h (sample_li() keeps one optional, returns it by name on every
/// path and fills it with this, so the result is not copied out of a stack temporary).
inline void emplace_li_sample(std::optional<LightLiSample>& out, const Rgb& L, const Vec3& wi, float pdf,
                              const Vec3& p_light, const Vec3& n_light = Vec3(0.f)) {
  LightLiSample& s = out.emplace();
  s.L = L;
  s.wi = wi;
  s.pdf = pdf;
  s.p_light = p_light;
  s.n_light = n_light;
}

/// A ray leaving a light, for methods that trace paths from the lights (light tracing, bidirectional
/// path tracing, photon mapping).
struct LightLeSample {
  Ray ray;             // origin on the light (or on a disk covering the scene for infinite/distant lights)
  Vec3 n{0.f};         // surface normal at the origin (zero for points and infinite/distant lights)
  Rgb L{0.f};          // emitted radiance (intensity for point lights) along the ray
  float pdf_pos = 0.f; // per unit area of the origin (1 for point lights)
  float pdf_dir = 0.f; // per unit solid angle of the direction (1 for distant lights)
};

class Light : public Object {
 public:
  ~Light() override;
  virtual LightType type() const = 0;
  /// Emitted power (flux), for light selection.
  virtual Rgb power() const = 0;
  /// Samples incident illumination at ctx. Empty when no contribution is possible.
  virtual std::optional<LightLiSample> sample_li(const LightSampleContext& ctx, Vec2 u) const = 0;
  /// Solid-angle density of sample_li() choosing the point `hit` seen from ctx in direction wi.
  virtual float pdf_li(const LightSampleContext& ctx, const Vec3& wi,
                       const SurfaceInteraction& hit) const = 0;
  /// Samples an emitted ray: u_pos chooses the origin, u_dir the direction. The power of the light is
  /// E[L |cos| / (pdf_pos pdf_dir)] (tested for every light).
  virtual std::optional<LightLeSample> sample_le(Vec2 u_pos, Vec2 u_dir) const = 0;
  /// Whether sample_li()'s density of a point or direction depends on the receiving point (area
  /// lights; a constant sky, which samples about the receiving normal), or is the emission's own
  /// density for every receiver (delta lights, image environments). Bidirectional MIS compares the
  /// two only where they can differ.
  virtual bool li_density_depends_on_receiver() const { return type() == LightType::Area; }
  /// Densities with which sample_le() produces `ray` (with surface normal n at its origin, if any).
  virtual void pdf_le(const Ray& ray, const Vec3& n, float* pdf_pos, float* pdf_dir) const = 0;

  /// Area lights: radiance leaving surface point (p, n, uv) in direction w.
  virtual Rgb L(const Vec3& p, const Vec3& n, const Vec2& uv, const Vec3& w) const;
  /// Infinite lights: radiance arriving along a ray that escapes the scene.
  virtual Rgb Le(const Ray& ray) const;

  /// Called once before rendering with the bounds of the scene's geometry (infinite and distant
  /// lights need them for their power and for placing shadow-ray targets).
  virtual void preprocess(const Vec3& scene_center, float scene_radius) {}

  /// Index in the scene's light list (set by the runtime; used for light-selection pmfs).
  uint32_t index() const { return index_; }
  void set_index(uint32_t i) { index_ = i; }

 private:
  uint32_t index_ = 0;
};

}  // namespace penumbra
