#include "scene/mix_bsdf.h"

#include <algorithm>

namespace penumbra {

uint32_t MixBsdf::flags() const {
  uint32_t f = 0;
  if (amount_ < 1.f) f |= a_.flags();
  if (amount_ > 0.f) f |= b_.flags();
  return f;
}

Rgb MixBsdf::f(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const {
  Rgb sum(0.f);
  if (amount_ < 1.f) sum += (1.f - amount_) * a_.f(wo, wi, ctx);
  if (amount_ > 0.f) sum += amount_ * b_.f(wo, wi, ctx);
  return sum;
}

float MixBsdf::pdf(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const {
  float p = 0.f;
  if (amount_ < 1.f) p += (1.f - amount_) * a_.pdf(wo, wi, ctx);
  if (amount_ > 0.f) p += amount_ * b_.pdf(wo, wi, ctx);
  return p;
}

std::optional<BsdfSample> MixBsdf::sample_f(const Vec3& wo, float uc, Vec2 u, const ShadingContext& ctx) const {
  // Choose a material by uc and stretch the rest of uc back to [0, 1) for its own lobe choice.
  bool second = uc < amount_;
  float p_choice = second ? amount_ : 1.f - amount_;
  float uc_child = second ? uc / amount_ : (uc - amount_) / (1.f - amount_);
  uc_child = std::min(std::max(uc_child, 0.f), 0x1.fffffep-1f);
  std::optional<BsdfSample> s = (second ? b_ : a_).sample_f(wo, uc_child, u, ctx);
  if (!s) return std::nullopt;
  if (s->is_specular()) {
    // A delta lobe belongs to the chosen material only: its weight f / pdf stays the child's.
    s->f *= p_choice;
    s->pdf *= p_choice;
    return s;
  }
  s->f = f(wo, s->wi, ctx);
  s->pdf = pdf(wo, s->wi, ctx);
  if (!(s->pdf > 0.f)) return std::nullopt;
  return s;
}

LobeSummary MixBsdf::lobe(const Vec3& wo, const ShadingContext& ctx) const {
  LobeSummary la = a_.lobe(wo, ctx), lb = b_.lobe(wo, ctx);
  float wa = (1.f - amount_) * la.coefficient, wb = amount_ * lb.coefficient;
  LobeSummary l = wb > wa ? lb : la;
  l.coefficient = wa + wb;
  return l;
}

}  // namespace penumbra
