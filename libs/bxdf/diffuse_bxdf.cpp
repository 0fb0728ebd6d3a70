#include "diffuse_bxdf.h"

#include <penumbra/sampling.h>

namespace penumbra::bxdf {

std::optional<BsdfSample> DiffuseBxdf::sample_f(const Vec3& wo, float, Vec2 u, TransportMode, Lobes allowed) const {
  std::optional<BsdfSample> bs;  // the one object every path returns (emplace_sample)
  if (wo.z == 0.f || is_black(r_) || !allows(allowed, Lobes::Reflection)) return bs;
  Vec3 wi = sample_cosine_hemisphere(u);
  if (wo.z < 0.f) wi.z = -wi.z;
  float pdf = cosine_hemisphere_pdf(std::abs(wi.z));
  if (pdf == 0.f) return bs;
  emplace_sample(bs, r_ * InvPi, wi, pdf, BsdfReflection | BsdfDiffuse);
  return bs;
}

float DiffuseBxdf::pdf(const Vec3& wo, const Vec3& wi, TransportMode, Lobes allowed) const {
  if (!allows(allowed, Lobes::Reflection)) return 0.f;
  return same_hemisphere(wo, wi) ? cosine_hemisphere_pdf(std::abs(wi.z)) : 0.f;
}

LobeSummary DiffuseBxdf::lobe(const Vec3& wo) const {
  LobeSummary l;
  l.peak = Vec3(0.f, 0.f, wo.z < 0.f ? -1.f : 1.f);
  l.coefficient = max_component(r_);
  l.cosine = true;
  return l;
}

}  // namespace penumbra::bxdf
