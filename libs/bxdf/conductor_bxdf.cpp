#include "conductor_bxdf.h"

namespace penumbra::bxdf {

namespace {

// Half vector of a reflection pair, on the +z side (the distribution's domain).
std::optional<Vec3> half_vector(const Vec3& wo, const Vec3& wi) {
  Vec3 wm = wo + wi;
  if (glm::dot(wm, wm) == 0.f) return std::nullopt;
  wm = glm::normalize(wm);
  return wm.z < 0.f ? -wm : wm;
}

}  // namespace

Rgb ConductorBxdf::f(const Vec3& wo, const Vec3& wi, TransportMode) const {
  if (!same_hemisphere(wo, wi) || distrib_.effectively_smooth()) return Rgb(0.f);
  float cos_o = abs_cos_theta(wo), cos_i = abs_cos_theta(wi);
  if (cos_o == 0.f || cos_i == 0.f) return Rgb(0.f);
  std::optional<Vec3> wm = half_vector(wo, wi);
  if (!wm) return Rgb(0.f);
  Rgb F = fresnel_complex(std::abs(glm::dot(wo, *wm)), eta_, k_);
  return distrib_.D(*wm) * distrib_.G(wo, wi) * F / (4.f * cos_o * cos_i);
}

std::optional<BsdfSample> ConductorBxdf::sample_f(const Vec3& wo, float, Vec2 u, TransportMode mode,
                                                  Lobes allowed) const {
  std::optional<BsdfSample> bs;  // the one object every path returns (emplace_sample)
  if (wo.z == 0.f || !allows(allowed, Lobes::Reflection)) return bs;
  if (distrib_.effectively_smooth()) {
    // Delta reflection: the weight f |cos| / pdf must be F, so f carries F / |cos|.
    Vec3 wi(-wo.x, -wo.y, wo.z);
    float cos_i = abs_cos_theta(wi);
    emplace_sample(bs, fresnel_complex(cos_i, eta_, k_) / cos_i, wi, 1.f, BsdfReflection | BsdfSpecular);
    return bs;
  }
  Vec3 wm = distrib_.sample_wm(wo, u);
  Vec3 wi = reflect(wo, wm);
  if (!same_hemisphere(wo, wi)) return bs;  // reflected into the microsurface
  float pdf = distrib_.pdf(wo, wm) / (4.f * std::abs(glm::dot(wo, wm)));
  if (!(pdf > 0.f) || wi.z == 0.f) return bs;
  emplace_sample(bs, f(wo, wi, mode), wi, pdf, BsdfReflection | BsdfGlossy);
  return bs;
}

float ConductorBxdf::pdf(const Vec3& wo, const Vec3& wi, TransportMode, Lobes allowed) const {
  if (!allows(allowed, Lobes::Reflection)) return 0.f;
  if (!same_hemisphere(wo, wi) || distrib_.effectively_smooth()) return 0.f;
  std::optional<Vec3> wm = half_vector(wo, wi);
  if (!wm) return 0.f;
  // Reflection maps half vectors to directions with Jacobian 1 / (4 |wo . wm|).
  return distrib_.pdf(wo, *wm) / (4.f * std::abs(glm::dot(wo, *wm)));
}

LobeSummary ConductorBxdf::lobe(const Vec3& wo) const {
  LobeSummary l;
  l.peak = Vec3(-wo.x, -wo.y, wo.z);
  l.alpha_x = distrib_.alpha_x();
  l.alpha_y = distrib_.alpha_y();
  l.coefficient = luminance(fresnel_complex(1.f, eta_, k_));
  return l;
}

Rgb k_from_reflectance(Rgb r) {
  r = glm::clamp(r, Rgb(0.f), Rgb(0.9999f));
  return 2.f * glm::sqrt(r) / glm::sqrt(Rgb(1.f) - r);
}

}  // namespace penumbra::bxdf
