// Material "disney": the Disney principled BSDF (Burley 2012, 2015) with pbrt-v3's parameters:
// Burley diffuse with retro-reflection, sheen, anisotropic GGX specular with Disney's Fresnel,
// GTR1 clearcoat, rough specular transmission, and for thin surfaces a flatness-blended fake
// subsurface lobe and diffuse transmission. No subsurface scattering.
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
#include "disney_bsdf.h"

#include <penumbra/plugin.h>

#include <string>

namespace {

using namespace penumbra;

const ParamSpec kParams[] = {
    {"rgb", "color", "0.5 0.5 0.5", "base colour, each channel in [0, 1]"},
    {"float", "metallic", "0", "0 dielectric .. 1 metal"},
    {"float", "eta", "1.5", "index of refraction of the dielectric part"},
    {"float", "roughness", "0.5", "0 smooth .. 1 rough; alpha = roughness^2, a perfect mirror/refraction below alpha 1e-3"},
    {"float", "speculartint", "0", "tints the Schlick specular colour towards the base hue (shows for 0 < metallic < 1)"},
    {"float", "anisotropic", "0", "0 isotropic .. 1 highlight stretched along the tangent"},
    {"float", "sheen", "0", "grazing-angle sheen (cloth)"},
    {"float", "sheentint", "0.5", "tints the sheen towards the base hue"},
    {"float", "clearcoat", "0", "clear coat weight (a second, achromatic specular layer)"},
    {"float", "clearcoatgloss", "1", "0 satin .. 1 glossy clear coat"},
    {"float", "spectrans", "0", "specular transmission: 0 opaque .. 1 glass"},
    {"bool", "thin", "false", "thin surface: transmission without a volume inside"},
    {"float", "flatness", "0", "thin only: flattens the diffuse lobe (fake subsurface)"},
    {"float", "difftrans", "1", "thin only: 0 reflects all diffuse light, 2 transmits all"},
    {"unsupported", "scatterdistance", "", "subsurface scattering is not supported; use spectrans or thin"},
    {"unsupported", "bumpmap", "", "bump mapping is not supported"},
    {"unsupported", "displacement", "", "displacement is not supported"},
    {"unsupported", "normalmap", "", "normal maps are not supported yet"},
};

// The weights and blends are fractions: outside [0, max] they would create energy or go negative.
float fraction(const ParamSet& params, const char* name, int max = 1) {
  float v = params.get_float(name);
  if (!(v >= 0.f && v <= float(max)))
    throw Error(params.loc_of(name), std::string(name) + " must be in [0, " + std::to_string(max) + "]");
  return v;
}

Object* create(const CreateContext& ctx) {
  const ParamSet& ps = ctx.params;
  disney::DisneyParams p;
  p.color = ps.get_rgb("color");
  if (!(glm::all(glm::greaterThanEqual(p.color, Rgb(0.f))) && glm::all(glm::lessThanEqual(p.color, Rgb(1.f)))))
    throw Error(ps.loc_of("color"), "color must be in [0, 1] (energy would not be conserved)");
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
