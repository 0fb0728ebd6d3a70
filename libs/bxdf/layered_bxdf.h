// A stochastic layered BxDF in the manner of pbrt-v4's LayeredBxDF (Physically Based Rendering, 4th
// ed., section 14.3): a dielectric interface on top of an opaque base (Lambertian or conductor) with a
// slab of thickness `thickness` between them, filled with a medium of unit extinction, single-
// scattering albedo `albedo` and Henyey-Greenstein asymmetry `g` (albedo 0: a pure absorber, so
// thickness alone tints and darkens). Two-sided: a wo below the surface sees the mirrored layers.
//
// Light is followed through the slab by a random walk of at most max_depth events (an event is one
// interface interaction or one scattering in the medium):
//   - f(wo, wi) is an unbiased Monte Carlo estimate (n_samples walks averaged) of the walk's BRDF:
//     the top's own reflection plus walks entering along a sampled refraction of wo, with next-event
//     connections to the refraction of wi at every base bounce and scattering event, combined by MIS
//     with hitting wi's refraction by sampling (as pbrt-v4 does; Russian roulette after depth 3).
//   - sample_f() walks: sample the top from wo; a reflection is returned as is, a refraction
//     continues through the slab until a refraction leaves through the top (or max_depth is
//     reached: no sample). The weight f |cos| / pdf it returns is the walk's throughput.
//   - pdf(wo, wi) is an unbiased estimate of the density with which sample_f() returns wi (unlike
//     pbrt-v4's, which approximates it): walks with the same sampling decisions, their probabilities
//     carried as weights, add the density of leaving through wi at every visit of the top (rough top)
//     or at the event before (smooth top, through the refraction's Jacobian).
// The Bsdf interface wants deterministic functions, so f() and pdf() seed their walks from a hash of
// (wo, wi) (as pbrt-v4 does), which keeps MIS weights of the two strategies summing to one; sample_f()
// reports pdf(wo, wi) as its pdf and scales f so that f |cos| / pdf is the walk's throughput. The
// overloads taking a Pcg32 draw fresh estimates, for tests that average them.
#pragma once

#include "conductor_bxdf.h"
#include "dielectric_bxdf.h"
#include "diffuse_bxdf.h"
#include "henyey_greenstein.h"

#include <penumbra/rng.h>

#include <limits>

namespace penumbra::bxdf {

struct LayerParams {
  float thickness = 0.01f;
  Rgb albedo{0.f};
  float g = 0.f;
  int max_depth = 10;
  int n_samples = 1;
};

template <class Bottom>
class LayeredBxdf {
 public:
  LayeredBxdf(DielectricBxdf top, Bottom bottom, LayerParams params)
      : top_(top), bottom_(bottom), p_(params), phase_(params.g) {
    // The walk tells the layers apart by height: a zero thickness would merge them.
    p_.thickness = std::max(p_.thickness, std::numeric_limits<float>::min());
  }

  const DielectricBxdf& top() const { return top_; }
  const Bottom& bottom() const { return bottom_; }
  const LayerParams& params() const { return p_; }

  uint32_t flags() const;
  Rgb f(const Vec3& wo, const Vec3& wi, TransportMode mode = TransportMode::Radiance) const;
  float pdf(const Vec3& wo, const Vec3& wi, TransportMode mode = TransportMode::Radiance) const;
  std::optional<BsdfSample> sample_f(const Vec3& wo, float uc, Vec2 u,
                                     TransportMode mode = TransportMode::Radiance) const;
  LobeSummary lobe(const Vec3& wo) const;

  /// The same with the walks' random numbers drawn from `rng` (independent estimates per call).
  Rgb f(const Vec3& wo, const Vec3& wi, TransportMode mode, Pcg32& rng) const;
  float pdf(const Vec3& wo, const Vec3& wi, TransportMode mode, Pcg32& rng) const;
  /// The walk only: wi, and f and pdf as products along it (f |cos| / pdf is the throughput). For a
  /// non-specular sample, pdf is not the density of wi (sample_f() replaces it by pdf(wo, wi)).
  std::optional<BsdfSample> sample_walk(const Vec3& wo, float uc, Vec2 u, TransportMode mode, Pcg32& rng) const;

 private:
  bool has_medium() const { return !is_black(p_.albedo); }
  bool bottom_specular() const { return (bottom_.flags() & BsdfSpecular) != 0; }
  uint32_t nonspecular_lobe() const;
  Rgb f_walk(const Vec3& wo, const Vec3& wi, TransportMode mode, Pcg32& rng) const;
  float pdf_walk(const Vec3& wo, const Vec3& wi, TransportMode mode, Pcg32& rng) const;

  DielectricBxdf top_;
  Bottom bottom_;
  LayerParams p_;
  HenyeyGreenstein phase_;
};

extern template class LayeredBxdf<DiffuseBxdf>;
extern template class LayeredBxdf<ConductorBxdf>;
using CoatedDiffuseBxdf = LayeredBxdf<DiffuseBxdf>;
using CoatedConductorBxdf = LayeredBxdf<ConductorBxdf>;

}  // namespace penumbra::bxdf
