#include "disney_lobes.h"

namespace penumbra::disney {

namespace {

// Half vector of a reflection pair above the surface; both directions above means it is never zero.
Vec3 half_vector(const Vec3& wo, const Vec3& wi) { return glm::normalize(wo + wi); }

}  // namespace

// ---- Diffuse family ---------------------------------------------------------------------------

float DiffuseLobes::selection_weight() const {
  // Retro-reflection and the flattened lobe redistribute roughly the diffuse albedo; sheen adds a
  // little at grazing angles. Only the ratio to the other lobes matters.
  float w = luminance(diffuse + fake_subsurface) + 0.5f * roughness * luminance(retro) + 0.1f * luminance(sheen);
  return active() ? std::max(w, 1e-3f) : 0.f;
}

Rgb DiffuseLobes::f(const Vec3& wo, const Vec3& wi) const {
  float fo = schlick_weight(wo.z), fi = schlick_weight(wi.z);
  float cos_d = glm::dot(wi, half_vector(wo, wi));  // angle between light and half vector
  Rgb result(0.f);
  // Burley 2015 eq. (4): the diffuse Fresnel term goes from 1 at normal incidence to 1/2 at grazing.
  result += diffuse * (InvPi * (1.f - 0.5f * fo) * (1.f - 0.5f * fi));
  if (!is_black(fake_subsurface)) {
    // Hanrahan-Krueger-like: flattens the lobe; 1.25 roughly restores the albedo.
    float fss90 = sqr(cos_d) * roughness;
    float fss = glm::mix(1.f, fss90, fo) * glm::mix(1.f, fss90, fi);
    float ss = 1.25f * (fss * (1.f / (wo.z + wi.z) - 0.5f) + 0.5f);
    result += fake_subsurface * (InvPi * ss);
  }
  if (!is_black(retro)) {
    float rr = 2.f * roughness * sqr(cos_d);
    result += retro * (InvPi * rr * (fo + fi + fo * fi * (rr - 1.f)));
  }
  if (!is_black(sheen)) result += sheen * schlick_weight(cos_d);
  return result;
}

// ---- Specular reflection ----------------------------------------------------------------------

Rgb SpecularReflection::fresnel(float cos_theta_d, float eta) const {
  Rgb dielectric(fresnel_dielectric(cos_theta_d, eta));
  return glm::mix(dielectric, fresnel_schlick(cspec0, cos_theta_d), metallic);
}

Rgb SpecularReflection::f(const Vec3& wo, const Vec3& wi, float eta) const {
  Vec3 wm = half_vector(wo, wi);
  float cos_d = glm::dot(wo, wm);
  return fresnel(cos_d, eta) * (distribution.D(wm) * distribution.G(wo, wi) / (4.f * wo.z * wi.z));
}

float SpecularReflection::pdf(const Vec3& wo, const Vec3& wi) const {
  Vec3 wm = half_vector(wo, wi);
  float cos_d = glm::dot(wo, wm);
  if (cos_d <= 0.f) return 0.f;
  // Visible-normal density, times the Jacobian of reflection dwm/dwi = 1 / (4 wo.wm).
  return distribution.pdf(wo, wm) / (4.f * cos_d);
}

std::optional<Vec3> SpecularReflection::sample(const Vec3& wo, Vec2 u) const {
  Vec3 wi = reflect(wo, distribution.sample_wm(wo, u));
  if (wi.z <= 0.f) return std::nullopt;  // reflected into the surface: shadowed
  return wi;
}

// ---- Clearcoat ----------------------------------------------------------------------------------

float Clearcoat::D(float cos_theta_m) const {
  // GTR1 (Berry): (a^2 - 1) / (pi ln(a^2) (1 + (a^2 - 1) cos^2)); alpha < 1 always here.
  float a2 = sqr(alpha);
  return (a2 - 1.f) / (Pi * std::log(a2) * (1.f + (a2 - 1.f) * sqr(cos_theta_m)));
}

float Clearcoat::f(const Vec3& wo, const Vec3& wi) const {
  // The coat's masking always uses alpha 0.25, whatever its gloss (Burley's choice).
  static const TrowbridgeReitz masking(0.25f, 0.25f);
  Vec3 wm = half_vector(wo, wi);
  float fr = fresnel_schlick(r0, glm::dot(wo, wm));
  float g = masking.G1(wo) * masking.G1(wi);
  return weight * D(wm.z) * fr * g / (4.f * wo.z * wi.z);
}

float Clearcoat::pdf(const Vec3& wo, const Vec3& wi) const {
  Vec3 wm = half_vector(wo, wi);
  float cos_d = glm::dot(wo, wm);
  if (cos_d <= 0.f) return 0.f;
  return D(wm.z) * wm.z / (4.f * cos_d);
}

std::optional<Vec3> Clearcoat::sample(const Vec3& wo, Vec2 u) const {
  // Inverts the CDF of D(theta_m) cos(theta_m) over the hemisphere.
  float a2 = sqr(alpha);
  float cos2 = (1.f - std::pow(a2, 1.f - u.x)) / (1.f - a2);
  float cos_m = safe_sqrt(cos2), sin_m = safe_sqrt(1.f - cos2);
  float phi = 2.f * Pi * u.y;
  Vec3 wm(sin_m * std::cos(phi), sin_m * std::sin(phi), cos_m);
  if (glm::dot(wo, wm) <= 0.f) return std::nullopt;  // facet seen from behind: no reflection
  Vec3 wi = reflect(wo, wm);
  if (wi.z <= 0.f) return std::nullopt;
  return wi;
}

// ---- Rough transmission -------------------------------------------------------------------------

namespace {

// Generalised half vector of a refraction pair, oriented up, and the two cosines with it. Returns
// false for pairs no microfacet can connect (a facet seen from behind by either direction).
struct RefractionGeometry {
  Vec3 wm;
  float cos_o, cos_i;  // wo.wm > 0, wi.wm < 0
  float denom;         // (wi.wm + wo.wm / eta)^2
};

std::optional<RefractionGeometry> refraction_geometry(const Vec3& wo, const Vec3& wi, float eta) {
  Vec3 wm = wi * eta + wo;
  float len2 = glm::dot(wm, wm);
  if (len2 == 0.f) return std::nullopt;
  wm /= std::sqrt(len2);
  if (wm.z < 0.f) wm = -wm;
  float cos_o = glm::dot(wo, wm), cos_i = glm::dot(wi, wm);
  if (cos_o <= 0.f || cos_i >= 0.f) return std::nullopt;
  float denom = sqr(cos_i + cos_o / eta);
  if (!(denom > 0.f)) return std::nullopt;
  return RefractionGeometry{wm, cos_o, cos_i, denom};
}

}  // namespace

Rgb RoughTransmission::f(const Vec3& wo, const Vec3& wi, float eta, TransportMode mode) const {
  std::optional<RefractionGeometry> g = refraction_geometry(wo, wi, eta);
  if (!g) return Rgb(0.f);
  float fr = fresnel_dielectric(g->cos_o, eta);
  float ft = distribution.D(g->wm) * (1.f - fr) * distribution.G(wo, wi) *
             std::abs(g->cos_i * g->cos_o / (wi.z * wo.z * g->denom));
  // Radiance is compressed into the smaller solid angle on the denser side (non-symmetric BTDF).
  if (mode == TransportMode::Radiance) ft /= sqr(eta);
  return tint * ft;
}

float RoughTransmission::pdf(const Vec3& wo, const Vec3& wi, float eta) const {
  std::optional<RefractionGeometry> g = refraction_geometry(wo, wi, eta);
  if (!g) return 0.f;
  // Visible-normal density times the Jacobian dwm/dwi of refraction.
  return distribution.pdf(wo, g->wm) * std::abs(g->cos_i) / g->denom;
}

std::optional<Vec3> RoughTransmission::sample(const Vec3& wo, Vec2 u, float eta) const {
  Vec3 wm = distribution.sample_wm(wo, u);
  Vec3 wi;
  float etap;
  if (!refract(wo, wm, eta, &etap, &wi)) return std::nullopt;  // total internal reflection
  if (wi.z >= 0.f) return std::nullopt;
  return glm::normalize(wi);
}

}  // namespace penumbra::disney
