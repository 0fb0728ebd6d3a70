// A Disney BSDF whose parameters come from textures: each call asks `params_at` for the hit's
// DisneyParams and forwards to a DisneyBsdf made on the stack, so untextured materials keep the
// plain DisneyBsdf and its cost. Shared by "disney" and "coateddiffuse" (which is built on it).
#pragma once

#include "disney_bsdf.h"

#include <functional>

namespace penumbra::disney {

class TexturedDisneyBsdf final : public Bsdf {
 public:
  using ParamsAt = std::function<DisneyParams(const TextureEvalContext&)>;
  /// `flags`: the union of the lobes any hit can have (the caller knows which inputs vary).
  TexturedDisneyBsdf(ParamsAt params_at, uint32_t flags) : params_at_(std::move(params_at)), flags_(flags) {}

  uint32_t flags() const override { return flags_; }
  Rgb f(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const override { return at(ctx).f(wo, wi, ctx); }
  std::optional<BsdfSample> sample_f(const Vec3& wo, float uc, Vec2 u, const ShadingContext& ctx) const override {
    return at(ctx).sample_f(wo, uc, u, ctx);
  }
  float pdf(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const override { return at(ctx).pdf(wo, wi, ctx); }
  LobeSummary lobe(const Vec3& wo, const ShadingContext& ctx) const override { return at(ctx).lobe(wo, ctx); }

 private:
  DisneyBsdf at(const ShadingContext& ctx) const { return DisneyBsdf(params_at_(ctx.tex)); }
  ParamsAt params_at_;
  uint32_t flags_;
};

}  // namespace penumbra::disney
