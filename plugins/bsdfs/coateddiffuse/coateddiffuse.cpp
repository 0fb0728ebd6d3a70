// Material "coateddiffuse" (pbrt-v4): a diffuse base under a dielectric coat. pbrt-v4 simulates the
// layers stochastically; Penumbra approximates them with the Disney BSDF's pieces, and says so when
// a scene uses it: Burley's diffuse with the base reflectance (its (1 - F/2) factors darken grazing
// angles as a coat does) plus the GTR1 clearcoat at full strength, with R0 from the coat's eta and
// its gloss from the coat's roughness. The Disney specular lobe is off (eta 1), so the coat is the
// only specular reflection. Not energy-exact: the diffuse is not dimmed by what the coat reflects.
//
// | parameter            | default     | meaning                                                   |
// |----------------------|-------------|-----------------------------------------------------------|
// | rgb reflectance      | 0.5 0.5 0.5 | diffuse base albedo, each channel in [0, 1]               |
// | float roughness      | 0           | coat roughness (both directions)                          |
// | float uroughness     | roughness   | coat roughness along s (averaged with v: coat is isotropic) |
// | float vroughness     | roughness   | coat roughness along t                                    |
// | bool remaproughness  | true        | alpha = sqrt(roughness) as in pbrt-v4, else alpha = roughness |
// | float thickness      | 0.01        | accepted and ignored (no absorption in the layer)         |
// | float eta            | 1.5         | coat IOR, sets its normal-incidence reflectance           |
//
// Coat alpha maps to GTR1's: alpha 0 -> 0.001 (clearcoatgloss 1), alpha >= 0.1 -> 0.1 (gloss 0).
// reflectance may be a spectrum texture and the roughnesses float textures (evaluated per hit,
// reflectance clamped to [0, 1]).
#include "../disney/disney_bsdf.h"
#include "../disney/textured_disney.h"
#include <penumbra/microfacet.h>

#include <penumbra/plugin.h>

namespace {

using namespace penumbra;

const ParamSpec kParams[] = {
    {"rgb texture", "reflectance", "0.5 0.5 0.5", "diffuse base albedo, each channel in [0, 1]"},
    {"float texture", "roughness", "0", "coat roughness"},
    {"float texture", "uroughness", "", "coat roughness along s (default: roughness)"},
    {"float texture", "vroughness", "", "coat roughness along t (default: roughness)"},
    {"bool", "remaproughness", "true", "alpha = sqrt(roughness) when true, alpha = roughness otherwise"},
    {"float", "thickness", "0.01", "coat thickness: accepted and ignored (no absorption modelled)"},
    {"float|spectrum", "eta", "1.5", "coat index of refraction; a spectrum gives its luminance-weighted mean"},
    {"unsupported", "albedo", "", "a scattering coat layer is not supported"},
    {"unsupported", "g", "", "a scattering coat layer is not supported"},
    {"unsupported", "maxdepth", "", "the layers are approximated, not random-walked"},
    {"unsupported", "nsamples", "", "the layers are approximated, not random-walked"},
    {"unsupported", "displacement", "", "displacement is not supported"},
    {"unsupported", "normalmap", "", "normal maps are not supported yet"},
};

// The Disney parameters of the approximation for a base reflectance and coat alphas.
disney::DisneyParams coated_params(Rgb reflectance, Vec2 uv_alpha, float eta) {
  float alpha = std::sqrt(uv_alpha.x * uv_alpha.y);  // GTR1 is isotropic: keep the lobe's area
  disney::DisneyParams p;
  p.color = reflectance;
  p.metallic = 0.f;
  p.eta = 1.f;          // no Disney specular lobe: the clearcoat is the coat
  p.roughness = 0.f;    // no retro-reflection: pbrt-v4's base is Lambertian
  p.clearcoat = 4.f;    // weight 0.25 * 4 = 1: a real coat reflects its full Fresnel
  p.clearcoat_gloss = std::clamp((0.1f - alpha) / (0.1f - 0.001f), 0.f, 1.f);
  p.clearcoat_r0 = disney::schlick_r0_from_eta(eta);
  return p;
}

Object* create(const CreateContext& ctx) {
  const ParamSet& ps = ctx.params;
  TexturedRgb reflectance = ctx.rgb_input("reflectance");
  Rgb r = reflectance.is_constant() ? reflectance.constant() : Rgb(0.5f);
  if (!(glm::all(glm::greaterThanEqual(r, Rgb(0.f))) && glm::all(glm::lessThanEqual(r, Rgb(1.f)))))
    throw Error(ps.loc_of("reflectance"), "reflectance must be in [0, 1] (energy would not be conserved)");
  float eta = ps.get_float("eta");
  if (!(eta > 0.f && std::isfinite(eta))) throw Error(ps.loc_of("eta"), "eta must be positive");
  MicrofacetRoughness rough = microfacet_roughness(ctx);
  warning(ctx.loc, "coateddiffuse is approximated by Disney's diffuse + clearcoat");
  if (reflectance.is_constant() && rough.is_constant())
    return new disney::DisneyBsdf(coated_params(r, microfacet_alphas(ps), eta));
  auto params_at = [reflectance, rough, eta](const TextureEvalContext& tc) {
    TrowbridgeReitz d = rough.at(tc);
    return coated_params(glm::clamp(reflectance.evaluate(tc), Rgb(0.f), Rgb(1.f)), Vec2(d.alpha_x(), d.alpha_y()), eta);
  };
  // Diffuse and the glossy coat at every hit, whatever the textures give.
  return new disney::TexturedDisneyBsdf(params_at, disney::DisneyBsdf(coated_params(Rgb(0.5f), Vec2(0.f), eta)).flags());
}

}  // namespace

PENUMBRA_PLUGIN(Bsdf, "coateddiffuse", "diffuse base under a clear coat (approximated with Disney lobes)", kParams,
                create)
