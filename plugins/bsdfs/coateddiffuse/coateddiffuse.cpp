// Material "coateddiffuse" (pbrt-v4): a Lambertian base under a dielectric coat, with an optional
// scattering medium between them, evaluated by the stochastic layered BxDF of libs/bxdf
// (layered_bxdf.h; docs/materials.md): f() and pdf() are Monte Carlo estimates, sample_f() a random
// walk through the layers. Two-sided.
//
// | parameter            | default     | meaning                                                      |
// |----------------------|-------------|--------------------------------------------------------------|
// | rgb reflectance      | 0.5 0.5 0.5 | base albedo, each channel in [0, 1] (or a spectrum texture)  |
// | float roughness      | 0           | coat roughness (0: a smooth coat); a float texture or value  |
// | float uroughness     | roughness   | coat roughness along the shading frame's s axis              |
// | float vroughness     | roughness   | coat roughness along the shading frame's t axis              |
// | bool remaproughness  | true        | alpha = sqrt(roughness), else alpha = roughness              |
// | float thickness      | 0.01        | slab thickness in units of the medium's mean free path       |
// | float eta            | 1.5         | coat IOR (a spectrum gives its luminance-weighted mean)      |
// | rgb albedo           | 0 0 0       | single-scattering albedo of the medium (0: pure absorber)    |
// | float g              | 0           | Henyey-Greenstein asymmetry of the medium                    |
// | integer maxdepth     | 10          | most events of a walk                                        |
// | integer nsamples     | 1           | walks averaged per f() and pdf() estimate                    |
#include <bxdf_bsdf.h>
#include <layer_inputs.h>
#include <layered_bxdf.h>

#include <penumbra/bsdf.h>
#include <penumbra/plugin.h>

namespace {

using namespace penumbra;
using namespace penumbra::bxdf;
using CoatedDiffuseBsdf = BxdfBsdf<CoatedDiffuseBxdf>;

// Textured parameters: each call evaluates them at the hit and forwards to the layered BxDF made on
// the stack. Flags are the union over the parameters' range (smooth or rough coat).
class TexturedCoatedDiffuseBsdf final : public PerHitBsdf<TexturedCoatedDiffuseBsdf> {
  friend class PerHitBsdf<TexturedCoatedDiffuseBsdf>;

 public:
  TexturedCoatedDiffuseBsdf(TexturedRgb reflectance, MicrofacetRoughness rough, float eta, LayerInputs layer)
      : reflectance_(reflectance), rough_(rough), eta_(eta), layer_(layer) {}
  uint32_t flags() const override { return BsdfReflection | BsdfSpecular | BsdfDiffuse; }

 private:
  CoatedDiffuseBsdf at(const ShadingContext& ctx) const {
    return CoatedDiffuseBsdf(CoatedDiffuseBxdf(DielectricBxdf(eta_, rough_.at(ctx.tex)),
                                               DiffuseBxdf(glm::clamp(reflectance_.evaluate(ctx.tex), Rgb(0.f), Rgb(1.f))),
                                               layer_.at(ctx.tex)));
  }
  TexturedRgb reflectance_;
  MicrofacetRoughness rough_;
  float eta_;
  LayerInputs layer_;
};

const ParamSpec kParams[] = {
    {"rgb texture", "reflectance", "0.5 0.5 0.5", "base albedo, each channel in [0, 1]"},
    {"float texture", "roughness", "0", "coat roughness (0: smooth)"},
    {"float texture", "uroughness", "", "coat roughness along s (default: roughness)"},
    {"float texture", "vroughness", "", "coat roughness along t (default: roughness)"},
    {"bool", "remaproughness", "true", "alpha = sqrt(roughness) when true, alpha = roughness otherwise"},
    {"float texture", "thickness", "0.01", "thickness of the slab between coat and base (unit extinction)"},
    {"float|spectrum", "eta", "1.5", "coat index of refraction; a spectrum gives its luminance-weighted mean"},
    {"rgb texture", "albedo", "0 0 0", "single-scattering albedo of the medium in the slab (0: absorbing)"},
    {"float texture", "g", "0", "Henyey-Greenstein asymmetry of the medium"},
    {"integer", "maxdepth", "10", "most scattering events of a random walk through the layers"},
    {"integer", "nsamples", "1", "random walks averaged per f() and pdf() estimate"},
};

Object* create(const CreateContext& ctx) {
  const ParamSet& ps = ctx.params;
  TexturedRgb reflectance = ctx.rgb_input("reflectance");
  if (reflectance.is_constant()) {
    Rgb r = reflectance.constant();
    if (!(glm::all(glm::greaterThanEqual(r, Rgb(0.f))) && glm::all(glm::lessThanEqual(r, Rgb(1.f)))))
      throw Error(ps.loc_of("reflectance"), "reflectance must be in [0, 1] (energy would not be conserved)");
  }
  float eta = checked_eta(ps, "eta");
  MicrofacetRoughness rough = prefixed_roughness(ctx, "");
  LayerInputs layer = layer_inputs(ctx);
  if (!reflectance.is_constant() || !rough.is_constant() || !layer.is_constant() || ctx.spectral)
    return new TexturedCoatedDiffuseBsdf(reflectance, rough, eta, layer);
  return new CoatedDiffuseBsdf(CoatedDiffuseBxdf(DielectricBxdf(eta, rough.at({})), DiffuseBxdf(reflectance.constant()),
                                                 layer.at({})));
}

}  // namespace

PENUMBRA_PLUGIN(Bsdf, "coateddiffuse", "diffuse base under a dielectric coat (stochastic layered BxDF)", kParams,
                create)
