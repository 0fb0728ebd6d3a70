// A Disney BSDF whose parameters come from textures: each call asks `params_at` for the hit's
// DisneyParams and forwards to a DisneyBsdf made on the stack, so untextured materials keep the
// plain DisneyBsdf and its cost. Used by "disney".
#pragma once

#include "disney_bsdf.h"

#include <functional>

namespace penumbra::disney {

class TexturedDisneyBsdf final : public PerHitBsdf<TexturedDisneyBsdf> {
  friend class PerHitBsdf<TexturedDisneyBsdf>;

 public:
  using ParamsAt = std::function<DisneyParams(const TextureEvalContext&)>;
  /// `flags`: the union of the lobes any hit can have (the caller knows which inputs vary).
  TexturedDisneyBsdf(ParamsAt params_at, uint32_t flags) : params_at_(std::move(params_at)), flags_(flags) {}

  uint32_t flags() const override { return flags_; }

 private:
  DisneyBsdf at(const ShadingContext& ctx) const { return DisneyBsdf(params_at_(ctx.tex)); }
  ParamsAt params_at_;
  uint32_t flags_;
};

}  // namespace penumbra::disney
