// Materials as BSDF plugins. A Bsdf is created once per material directive; it evaluates and
// samples scattering in the local shading frame of a hit (normal +z). Directions point away from
// the surface. f() excludes the cosine factor. Textured parameters (TexturedFloat, TexturedRgb from
// texture.h) are evaluated in each call at the ShadingContext's TextureEvalContext; constant ones
// are read once at creation.
#pragma once

#include <penumbra/color.h>
#include <penumbra/math.h>
#include <penumbra/object.h>
#include <penumbra/texture.h>

#include <cstdint>
#include <optional>

namespace penumbra {

/// Whether radiance (camera paths) or importance (light paths) is being transported; non-symmetric
/// BSDFs (refraction) differ between the two.
enum class TransportMode { Radiance, Importance };

enum BsdfFlags : uint32_t {
  BsdfReflection = 1u << 0,
  BsdfTransmission = 1u << 1,
  BsdfDiffuse = 1u << 2,
  BsdfGlossy = 1u << 3,
  BsdfSpecular = 1u << 4,
};

/// Where the BSDF is evaluated: the texture lookup context of the hit and the transport mode.
/// Built from a hit as ShadingContext{si.texture_context(), mode}.
struct ShadingContext {
  TextureEvalContext tex;
  TransportMode mode = TransportMode::Radiance;
};

struct BsdfSample {
  Rgb f{0.f};          // BSDF value for (wo, wi); for specular lobes the delta's weight
  Vec3 wi{0.f};        // sampled incident direction, local frame
  float pdf = 0.f;     // solid-angle density (specular: the discrete probability of the lobe)
  uint32_t flags = 0;  // lobe that was sampled (BsdfFlags)
  float eta = 1.f;     // transmission: relative IOR eta' across the interface as wo sees it (radiance
                       // is scaled by 1/eta'^2 there; path tracers undo it for Russian roulette)
  bool is_specular() const { return (flags & BsdfSpecular) != 0; }
};

/// Makes `out` hold a sample, built in place. For sample_f() on a hot path: declare one
/// std::optional<BsdfSample>, return that object by name on every path and fill it with this. GCC then
/// builds the result where the caller receives it; `return BsdfSample{...}` builds it on the stack
/// and copies it out, and the copy stalls on the stores just made (DiffuseBxdf::sample_f: 4 % of a
/// path tracer's time on the Cornell box).
inline void emplace_sample(std::optional<BsdfSample>& out, const Rgb& f, const Vec3& wi, float pdf, uint32_t flags,
                           float eta = 1.f) {
  BsdfSample& s = out.emplace();
  s.f = f;
  s.wi = wi;
  s.pdf = pdf;
  s.flags = flags;
  s.eta = eta;
}

/// An approximate scattering lobe for a given wo, used by hierarchical Russian roulette to bound
/// where a BSDF sends most of its energy: an anisotropic GGX-like lobe around `peak` (local frame)
/// with roughness (alpha_x, alpha_y) along the shading frame's s and t axes, scaled by `coefficient`
/// (an albedo-like weight). A diffuse lobe reports peak = +z (on wo's side), alpha = 1, cosine = true.
/// It describes what connections can use: a BSDF with delta lobes among others summarises the
/// others (f() and pdf() leave deltas out); one of delta lobes only reports its strongest delta, with
/// alphas below TrowbridgeReitz::kSmoothAlpha, which no connection uses (the vertex is not connectible).
struct LobeSummary {
  Vec3 peak{0.f, 0.f, 1.f};
  float alpha_x = 1.f, alpha_y = 1.f;
  float coefficient = 0.f;
  bool cosine = false;  // true for a cosine (Lambertian) lobe rather than a GGX lobe
};

class Bsdf : public Object {
 public:
  ~Bsdf() override;
  /// Union of the lobes this BSDF can have (BsdfFlags). A delta lobe among others adds BsdfSpecular
  /// next to their bits: such a BSDF is not specular-only (integrators connect to it through f() and
  /// pdf() of the other lobes) and its delta samples carry BsdfSpecular in BsdfSample::flags.
  virtual uint32_t flags() const = 0;
  virtual Rgb f(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const = 0;
  /// Samples wi given wo; uc picks a lobe, u the direction. Empty when no direction was produced.
  virtual std::optional<BsdfSample> sample_f(const Vec3& wo, float uc, Vec2 u,
                                             const ShadingContext& ctx) const = 0;
  /// Density with which sample_f() returns wi (0 for specular lobes).
  virtual float pdf(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const = 0;

  /// The dominant lobe for wo (see LobeSummary). The default is a cosine lobe with coefficient 1.
  virtual LobeSummary lobe(const Vec3& wo, const ShadingContext& ctx) const;

  bool is_specular_only() const { return is_specular_only(flags()); }
  /// The same test on flags already asked for (flags() is a virtual call).
  static bool is_specular_only(uint32_t f) { return (f & BsdfSpecular) && !(f & (BsdfDiffuse | BsdfGlossy)); }
};

/// Base of a material whose parameters vary per hit (textures): Derived::at(ctx) builds the BSDF with
/// constant parameters for the hit (on the stack), and f, sample_f, pdf and lobe forward to it;
/// Derived still declares flags() (the union over its parameters' range).
template <class Derived>
class PerHitBsdf : public Bsdf {
 public:
  Rgb f(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const override { return self().at(ctx).f(wo, wi, ctx); }
  std::optional<BsdfSample> sample_f(const Vec3& wo, float uc, Vec2 u, const ShadingContext& ctx) const override {
    return self().at(ctx).sample_f(wo, uc, u, ctx);
  }
  float pdf(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const override {
    return self().at(ctx).pdf(wo, wi, ctx);
  }
  LobeSummary lobe(const Vec3& wo, const ShadingContext& ctx) const override { return self().at(ctx).lobe(wo, ctx); }

 private:
  const Derived& self() const { return static_cast<const Derived&>(*this); }
};

}  // namespace penumbra
