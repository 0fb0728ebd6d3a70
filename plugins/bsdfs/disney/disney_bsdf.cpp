#include "disney_bsdf.h"

#include <penumbra/sampling.h>

#include <array>

namespace penumbra::disney {

namespace {

// Within this distance of 1 the refracted lobe is narrower than (eta - 1) radians: invisible, and
// too sharp to evaluate as a density (dwm/dwi grows like 1 / (eta - 1)^2).
constexpr float kPassThroughEtaTolerance = 1e-3f;

TrowbridgeReitz disney_distribution(float roughness, float aspect) {
  // Burley: alpha = roughness^2 (not the sqrt remap of pbrt-v4's other materials), stretched by
  // the aspect ratio for anisotropy. No clamp of Burley's (pbrt-v3's alpha >= 1e-3): below
  // TrowbridgeReitz::kSmoothAlpha on both axes the lobe is a delta (effectively_smooth()).
  float a = sqr(roughness);
  return TrowbridgeReitz(a / aspect, a * aspect);
}

// What a delta lobe reports as its alpha in the lobe summary: the distribution's floor.
float delta_alpha() { return TrowbridgeReitz(0.f, 0.f).alpha_x(); }

}  // namespace

DisneyBsdf::DisneyBsdf(const DisneyParams& p) : eta_(p.eta), thin_(p.thin) {
  const Rgb& rgb = p.color;
  float lum = luminance(rgb);
  Rgb rgb_tint = lum > 0.f ? rgb / lum : Rgb(1.f);  // hue and saturation only
  Rgb rgb_sqrt = glm::sqrt(rgb);
  // In a spectral render, each derived colour's spectrum at the path's wavelengths (the tint can
  // exceed 1: an unbounded value).
  const SampledWavelengths* w = p.wavelengths;
  const Rgb c = w ? w->albedo(rgb) : rgb;
  const Rgb tint = w ? w->unbounded(rgb_tint) : rgb_tint;
  const Rgb c_sqrt = w ? w->albedo(rgb_sqrt) : rgb_sqrt;

  // Diffuse family. Unlike pbrt-v3, retro-reflection and diffuse transmission are also scaled so
  // that reflected + transmitted diffuse keep the diffuse weight, and metals never transmit.
  float diffuse_weight = (1.f - p.metallic) * (1.f - p.spec_trans);
  float transmitted = p.thin ? 0.5f * p.diff_trans : 0.f;
  float flat = p.thin ? p.flatness : 0.f;
  Rgb body = diffuse_weight * (1.f - transmitted) * c;
  diffuse_.diffuse = body * (1.f - flat);
  diffuse_.fake_subsurface = body * flat;
  diffuse_.retro = body;
  diffuse_.roughness = p.roughness;
  if (p.sheen > 0.f) diffuse_.sheen = diffuse_weight * p.sheen * glm::mix(Rgb(1.f), tint, p.sheen_tint);
  diffuse_transmission_ = diffuse_weight * transmitted * c;

  float aspect = std::sqrt(1.f - 0.9f * p.anisotropic);
  specular_.distribution = disney_distribution(p.roughness, aspect);
  specular_.cspec0 = glm::mix(schlick_r0_from_eta(p.eta) * glm::mix(Rgb(1.f), tint, p.specular_tint), c, p.metallic);
  specular_.metallic = p.metallic;

  clearcoat_.weight = 0.25f * p.clearcoat;
  clearcoat_.alpha = glm::mix(0.1f, 0.001f, p.clearcoat_gloss);
  clearcoat_.r0 = p.clearcoat_r0;

  // sqrt(colour): light crossing two interfaces comes out with the base colour.
  transmission_.tint = (1.f - p.metallic) * p.spec_trans * c_sqrt;
  // Thin surfaces stand for two interfaces with one lobe: Burley 2015 fig. 15 widens it with eta.
  transmission_.distribution =
      p.thin ? disney_distribution((0.65f * p.eta - 0.35f) * p.roughness, aspect) : specular_.distribution;
  transmissive_ = !is_black(transmission_.tint);
  pass_through_ = std::abs(p.eta - 1.f) < kPassThroughEtaTolerance;
  specular_delta_ = specular_.distribution.effectively_smooth();
  transmission_delta_ = pass_through_ || transmission_.distribution.effectively_smooth();

  if (diffuse_.active()) flags_ |= BsdfReflection | BsdfDiffuse;
  if (specular_.active(eta_)) flags_ |= BsdfReflection | (specular_delta_ ? BsdfSpecular : BsdfGlossy);
  if (clearcoat_.active()) flags_ |= BsdfReflection | BsdfGlossy;
  if (transmissive_) flags_ |= BsdfTransmission | (transmission_delta_ ? BsdfSpecular : BsdfGlossy);
  if (!is_black(diffuse_transmission_)) flags_ |= BsdfTransmission | BsdfDiffuse;
}

DisneyBsdf::Side DisneyBsdf::side_of(const Vec3& wo) const {
  bool flipped = wo.z < 0.f;
  // An opaque surface is two-sided; a transmissive one has an inside, where eta inverts (pbrt-v3).
  float eta = flipped && transmissive_ ? 1.f / eta_ : eta_;
  return Side{flipped, Vec3(wo.x, wo.y, std::abs(wo.z)), eta};
}

DisneyBsdf::Weights DisneyBsdf::weights(const Side& side) const {
  // Approximate albedos for this wo. Any positive weight is unbiased, since pdf() uses the same
  // ones; a lobe that can contribute keeps a floor so that its directions are never unreachable.
  float cos_o = side.wo.z;
  Weights w;
  w.diffuse = diffuse_.selection_weight();
  if (specular_.active(eta_)) w.specular = std::max(luminance(specular_.fresnel(cos_o, side.eta)), 1e-3f);
  if (clearcoat_.active()) w.clearcoat = clearcoat_.weight * fresnel_schlick(clearcoat_.r0, cos_o);
  if (transmissive_) {
    float t = 1.f - fresnel_dielectric(cos_o, side.eta);
    // Past the critical angle rough facets still refract some light: keep sampling them. A delta
    // refracts exactly 1 - F (nothing under total internal reflection).
    w.transmission = luminance(transmission_.tint) * (transmission_delta_ ? t : std::max(t, 0.1f));
  }
  if (!is_black(diffuse_transmission_)) w.diffuse_transmission = std::max(luminance(diffuse_transmission_), 1e-3f);
  return w;
}

Rgb DisneyBsdf::f_upper(const Side& side, const Vec3& wi, TransportMode mode) const {
  const Vec3& wo = side.wo;
  if (wi.z > 0.f) {
    Rgb r(0.f);
    if (diffuse_.active()) r += diffuse_.f(wo, wi);
    if (rough_specular()) r += specular_.f(wo, wi, side.eta);
    if (clearcoat_.active()) r += Rgb(clearcoat_.f(wo, wi));
    return r;
  }
  Rgb t = diffuse_transmission_ * InvPi;
  if (rough_transmission()) t += transmission_.f(wo, wi, side.eta, mode);
  return t;
}

float DisneyBsdf::pdf_upper(const Side& side, const Weights& w, const Vec3& wi) const {
  float sum = w.sum();
  if (!(sum > 0.f)) return 0.f;
  const Vec3& wo = side.wo;
  float p = 0.f;
  if (wi.z > 0.f) {
    if (w.diffuse > 0.f) p += w.diffuse * cosine_hemisphere_pdf(wi.z);
    if (w.specular > 0.f && !specular_delta_) p += w.specular * specular_.pdf(wo, wi);
    if (w.clearcoat > 0.f) p += w.clearcoat * clearcoat_.pdf(wo, wi);
  } else {
    if (w.diffuse_transmission > 0.f) p += w.diffuse_transmission * cosine_hemisphere_pdf(-wi.z);
    if (w.transmission > 0.f && rough_transmission()) p += w.transmission * transmission_.pdf(wo, wi, side.eta);
  }
  return p / sum;
}

Rgb DisneyBsdf::f(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const {
  if (wo.z == 0.f || wi.z == 0.f) return Rgb(0.f);
  Side side = side_of(wo);
  return f_upper(side, side.to_upper(wi), ctx.mode);
}

float DisneyBsdf::pdf(const Vec3& wo, const Vec3& wi, const ShadingContext&) const {
  if (wo.z == 0.f || wi.z == 0.f) return 0.f;
  Side side = side_of(wo);
  return pdf_upper(side, weights(side), side.to_upper(wi));
}

std::optional<BsdfSample> DisneyBsdf::sample_f(const Vec3& wo, float uc, Vec2 u, const ShadingContext& ctx) const {
  if (wo.z == 0.f || flags_ == 0) return std::nullopt;
  Side side = side_of(wo);
  Weights w = weights(side);
  float sum = w.sum();
  if (!(sum > 0.f)) return std::nullopt;

  enum Lobe { Diffuse, Specular, Coat, Transmission, DiffuseTransmission };
  std::array<float, 5> lobe_weights = {w.diffuse, w.specular, w.clearcoat, w.transmission, w.diffuse_transmission};
  // Rounding may leave uc * sum past the last boundary: fall back to the last lobe that exists.
  int lobe = -1;
  float x = uc * sum, acc = 0.f;
  for (int k = 0; k < 5; ++k) {
    if (lobe_weights[k] <= 0.f) continue;
    lobe = k;
    acc += lobe_weights[k];
    if (x < acc) break;
  }

  std::optional<Vec3> wi;
  uint32_t sampled = 0;
  switch (lobe) {
    case Diffuse:
      wi = sample_cosine_hemisphere(u);
      sampled = BsdfReflection | BsdfDiffuse;
      break;
    case Specular:
      if (specular_delta_) {
        // A mirror, as conductor's: f = F / |cos| and pdf the lobe's probability, so that
        // f |cos| / pdf = F / p. The half vector is the normal: Fresnel at cos_o.
        Vec3 mirror(-side.wo.x, -side.wo.y, side.wo.z);
        Rgb f = specular_.fresnel(side.wo.z, side.eta) / side.wo.z;
        return BsdfSample{f, side.to_upper(mirror), w.specular / sum, BsdfReflection | BsdfSpecular};
      }
      wi = specular_.sample(side.wo, u);
      sampled = BsdfReflection | BsdfGlossy;
      break;
    case Coat:
      wi = clearcoat_.sample(side.wo, u);
      sampled = BsdfReflection | BsdfGlossy;
      break;
    case Transmission:
      if (transmission_delta_) {
        // A delta, as dielectric's smooth refraction: f = (1 - F) tint / |cos_i| and pdf the lobe's
        // probability. Straight through for eta ~ 1 and for thin surfaces (two parallel interfaces
        // give the direction back, and the radiance compression of entering is undone on leaving,
        // so thin surfaces do not scale by 1/eta^2); otherwise refracted about the normal.
        float T = 1.f - fresnel_dielectric(side.wo.z, side.eta);
        Vec3 wt = -side.wo;
        float etap = side.eta;
        if (!pass_through_ && !thin_ && !refract(side.wo, Vec3(0.f, 0.f, 1.f), side.eta, &etap, &wt))
          return std::nullopt;  // total internal reflection: T = 0, never chosen
        if (!(T > 0.f) || wt.z == 0.f) return std::nullopt;
        Rgb f = transmission_.tint * (T / std::abs(wt.z));
        if (ctx.mode == TransportMode::Radiance && !thin_) f /= sqr(etap);
        return BsdfSample{f, side.to_upper(wt), w.transmission / sum, BsdfTransmission | BsdfSpecular,
                          thin_ ? 1.f : etap};
      }
      wi = transmission_.sample(side.wo, u, side.eta);
      sampled = BsdfTransmission | BsdfGlossy;
      break;
    case DiffuseTransmission:
      wi = sample_cosine_hemisphere(u);
      if (wi) wi->z = -wi->z;
      sampled = BsdfTransmission | BsdfDiffuse;
      break;
    default:
      return std::nullopt;
  }
  if (!wi || wi->z == 0.f) return std::nullopt;
  float pdf = pdf_upper(side, w, *wi);
  if (!(pdf > 0.f)) return std::nullopt;
  // The rough transmission lobe scales radiance by 1/eta^2 (disney_lobes.cpp), which the sample reports.
  float eta = sampled == (BsdfTransmission | BsdfGlossy) ? side.eta : 1.f;
  return BsdfSample{f_upper(side, *wi, ctx.mode), side.to_upper(*wi), pdf, sampled, eta};
}

LobeSummary DisneyBsdf::lobe(const Vec3& wo, const ShadingContext&) const {
  LobeSummary l;
  l.peak = Vec3(0.f, 0.f, wo.z < 0.f ? -1.f : 1.f);
  l.cosine = true;
  if (wo.z == 0.f || flags_ == 0) return l;
  Side side = side_of(wo);
  Weights w = weights(side);
  float diffuse = w.diffuse + w.diffuse_transmission;
  // Delta lobes are left out when there are others: connections (the summary's users) only see f()
  // of the non-delta lobes. A BSDF of delta lobes only describes its strongest delta, as conductor
  // and dielectric do for theirs.
  bool has_non_delta = diffuse > 0.f || w.clearcoat > 0.f || (w.specular > 0.f && !specular_delta_) ||
                       (w.transmission > 0.f && !transmission_delta_);
  float specular = has_non_delta && specular_delta_ ? 0.f : w.specular;
  float transmission = has_non_delta && transmission_delta_ ? 0.f : w.transmission;
  float best = std::max({diffuse, specular, w.clearcoat, transmission});
  const Vec3 up(0.f, 0.f, 1.f);
  if (best == diffuse) {
    l.coefficient = diffuse;
    return l;
  }
  l.cosine = false;
  l.coefficient = best;
  Vec3 peak = reflect(side.wo, up);
  if (best == specular) {
    l.alpha_x = specular_.distribution.alpha_x();
    l.alpha_y = specular_.distribution.alpha_y();
  } else if (best == w.clearcoat) {
    l.alpha_x = l.alpha_y = clearcoat_.alpha;
  } else {
    l.alpha_x = pass_through_ ? delta_alpha() : transmission_.distribution.alpha_x();
    l.alpha_y = pass_through_ ? delta_alpha() : transmission_.distribution.alpha_y();
    Vec3 refracted;
    float etap;
    if (pass_through_ || (thin_ && transmission_delta_)) peak = -side.wo;
    else if (refract(side.wo, up, side.eta, &etap, &refracted)) peak = refracted;
  }
  l.peak = side.to_upper(peak);
  return l;
}

}  // namespace penumbra::disney
