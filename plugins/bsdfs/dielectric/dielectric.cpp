// Material "dielectric": glass or water, an interface between two non-absorbing media.
// Smooth (alpha < 1e-3): delta reflection and refraction, chosen with the Fresnel reflectance as
// probability. Rough: Trowbridge-Reitz microfacet reflection and transmission (Walter et al. 2007)
// with the generalized half vector, sampled from the visible normals. eta == 1 is an index-matched
// interface: light passes straight through. The outside is +z; wo below the surface is inside the
// medium, where the relative IOR is 1/eta.
//
// | parameter          | default   | meaning                                                  |
// |--------------------|-----------|----------------------------------------------------------|
// | float eta          | 1.5       | IOR inside relative to outside (a single value)          |
// | float roughness    | 0         | isotropic microfacet roughness (or a float texture)      |
// | float uroughness   | roughness | roughness along the shading frame's s axis               |
// | float vroughness   | roughness | roughness along the shading frame's t axis               |
// | bool remaproughness| true      | alpha = sqrt(roughness) (else alpha = roughness)         |
//
// Radiance is compressed by 1/eta'^2 when it refracts into a denser medium (TransportMode::Radiance);
// importance is not, which is what makes transmission non-symmetric.
#include <penumbra/bsdf.h>
#include <penumbra/microfacet.h>
#include <penumbra/plugin.h>

namespace {

using namespace penumbra;

class DielectricBsdf final : public Bsdf {
 public:
  DielectricBsdf(float eta, TrowbridgeReitz distrib) : eta_(eta), distrib_(distrib) {}

  uint32_t flags() const override {
    if (eta_ == 1.f) return BsdfTransmission | BsdfSpecular;
    return BsdfReflection | BsdfTransmission | (smooth() ? BsdfSpecular : BsdfGlossy);
  }

  Rgb f(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const override {
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
    if (ctx.mode == TransportMode::Radiance) ft /= sqr(pr->etap);
    return Rgb(ft);
  }

  std::optional<BsdfSample> sample_f(const Vec3& wo, float uc, Vec2 u, const ShadingContext& ctx) const override {
    if (wo.z == 0.f) return std::nullopt;
    if (eta_ == 1.f) return BsdfSample{Rgb(1.f / std::abs(wo.z)), -wo, 1.f, BsdfTransmission | BsdfSpecular};
    if (smooth()) return sample_smooth(wo, uc, ctx);

    Vec3 wm = distrib_.sample_wm(wo, u);
    float R = fresnel_dielectric(glm::dot(wo, wm), eta_), T = 1.f - R;
    float pdf_wm = distrib_.pdf(wo, wm);
    if (!(pdf_wm > 0.f)) return std::nullopt;
    if (uc < R / (R + T)) {
      Vec3 wi = reflect(wo, wm);
      if (!same_hemisphere(wo, wi)) return std::nullopt;
      float pdf = pdf_wm / (4.f * std::abs(glm::dot(wo, wm))) * R / (R + T);
      Rgb fr(distrib_.D(wm) * distrib_.G(wo, wi) * R / std::abs(4.f * wo.z * wi.z));
      return BsdfSample{fr, wi, pdf, BsdfReflection | BsdfGlossy};
    }
    float etap;
    Vec3 wi;
    if (!refract(wo, wm, eta_, &etap, &wi) || same_hemisphere(wo, wi) || wi.z == 0.f) return std::nullopt;
    float dot_i = glm::dot(wi, wm), dot_o = glm::dot(wo, wm);
    float denom = sqr(dot_i + dot_o / etap);
    float pdf = pdf_wm * std::abs(dot_i) / denom * T / (R + T);
    float ft = distrib_.D(wm) * distrib_.G(wo, wi) * T * std::abs(dot_i * dot_o / (denom * wi.z * wo.z));
    if (ctx.mode == TransportMode::Radiance) ft /= sqr(etap);
    if (!(pdf > 0.f) || !std::isfinite(pdf)) return std::nullopt;
    return BsdfSample{Rgb(ft), wi, pdf, BsdfTransmission | BsdfGlossy, etap};
  }

  float pdf(const Vec3& wo, const Vec3& wi, const ShadingContext&) const override {
    if (eta_ == 1.f || smooth()) return 0.f;
    std::optional<Pair> pr = pair(wo, wi);
    if (!pr) return 0.f;
    float R = fresnel_dielectric(glm::dot(wo, pr->wm), eta_), T = 1.f - R;
    float pdf_wm = distrib_.pdf(wo, pr->wm);
    if (pr->reflection) return pdf_wm / (4.f * std::abs(glm::dot(wo, pr->wm))) * R / (R + T);
    float dot_i = glm::dot(wi, pr->wm);
    float denom = sqr(dot_i + glm::dot(wo, pr->wm) / pr->etap);
    return pdf_wm * std::abs(dot_i) / denom * T / (R + T);
  }

  LobeSummary lobe(const Vec3& wo, const ShadingContext&) const override {
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

 private:
  bool smooth() const { return distrib_.effectively_smooth(); }

  std::optional<BsdfSample> sample_smooth(const Vec3& wo, float uc, const ShadingContext& ctx) const {
    // Choosing the lobe with probability R makes every sample's weight exactly 1 (1/eta'^2 for
    // transmitted radiance): f |cos| / pdf = (R / |cos|) |cos| / R.
    float R = fresnel_dielectric(wo.z, eta_), T = 1.f - R;
    if (uc < R) {
      Vec3 wi(-wo.x, -wo.y, wo.z);
      return BsdfSample{Rgb(R / std::abs(wi.z)), wi, R, BsdfReflection | BsdfSpecular};
    }
    float etap;
    Vec3 wi;
    if (!refract(wo, Vec3(0.f, 0.f, 1.f), eta_, &etap, &wi) || wi.z == 0.f) return std::nullopt;
    float ft = T / std::abs(wi.z);
    if (ctx.mode == TransportMode::Radiance) ft /= sqr(etap);
    return BsdfSample{Rgb(ft), wi, T, BsdfTransmission | BsdfSpecular, etap};
  }

  // The microfacet normal that scatters wo into wi, with what kind of event it is.
  struct Pair {
    Vec3 wm;
    float etap;  // relative IOR across the interface as wo sees it (1 for reflection)
    bool reflection;
  };
  std::optional<Pair> pair(const Vec3& wo, const Vec3& wi) const {
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

  float eta_;
  TrowbridgeReitz distrib_;
};

// Textured roughness: each call builds the distribution at the hit and forwards to a DielectricBsdf
// made on the stack (the constant material keeps its code and cost). Its flags are the union over
// roughness values, since a texture may make some points smooth.
class TexturedDielectricBsdf final : public PerHitBsdf<TexturedDielectricBsdf> {
  friend class PerHitBsdf<TexturedDielectricBsdf>;

 public:
  TexturedDielectricBsdf(float eta, MicrofacetRoughness r) : eta_(eta), r_(r) {}
  uint32_t flags() const override {
    if (eta_ == 1.f) return BsdfTransmission | BsdfSpecular;
    return BsdfReflection | BsdfTransmission | BsdfGlossy | BsdfSpecular;
  }

 private:
  DielectricBsdf at(const ShadingContext& ctx) const { return DielectricBsdf(eta_, r_.at(ctx.tex)); }
  float eta_;
  MicrofacetRoughness r_;
};

const ParamSpec kParams[] = {
    {"float|spectrum", "eta", "1.5", "index of refraction inside relative to outside; a spectrum gives its luminance-weighted mean (no dispersion)"},
    {"float texture", "roughness", "0", "isotropic microfacet roughness (0: smooth)"},
    {"float texture", "uroughness", "", "roughness along the shading frame's s axis (default: roughness)"},
    {"float texture", "vroughness", "", "roughness along the shading frame's t axis (default: roughness)"},
    {"bool", "remaproughness", "true", "alpha = sqrt(roughness) if true, else alpha = roughness"},
    {"unsupported", "displacement", "", "displacement is not supported"},
    {"unsupported", "normalmap", "", "normal maps are not supported yet"},
};

Object* create(const CreateContext& ctx) {
  const ParamSet& p = ctx.params;
  float eta = p.get_float("eta");
  if (!(eta > 0.f) || !std::isfinite(eta)) throw Error(p.loc_of("eta"), "eta must be a positive number");
  MicrofacetRoughness rough = microfacet_roughness(ctx);
  if (!rough.is_constant()) return new TexturedDielectricBsdf(eta, rough);
  Vec2 alpha = microfacet_alphas(p);
  float ur = alpha.x, vr = alpha.y;
  return new DielectricBsdf(eta, TrowbridgeReitz(ur, vr));
}

}  // namespace

PENUMBRA_PLUGIN(Bsdf, "dielectric", "glass and water: smooth or rough GGX reflection and refraction", kParams, create)
