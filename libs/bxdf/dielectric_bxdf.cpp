#include "dielectric_bxdf.h"

namespace penumbra::bxdf {

namespace {

// Probabilities of choosing reflection and transmission given their Fresnel weights R and T and
// the allowed lobes (a forbidden lobe gets probability 0).
struct Choice {
  float pr, pt;
};
Choice restrict_choice(float R, float T, Lobes allowed) {
  return {allows(allowed, Lobes::Reflection) ? R : 0.f, allows(allowed, Lobes::Transmission) ? T : 0.f};
}

}  // namespace

uint32_t DielectricBxdf::flags() const {
  if (eta_ == 1.f) return BsdfTransmission | BsdfSpecular;
  return BsdfReflection | BsdfTransmission | (smooth() ? BsdfSpecular : BsdfGlossy);
}

Rgb DielectricBxdf::f(const Vec3& wo, const Vec3& wi, TransportMode mode) const {
  if (eta_ == 1.f || smooth()) return Rgb(0.f);
  std::optional<Pair> pr = pair(wo, wi);
  if (!pr) return Rgb(0.f);
  float F = fresnel_dielectric(glm::dot(wo, pr->wm), eta_);
  float DG = distrib_.D(pr->wm) * distrib_.G(wo, wi);
  if (pr->reflection) return Rgb(DG * F / std::abs(4.f * wo.z * wi.z));
  // Walter et al. eq. 21, with the solid-angle Jacobian of the generalized half vector.
  float dot_i = glm::dot(wi, pr->wm), dot_o = glm::dot(wo, pr->wm);
  float denom = sqr(dot_i + dot_o / pr->etap) * wi.z * wo.z;
  float ft = DG * (1.f - F) * std::abs(dot_i * dot_o / denom);
  if (mode == TransportMode::Radiance) ft /= sqr(pr->etap);
  return Rgb(ft);
}

std::optional<BsdfSample> DielectricBxdf::sample_f(const Vec3& wo, float uc, Vec2 u, TransportMode mode,
                                                   Lobes allowed, float* choice) const {
  if (choice) *choice = 1.f;
  // Both return a prvalue of this type, so neither result is copied.
  if (wo.z != 0.f && eta_ != 1.f && smooth()) return sample_smooth(wo, uc, mode, allowed, choice);
  return sample_rough(wo, uc, u, mode, allowed, choice);
}

// The index-matched pass-through, and rough interfaces.
std::optional<BsdfSample> DielectricBxdf::sample_rough(const Vec3& wo, float uc, Vec2 u, TransportMode mode,
                                                       Lobes allowed, float* choice) const {
  std::optional<BsdfSample> bs;  // the one object every path returns (emplace_sample)
  if (wo.z == 0.f) return bs;
  if (eta_ == 1.f) {
    if (!allows(allowed, Lobes::Transmission)) return bs;
    emplace_sample(bs, Rgb(1.f / std::abs(wo.z)), -wo, 1.f, BsdfTransmission | BsdfSpecular);
    return bs;
  }
  Vec3 wm = distrib_.sample_wm(wo, u);
  float R = fresnel_dielectric(glm::dot(wo, wm), eta_), T = 1.f - R;
  float pdf_wm = distrib_.pdf(wo, wm);
  if (!(pdf_wm > 0.f)) return bs;
  Choice c = restrict_choice(R, T, allowed);
  if (c.pr == 0.f && c.pt == 0.f) return bs;
  if (uc < c.pr / (c.pr + c.pt)) {
    Vec3 wi = reflect(wo, wm);
    if (!same_hemisphere(wo, wi)) return bs;
    float pdf = pdf_wm / (4.f * std::abs(glm::dot(wo, wm))) * c.pr / (c.pr + c.pt);
    Rgb fr(distrib_.D(wm) * distrib_.G(wo, wi) * R / std::abs(4.f * wo.z * wi.z));
    if (choice) *choice = R / (R + T);
    emplace_sample(bs, fr, wi, pdf, BsdfReflection | BsdfGlossy);
    return bs;
  }
  float etap;
  Vec3 wi;
  if (!refract(wo, wm, eta_, &etap, &wi) || same_hemisphere(wo, wi) || wi.z == 0.f) return bs;
  float dot_i = glm::dot(wi, wm), dot_o = glm::dot(wo, wm);
  float denom = sqr(dot_i + dot_o / etap);
  float pdf = pdf_wm * std::abs(dot_i) / denom * c.pt / (c.pr + c.pt);
  float ft = distrib_.D(wm) * distrib_.G(wo, wi) * T * std::abs(dot_i * dot_o / (denom * wi.z * wo.z));
  if (mode == TransportMode::Radiance) ft /= sqr(etap);
  if (!(pdf > 0.f) || !std::isfinite(pdf)) return bs;
  if (choice) *choice = T / (R + T);
  emplace_sample(bs, Rgb(ft), wi, pdf, BsdfTransmission | BsdfGlossy, etap);
  return bs;
}

float DielectricBxdf::pdf(const Vec3& wo, const Vec3& wi, TransportMode, Lobes allowed) const {
  if (eta_ == 1.f || smooth()) return 0.f;
  std::optional<Pair> pr = pair(wo, wi);
  if (!pr) return 0.f;
  float R = fresnel_dielectric(glm::dot(wo, pr->wm), eta_), T = 1.f - R;
  Choice c = restrict_choice(R, T, allowed);
  if (c.pr == 0.f && c.pt == 0.f) return 0.f;
  float pdf_wm = distrib_.pdf(wo, pr->wm);
  if (pr->reflection) return pdf_wm / (4.f * std::abs(glm::dot(wo, pr->wm))) * c.pr / (c.pr + c.pt);
  float dot_i = glm::dot(wi, pr->wm);
  float denom = sqr(dot_i + glm::dot(wo, pr->wm) / pr->etap);
  return pdf_wm * std::abs(dot_i) / denom * c.pt / (c.pr + c.pt);
}

LobeSummary DielectricBxdf::lobe(const Vec3& wo) const {
  LobeSummary l;
  l.alpha_x = distrib_.alpha_x();
  l.alpha_y = distrib_.alpha_y();
  if (eta_ == 1.f) {
    l.peak = -wo;
    l.coefficient = 1.f;
    return l;
  }
  float R = fresnel_dielectric(wo.z, eta_);
  Vec3 wt;
  if (1.f - R > R && refract(wo, Vec3(0.f, 0.f, 1.f), eta_, nullptr, &wt)) {
    l.peak = wt;
    l.coefficient = 1.f - R;
  } else {
    l.peak = Vec3(-wo.x, -wo.y, wo.z);
    l.coefficient = R;
  }
  return l;
}

std::optional<BsdfSample> DielectricBxdf::sample_smooth(const Vec3& wo, float uc, TransportMode mode, Lobes allowed,
                                                        float* choice) const {
  // Choosing the lobe with probability R makes every sample's weight exactly 1 (1/eta'^2 for
  // transmitted radiance): f |cos| / pdf = (R / |cos|) |cos| / R. A restricted choice keeps f and
  // takes the conditional probability.
  std::optional<BsdfSample> bs;  // the one object every path returns (emplace_sample)
  float R = fresnel_dielectric(wo.z, eta_), T = 1.f - R;
  float pr = R, pt = T;
  if (allowed != Lobes::All) {
    Choice c = restrict_choice(R, T, allowed);
    if (c.pr == 0.f && c.pt == 0.f) return bs;
    pr = c.pr / (c.pr + c.pt);
    pt = c.pt / (c.pr + c.pt);
  }
  if (uc < pr) {
    Vec3 wi(-wo.x, -wo.y, wo.z);
    if (choice) *choice = R;
    emplace_sample(bs, Rgb(R / std::abs(wi.z)), wi, pr, BsdfReflection | BsdfSpecular);
    return bs;
  }
  float etap;
  Vec3 wi;
  if (!refract(wo, Vec3(0.f, 0.f, 1.f), eta_, &etap, &wi) || wi.z == 0.f) return bs;
  float ft = T / std::abs(wi.z);
  if (mode == TransportMode::Radiance) ft /= sqr(etap);
  if (choice) *choice = T;
  emplace_sample(bs, Rgb(ft), wi, pt, BsdfTransmission | BsdfSpecular, etap);
  return bs;
}

std::optional<DielectricBxdf::Pair> DielectricBxdf::pair(const Vec3& wo, const Vec3& wi) const {
  if (wo.z == 0.f || wi.z == 0.f) return std::nullopt;
  Pair p;
  p.reflection = same_hemisphere(wo, wi);
  p.etap = p.reflection ? 1.f : (wo.z > 0.f ? eta_ : 1.f / eta_);
  Vec3 wm = wi * p.etap + wo;  // the generalized half vector (Walter et al. eq. 16)
  if (glm::dot(wm, wm) == 0.f) return std::nullopt;
  wm = glm::normalize(wm);
  if (wm.z < 0.f) wm = -wm;
  // Microfacets seen from behind by wo or wi cannot produce this pair.
  if (glm::dot(wm, wi) * wi.z < 0.f || glm::dot(wm, wo) * wo.z < 0.f) return std::nullopt;
  p.wm = wm;
  return p;
}

}  // namespace penumbra::bxdf
