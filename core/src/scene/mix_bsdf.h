// pbrt-v4's "mix" material: materials[0] with probability 1 - amount, materials[1] with probability
// amount. pbrt-v4 picks one of the two per shading point by hashing the point and wo; the expected
// image is that of the amount-weighted average of the two BSDFs, which is what this evaluates:
// f = (1 - a) f0 + a f1 and pdf = (1 - a) pdf0 + a pdf1, and sample_f() selects one of the two by
// the lobe-selection number (probability amount for materials[1]) and samples it, so the choice is
// stochastic by amount as in pbrt-v4 while f and pdf stay those of the mixture (one-sample MIS over
// the two materials; delta samples keep their material's weight).
#pragma once

#include <penumbra/bsdf.h>

namespace penumbra {

class MixBsdf final : public Bsdf {
 public:
  /// `amount` in [0, 1] is the probability of `second`.
  MixBsdf(const Bsdf& first, const Bsdf& second, float amount) : a_(first), b_(second), amount_(amount) {}

  uint32_t flags() const override;
  Rgb f(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const override;
  std::optional<BsdfSample> sample_f(const Vec3& wo, float uc, Vec2 u, const ShadingContext& ctx) const override;
  float pdf(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const override;
  LobeSummary lobe(const Vec3& wo, const ShadingContext& ctx) const override;

 private:
  const Bsdf& a_;
  const Bsdf& b_;
  float amount_;
};

}  // namespace penumbra
