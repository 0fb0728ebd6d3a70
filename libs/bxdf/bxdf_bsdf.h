// A library BxDF as a Bsdf plugin object: f, sample_f, pdf and lobe forward to the BxDF with the
// shading context's transport mode. Used for constant materials and, made on the stack, by the
// textured ones (PerHitBsdf's at()).
#pragma once

#include <penumbra/bsdf.h>

#include <utility>

namespace penumbra::bxdf {

template <class B>
class BxdfBsdf final : public Bsdf {
 public:
  explicit BxdfBsdf(B b) : b_(std::move(b)) {}
  const B& bxdf() const { return b_; }
  uint32_t flags() const override { return b_.flags(); }
  Rgb f(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const override { return b_.f(wo, wi, ctx.mode); }
  std::optional<BsdfSample> sample_f(const Vec3& wo, float uc, Vec2 u, const ShadingContext& ctx) const override {
    return b_.sample_f(wo, uc, u, ctx.mode);
  }
  float pdf(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const override { return b_.pdf(wo, wi, ctx.mode); }
  LobeSummary lobe(const Vec3& wo, const ShadingContext&) const override { return b_.lobe(wo); }

 private:
  B b_;
};

}  // namespace penumbra::bxdf
