// The Disney principled BSDF as one Bsdf: the lobes of disney_lobes.h weighted as in pbrt-v3's
// DisneyMaterial, sampled by picking one lobe with a probability from its approximate albedo for
// the given wo. f() is the sum of all lobes and pdf() the exact mixture sum_k p_k pdf_k, the
// one-sample MIS density of what sample_f() does.
//
// Smooth lobes are deltas, with the threshold conductor and dielectric use
// (TrowbridgeReitz::kSmoothAlpha): when the specular distribution's alpha is below it along both
// axes (after anisotropy), the specular reflection (metallic and dielectric part together) is a
// mirror; when the transmission distribution's is, transmission is a perfect refraction (thin
// surfaces: a straight pass-through). A delta lobe's sample has flags Specular, f = its weight /
// |cos| and pdf = the lobe's selection probability p_k; f() and pdf() leave it out (0 for any
// given pair of directions), and flags() reports it as Specular next to whatever other lobes the
// material has. Such a mixed BSDF (say metallic 0.5, roughness 0: a mirror plus a diffuse lobe) is
// not specular-only, so integrators still connect to it through f() and pdf() of the other lobes,
// and tell a delta sample from the others by its own flags (BsdfSample::is_specular()).
// The clearcoat is never a delta: GTR1's alpha is at least 0.001 by its definition
// (lerp(0.1, 0.001, clearcoatgloss)), a glossy lobe at any gloss.
//
// Used by the "disney" plugin.
#pragma once

#include "disney_lobes.h"

#include <penumbra/bsdf.h>

namespace penumbra::disney {

/// pbrt-v3's parameters, constant over the surface.
struct DisneyParams {
  Rgb color{0.5f};
  float metallic = 0.f;
  float eta = 1.5f;
  float roughness = 0.5f;
  float specular_tint = 0.f;
  float anisotropic = 0.f;
  float sheen = 0.f;
  float sheen_tint = 0.5f;
  float clearcoat = 0.f;       // the coat's weight is 0.25 clearcoat
  float clearcoat_gloss = 1.f;
  float clearcoat_r0 = 0.04f;  // Disney fixes IOR 1.5
  float spec_trans = 0.f;
  bool thin = false;
  float flatness = 0.f;
  float diff_trans = 1.f;      // thin only: 0 reflects all diffuse light, 2 transmits all
  /// A spectral render's wavelengths at the hit, or null. The colours derived from `color` (its
  /// tint, its square root) are made in RGB, as the model defines them, and each then becomes its
  /// smooth spectrum at these wavelengths.
  const SampledWavelengths* wavelengths = nullptr;
};

class DisneyBsdf final : public Bsdf {
 public:
  explicit DisneyBsdf(const DisneyParams& p);

  uint32_t flags() const override { return flags_; }
  Rgb f(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const override;
  std::optional<BsdfSample> sample_f(const Vec3& wo, float uc, Vec2 u, const ShadingContext& ctx) const override;
  float pdf(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const override;
  LobeSummary lobe(const Vec3& wo, const ShadingContext& ctx) const override;

 private:
  // wo mirrored above the surface, and the relative IOR seen from its side.
  struct Side {
    bool flipped;
    Vec3 wo;
    float eta;
    // Mirrors a direction into (or, being its own inverse, back out of) the upper configuration.
    Vec3 to_upper(const Vec3& w) const { return flipped ? Vec3(w.x, w.y, -w.z) : w; }
  };
  // Unnormalised selection weights of the lobes for one wo.
  struct Weights {
    float diffuse = 0.f, specular = 0.f, clearcoat = 0.f, transmission = 0.f, diffuse_transmission = 0.f;
    float sum() const { return diffuse + specular + clearcoat + transmission + diffuse_transmission; }
  };

  Side side_of(const Vec3& wo) const;
  Weights weights(const Side& side) const;
  Rgb f_upper(const Side& side, const Vec3& wi, TransportMode mode) const;
  float pdf_upper(const Side& side, const Weights& w, const Vec3& wi) const;
  bool rough_transmission() const { return transmissive_ && !transmission_delta_; }
  bool rough_specular() const { return specular_.active(eta_) && !specular_delta_; }

  DiffuseLobes diffuse_;
  SpecularReflection specular_;
  Clearcoat clearcoat_;
  RoughTransmission transmission_;
  Rgb diffuse_transmission_{0.f};  // thin surfaces: Lambertian transmission
  float eta_;
  bool thin_;
  bool transmissive_;              // has a specular transmission lobe
  bool pass_through_;              // eta ~ 1: that lobe is a straight delta pass-through
  bool specular_delta_;            // the specular reflection is a mirror (alpha < kSmoothAlpha)
  bool transmission_delta_;        // transmission is a delta: pass-through or alpha < kSmoothAlpha
  uint32_t flags_ = 0;
};

}  // namespace penumbra::disney
