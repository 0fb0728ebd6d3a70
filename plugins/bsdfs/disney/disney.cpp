// Material "disney": the Disney principled BSDF (Burley 2012, 2015) with pbrt-v3's parameters:
// Burley diffuse with retro-reflection, sheen, anisotropic GGX specular with Disney's Fresnel,
// GTR1 clearcoat, rough specular transmission, and for thin surfaces a flatness-blended fake
// subsurface lobe and diffuse transmission. No subsurface scattering. `color` and every fraction
// may be a texture (`"texture roughness" "name"`), clamped into its range at each lookup.
//
// | parameter            | default     | meaning                                                      |
// |----------------------|-------------|--------------------------------------------------------------|
// | rgb color            | 0.5 0.5 0.5 | base colour, each channel in [0, 1]                          |
// | float metallic       | 0           | 0 dielectric .. 1 metal (specular coloured by `color`)       |
// | float eta            | 1.5         | IOR of the dielectric part (specular Fresnel, transmission)  |
// | float roughness      | 0.5         | alpha = roughness^2; below 1e-3 (both axes): a delta, see notes |
// | float speculartint   | 0           | tints the Schlick R0 towards the colour's hue                |
// | float anisotropic    | 0           | stretches the highlight along the shading frame's s axis     |
// | float sheen          | 0           | grazing-angle sheen for cloth                                |
// | float sheentint      | 0.5         | tints the sheen towards the colour's hue                     |
// | float clearcoat      | 0           | weight of the clear coat (0.25 clearcoat, IOR 1.5)           |
// | float clearcoatgloss | 1           | coat GTR1 alpha = lerp(0.1, 0.001, clearcoatgloss), never a delta |
// | float spectrans      | 0           | share of the dielectric part that refracts                   |
// | bool thin            | false       | thin surface: one-lobe transmission, flatness, difftrans     |
// | float flatness       | 0           | thin only: blends diffuse into the fake subsurface lobe      |
// | float difftrans      | 1           | thin only, in [0, 2]: 0 reflects all diffuse light, 2 transmits all |
//
// Notes: speculartint only shows where metallic is between 0 and 1 (the dielectric part uses the
// exact dielectric Fresnel, as in pbrt-v3). Within 1e-3 of eta = 1 transmission is a straight
// pass-through (a delta lobe).
//
// Smooth lobes are deltas, with conductor's and dielectric's threshold (TrowbridgeReitz::
// kSmoothAlpha = 1e-3 in penumbra/microfacet.h): where the specular alpha (roughness^2, stretched by
// anisotropic) is below 1e-3 along both axes (roughness below ~0.0316 when isotropic), the specular
// reflection, metallic and dielectric parts together, is a perfect mirror; where the transmission
// alpha is (the same, or for thin surfaces ((0.65 eta - 0.35) roughness)^2), transmission is a
// perfect refraction, and for thin surfaces a straight pass-through of weight 1 - F without the
// 1/eta^2 of entering a medium (it is left again at once). pbrt-v3 instead clamps alpha to 1e-3
// and keeps a GGX lobe there, which next-event estimation turns into fireflies. "metallic 1
// roughness 0" is thus conductor's mirror with Schlick's Fresnel from `color`, and "spectrans 1
// roughness 0 color 1" is dielectric's smooth glass. Other lobes stay what they are: a mirror
// on a diffuse base (metallic 0.5, roughness 0) is a delta plus a diffuse lobe. The clearcoat
// is never a delta: GTR1's alpha is at least 0.001 by its definition (clearcoatgloss 1).
#include "textured_disney.h"
#include "disney_bsdf.h"

#include <penumbra/plugin.h>

#include <string>

namespace {

using namespace penumbra;

const ParamSpec kParams[] = {
    {"rgb texture", "color", "0.5 0.5 0.5", "base colour, each channel in [0, 1]"},
    {"float texture", "metallic", "0", "0 dielectric .. 1 metal"},
    {"float", "eta", "1.5", "index of refraction of the dielectric part"},
    {"float texture", "roughness", "0.5", "0 smooth .. 1 rough; alpha = roughness^2, a perfect mirror/refraction below alpha 1e-3"},
    {"float texture", "speculartint", "0", "tints the Schlick specular colour towards the base hue (shows for 0 < metallic < 1)"},
    {"float texture", "anisotropic", "0", "0 isotropic .. 1 highlight stretched along the tangent"},
    {"float texture", "sheen", "0", "grazing-angle sheen (cloth)"},
    {"float texture", "sheentint", "0.5", "tints the sheen towards the base hue"},
    {"float texture", "clearcoat", "0", "clear coat weight (a second, achromatic specular layer)"},
    {"float texture", "clearcoatgloss", "1", "0 satin .. 1 glossy clear coat"},
    {"float texture", "spectrans", "0", "specular transmission: 0 opaque .. 1 glass"},
    {"bool", "thin", "false", "thin surface: transmission without a volume inside"},
    {"float texture", "flatness", "0", "thin only: flattens the diffuse lobe (fake subsurface)"},
    {"float texture", "difftrans", "1", "thin only: 0 reflects all diffuse light, 2 transmits all"},
    {"unsupported", "scatterdistance", "", "subsurface scattering is not supported; use spectrans or thin"},
    {"unsupported", "bumpmap", "", "bump mapping is not supported"},
};

// The weights and blends are fractions: outside [0, max] they would create energy or go negative.
float fraction(const ParamSet& params, const char* name, int max = 1) {
  float v = params.get_float(name);
  if (!(v >= 0.f && v <= float(max)))
    throw Error(params.loc_of(name), std::string(name) + " must be in [0, " + std::to_string(max) + "]");
  return v;
}

// The texturable fractions: parameter name, field and upper bound.
struct Fraction {
  const char* name;
  float disney::DisneyParams::*field;
  float max;
};
const Fraction kFractions[] = {
    {"metallic", &disney::DisneyParams::metallic, 1.f},
    {"roughness", &disney::DisneyParams::roughness, 1.f},
    {"speculartint", &disney::DisneyParams::specular_tint, 1.f},
    {"anisotropic", &disney::DisneyParams::anisotropic, 1.f},
    {"sheen", &disney::DisneyParams::sheen, 1.f},
    {"sheentint", &disney::DisneyParams::sheen_tint, 1.f},
    {"clearcoat", &disney::DisneyParams::clearcoat, 1.f},
    {"clearcoatgloss", &disney::DisneyParams::clearcoat_gloss, 1.f},
    {"spectrans", &disney::DisneyParams::spec_trans, 1.f},
    {"flatness", &disney::DisneyParams::flatness, 1.f},
    {"difftrans", &disney::DisneyParams::diff_trans, 2.f},
};

// Textured parameters are clamped into their ranges per lookup. The lobes a hit can have are the
// union of those of the extremes (every textured fraction at 0, then at its maximum), with both a
// delta and a glossy specular when the roughness varies.
Object* create_textured(const CreateContext& ctx, const disney::DisneyParams& base) {
  TexturedRgb color = ctx.rgb_input("color");
  std::vector<std::pair<Fraction, TexturedFloat>> varying;
  for (const Fraction& f : kFractions) {
    TexturedFloat in = ctx.float_input(f.name);
    if (!in.is_constant()) varying.emplace_back(f, in);
  }
  auto params_at = [base, color, varying](const TextureEvalContext& tc) {
    disney::DisneyParams p = base;
    // The colour in RGB even in a spectral render: DisneyBsdf makes its spectra after deriving
    // the tints from it.
    TextureEvalContext rgb_tc = tc;
    rgb_tc.wavelengths = nullptr;
    p.color = glm::clamp(color.evaluate(rgb_tc), Rgb(0.f), Rgb(1.f));
    p.wavelengths = tc.wavelengths;
    for (const auto& [f, in] : varying) p.*(f.field) = std::clamp(in.evaluate(tc), 0.f, f.max);
    return p;
  };
  uint32_t flags = 0;
  for (float extreme : {0.f, 1.f}) {
    disney::DisneyParams p = base;
    if (!color.is_constant()) p.color = Rgb(0.5f);
    for (const auto& [f, in] : varying) p.*(f.field) = extreme * f.max;
    flags |= disney::DisneyBsdf(p).flags();
  }
  for (const auto& [f, in] : varying)
    if (f.field == &disney::DisneyParams::roughness) flags |= BsdfSpecular | BsdfGlossy;
  return new disney::TexturedDisneyBsdf(params_at, flags);
}

Rgb checked_color(const ParamSet& ps) {
  Rgb c = ps.get_rgb("color");
  if (!(glm::all(glm::greaterThanEqual(c, Rgb(0.f))) && glm::all(glm::lessThanEqual(c, Rgb(1.f)))))
    throw Error(ps.loc_of("color"), "color must be in [0, 1] (energy would not be conserved)");
  return c;
}

bool any_textured(const ParamSet& ps) {
  for (const auto& p : ps.params())
    if (p.type == "texture") return true;
  return false;
}

Object* create(const CreateContext& ctx) {
  const ParamSet& ps = ctx.params;
  // Textured, or in a spectral render (whose colours are made per hit, at the path's wavelengths).
  if (any_textured(ps) || ctx.spectral) {
    // Constants are still checked; the textured ones take their defaults here and vary per hit.
    disney::DisneyParams base;
    if (ps.find("color") && ps.find("color")->type != "texture") base.color = checked_color(ps);
    for (const Fraction& f : kFractions) {
      const Param* given = ps.find(f.name);
      if (!given || given->type != "texture") base.*(f.field) = fraction(ps, f.name, static_cast<int>(f.max));
    }
    base.eta = ps.get_float("eta");
    if (!(base.eta > 0.f && std::isfinite(base.eta))) throw Error(ps.loc_of("eta"), "eta must be positive");
    base.thin = ps.get_bool("thin");
    return create_textured(ctx, base);
  }
  disney::DisneyParams p;
  p.color = checked_color(ps);
  p.metallic = fraction(ps, "metallic");
  p.eta = ps.get_float("eta");
  if (!(p.eta > 0.f && std::isfinite(p.eta))) throw Error(ps.loc_of("eta"), "eta must be positive");
  p.roughness = fraction(ps, "roughness");
  p.specular_tint = fraction(ps, "speculartint");
  p.anisotropic = fraction(ps, "anisotropic");
  p.sheen = fraction(ps, "sheen");
  p.sheen_tint = fraction(ps, "sheentint");
  p.clearcoat = fraction(ps, "clearcoat");
  p.clearcoat_gloss = fraction(ps, "clearcoatgloss");
  p.spec_trans = fraction(ps, "spectrans");
  p.thin = ps.get_bool("thin");
  p.flatness = fraction(ps, "flatness");
  p.diff_trans = fraction(ps, "difftrans", 2);
  return new disney::DisneyBsdf(p);
}

}  // namespace

PENUMBRA_PLUGIN(Bsdf, "disney", "Disney principled BSDF (pbrt-v3 parameters)", kParams, create)
