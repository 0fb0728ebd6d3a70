// Conductor (metal) reflection: a Trowbridge-Reitz (GGX) microfacet BRDF with the exact Fresnel
// equations of a complex index of refraction eta + i k, f = D G F / (4 |cos_o cos_i|), sampled from
// the visible normals. Below TrowbridgeReitz::kSmoothAlpha it is a perfect mirror (a delta lobe).
// Two-sided.
#pragma once

#include "lobes.h"

#include <penumbra/bsdf.h>
#include <penumbra/microfacet.h>

#include <optional>

namespace penumbra::bxdf {

class ConductorBxdf {
 public:
  ConductorBxdf(TrowbridgeReitz distrib, Rgb eta, Rgb k) : distrib_(distrib), eta_(eta), k_(k) {}
  const TrowbridgeReitz& distribution() const { return distrib_; }
  uint32_t flags() const { return BsdfReflection | (distrib_.effectively_smooth() ? BsdfSpecular : BsdfGlossy); }
  Rgb f(const Vec3& wo, const Vec3& wi, TransportMode mode = TransportMode::Radiance) const;
  std::optional<BsdfSample> sample_f(const Vec3& wo, float uc, Vec2 u, TransportMode mode = TransportMode::Radiance,
                                     Lobes allowed = Lobes::All) const;
  float pdf(const Vec3& wo, const Vec3& wi, TransportMode mode = TransportMode::Radiance,
            Lobes allowed = Lobes::All) const;
  LobeSummary lobe(const Vec3& wo) const;

 private:
  TrowbridgeReitz distrib_;
  Rgb eta_, k_;
};

/// pbrt-v4's "reflectance" mode of a conductor: eta = 1 and k = 2 sqrt(R) / sqrt(1 - R), which makes
/// the reflectance at normal incidence exactly R. R is clamped to [0, 0.9999] (R = 1 would need an
/// infinite k; 0.9999 is indistinguishable and keeps Fresnel finite).
Rgb k_from_reflectance(Rgb r);

}  // namespace penumbra::bxdf
