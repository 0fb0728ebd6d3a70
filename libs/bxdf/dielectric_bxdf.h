// Dielectric interface (glass, water, a coat) between two non-absorbing media, outside +z with IOR 1
// and inside with IOR eta. Smooth (alpha below TrowbridgeReitz::kSmoothAlpha): delta reflection and
// refraction, chosen with the Fresnel reflectance as probability. Rough: Trowbridge-Reitz microfacet
// reflection and transmission (Walter et al. 2007) with the generalized half vector, sampled from
// the visible normals. eta == 1 is index-matched: light passes straight through. wo below the
// surface is inside the medium, where the relative IOR is 1/eta. Radiance is compressed by 1/eta'^2
// when it refracts into a denser medium (TransportMode::Radiance); importance is not.
#pragma once

#include "lobes.h"

#include <penumbra/bsdf.h>
#include <penumbra/microfacet.h>

#include <optional>

namespace penumbra::bxdf {

class DielectricBxdf {
 public:
  DielectricBxdf(float eta, TrowbridgeReitz distrib) : eta_(eta), distrib_(distrib) {}
  float eta() const { return eta_; }
  const TrowbridgeReitz& distribution() const { return distrib_; }
  bool smooth() const { return distrib_.effectively_smooth(); }
  /// The interface is a delta (smooth or index-matched): f() and pdf() are 0 for given directions.
  bool specular() const { return eta_ == 1.f || smooth(); }

  uint32_t flags() const;
  Rgb f(const Vec3& wo, const Vec3& wi, TransportMode mode = TransportMode::Radiance) const;
  /// With `allowed` restricting the lobes, the returned pdf is conditional on that restriction. If
  /// `choice` is given it receives the probability with which unrestricted sampling, having drawn the
  /// same microfacet normal, would have chosen the returned lobe (a likelihood ratio for forced
  /// lobe choices; 1 when nothing was restricted).
  std::optional<BsdfSample> sample_f(const Vec3& wo, float uc, Vec2 u, TransportMode mode = TransportMode::Radiance,
                                     Lobes allowed = Lobes::All, float* choice = nullptr) const;
  float pdf(const Vec3& wo, const Vec3& wi, TransportMode mode = TransportMode::Radiance,
            Lobes allowed = Lobes::All) const;
  LobeSummary lobe(const Vec3& wo) const;

 private:
  std::optional<BsdfSample> sample_smooth(const Vec3& wo, float uc, TransportMode mode, Lobes allowed,
                                          float* choice) const;
  std::optional<BsdfSample> sample_rough(const Vec3& wo, float uc, Vec2 u, TransportMode mode, Lobes allowed,
                                         float* choice) const;
  // The microfacet normal that scatters wo into wi, with what kind of event it is.
  struct Pair {
    Vec3 wm;
    float etap;  // relative IOR across the interface as wo sees it (1 for reflection)
    bool reflection;
  };
  std::optional<Pair> pair(const Vec3& wo, const Vec3& wi) const;

  float eta_;
  TrowbridgeReitz distrib_;
};

}  // namespace penumbra::bxdf
