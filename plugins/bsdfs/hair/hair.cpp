// Material "hair" (pbrt-v4's): the Chiang et al. 2016 hair model of hair_bxdf.h, for curves (and any
// surface whose v runs across a fibre: h = -1 + 2 v at the hit, as pbrt-v4 takes it).
//
// | parameter          | default | meaning                                                        |
// |--------------------|---------|----------------------------------------------------------------|
// | rgb sigma_a        |         | absorption per fibre diameter (or a spectrum texture)          |
// | rgb reflectance    |         | the colour the fibre should have: sigma_a by pbrt-v4's fit     |
// | float eumelanin    |         | melanin concentrations: sigma_a from pbrt-v4's coefficients;   |
// | float pheomelanin  |         |   eumelanin 1.3 when none of the four colour inputs is given   |
// | float eta          | 1.55    | index of refraction of the fibre                               |
// | float beta_m       | 0.3     | longitudinal roughness, (0, 1]                                 |
// | float beta_n       | 0.3     | azimuthal roughness, (0, 1]                                    |
// | float alpha        | 2       | cuticle scale tilt in degrees                                  |
//
// Which colour input counts, as pbrt-v4: sigma_a, else reflectance, else the melanin concentrations.
// The float parameters may be float textures. pbrt-v4 renders spectrally, converting sigma_a and the
// melanin coefficients to spectra; here they stay RGB (docs/scene-format.md).
#include "hair_bxdf.h"

#include <penumbra/bsdf.h>
#include <penumbra/plugin.h>

namespace {

using namespace penumbra;
using namespace penumbra::hair;

enum class ColourInput { SigmaA, Reflectance, Melanin };

class HairBsdf final : public Bsdf {
 public:
  HairBsdf(ColourInput input, TexturedRgb colour, TexturedFloat eumelanin, TexturedFloat pheomelanin, TexturedFloat eta,
           TexturedFloat beta_m, TexturedFloat beta_n, TexturedFloat alpha, bool spectral)
      : input_(input),
        colour_(colour),
        eumelanin_(eumelanin),
        pheomelanin_(pheomelanin),
        eta_(eta),
        beta_m_(beta_m),
        beta_n_(beta_n),
        alpha_(alpha) {
    // What does not vary from hit to hit is made once: the lobes (from the roughnesses and the
    // tilt) and the absorption.
    TextureEvalContext none;
    if (beta_m.is_constant() && beta_n.is_constant() && alpha.is_constant())
      constant_lobes_ = lobes(none);
    bool colour_constant = input == ColourInput::Melanin ? eumelanin.is_constant() && pheomelanin.is_constant()
                                                         : colour.is_constant();
    // (In a spectral render the absorption is a spectrum at each path's wavelengths.)
    if (colour_constant && (input != ColourInput::Reflectance || beta_n.is_constant()) && !spectral)
      constant_sigma_a_ = sigma_a(none);
  }

  uint32_t flags() const override { return BsdfReflection | BsdfTransmission | BsdfGlossy; }

  Rgb f(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const override { return at(ctx).f(wo, wi); }

  std::optional<BsdfSample> sample_f(const Vec3& wo, float uc, Vec2 u, const ShadingContext& ctx) const override {
    std::optional<HairSample> s = at(ctx).sample_f(wo, uc, u);
    if (!s) return std::nullopt;
    uint32_t side = s->wi.z * wo.z > 0.f ? BsdfReflection : BsdfTransmission;
    return BsdfSample{s->f, s->wi, s->pdf, side | BsdfGlossy};
  }

  float pdf(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const override { return at(ctx).pdf(wo, wi); }

 private:
  float beta_n(const TextureEvalContext& t) const { return std::clamp(beta_n_.evaluate(t), 1e-3f, 1.f); }

  HairLobes lobes(const TextureEvalContext& t) const {
    return HairLobes::from(std::clamp(beta_m_.evaluate(t), 1e-3f, 1.f), beta_n(t), alpha_.evaluate(t));
  }

  Rgb sigma_a(const TextureEvalContext& t) const {
    switch (input_) {
      case ColourInput::SigmaA: return glm::max(colour_.evaluate(t), Rgb(0.f));
      case ColourInput::Reflectance: return sigma_a_from_reflectance(colour_.evaluate(t), beta_n(t));
      case ColourInput::Melanin: break;
    }
    Rgb s = sigma_a_from_concentration(std::max(0.f, eumelanin_.evaluate(t)), std::max(0.f, pheomelanin_.evaluate(t)));
    return t.wavelengths ? t.wavelengths->unbounded(s) : s;  // pbrt-v4: the RGB absorptions as spectra
  }

  HairBxdf at(const ShadingContext& ctx) const {
    const TextureEvalContext& t = ctx.tex;
    float h = std::clamp(-1.f + 2.f * t.uv.y, -1.f, 1.f);
    return HairBxdf(constant_lobes_ ? *constant_lobes_ : lobes(t), h, eta_.evaluate(t),
                    constant_sigma_a_ ? *constant_sigma_a_ : sigma_a(t));
  }

  ColourInput input_;
  TexturedRgb colour_;
  TexturedFloat eumelanin_, pheomelanin_, eta_, beta_m_, beta_n_, alpha_;
  std::optional<HairLobes> constant_lobes_;
  std::optional<Rgb> constant_sigma_a_;
};

const ParamSpec kParams[] = {
    {"rgb texture", "sigma_a", "", "absorption per fibre diameter, or a spectrum texture"},
    {"rgb texture", "reflectance", "", "fibre colour (sigma_a by pbrt-v4's fit), or a spectrum texture"},
    {"float texture", "eumelanin", "", "eumelanin concentration (1.3 when no colour input is given)"},
    {"float texture", "pheomelanin", "", "pheomelanin concentration"},
    {"float texture", "eta", "1.55", "index of refraction of the fibre"},
    {"float texture", "beta_m", "0.3", "longitudinal roughness in (0, 1]"},
    {"float texture", "beta_n", "0.3", "azimuthal roughness in (0, 1]"},
    {"float texture", "alpha", "2", "cuticle scale tilt in degrees"},
};

Object* create(const CreateContext& ctx) {
  const ParamSet& p = ctx.params;
  auto in_range = [&](const char* name, float lo, float hi, const char* what) {
    TexturedFloat t = ctx.float_input(name);
    if (t.is_constant() && !(t.constant() >= lo && t.constant() <= hi)) throw Error(p.loc_of(name), std::string(name) + what);
    return t;
  };
  TexturedFloat eta = ctx.float_input("eta");
  if (eta.is_constant() && !(eta.constant() > 0.f)) throw Error(p.loc_of("eta"), "eta must be > 0");
  TexturedFloat beta_m = in_range("beta_m", 1e-3f, 1.f, " must be in (0, 1]");
  TexturedFloat beta_n = in_range("beta_n", 1e-3f, 1.f, " must be in (0, 1]");
  TexturedFloat alpha = in_range("alpha", -90.f, 90.f, " must be in [-90, 90] degrees");
  ColourInput input = ColourInput::Melanin;
  TexturedRgb colour;
  TexturedFloat eu(1.3f), pheo(0.f);
  if (p.has("sigma_a")) {
    input = ColourInput::SigmaA;
    colour = ctx.rgb_input("sigma_a", RgbKind::Unbounded);
    if (colour.is_constant() && !(glm::all(glm::greaterThanEqual(colour.constant(), Rgb(0.f)))))
      throw Error(p.loc_of("sigma_a"), "sigma_a must be >= 0");
  } else if (p.has("reflectance")) {
    input = ColourInput::Reflectance;
    colour = ctx.rgb_input("reflectance");
    if (colour.is_constant()) {
      Rgb c = colour.constant();
      if (!(glm::all(glm::greaterThan(c, Rgb(0.f))) && max_component(c) <= 1.f))
        throw Error(p.loc_of("reflectance"), "hair reflectance must be in (0, 1]");
    }
  } else if (p.has("eumelanin") || p.has("pheomelanin")) {
    eu = p.has("eumelanin") ? ctx.float_input("eumelanin") : TexturedFloat(0.f);
    pheo = p.has("pheomelanin") ? ctx.float_input("pheomelanin") : TexturedFloat(0.f);
  }
  return new HairBsdf(input, colour, eu, pheo, eta, beta_m, beta_n, alpha, ctx.spectral);
}

}  // namespace

PENUMBRA_PLUGIN(Bsdf, "hair", "pbrt-v4's hair scattering (Chiang et al. 2016) for curves", kParams, create)
