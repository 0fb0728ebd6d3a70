// Material "coatedconductor" (pbrt-v4): a conductor base under a dielectric coat, with an optional
// scattering medium between them, evaluated by the stochastic layered BxDF of libs/bxdf
// (layered_bxdf.h; docs/materials.md). Two-sided. The base sees the coat's medium, so its IOR is
// taken relative to the coat: conductor eta and k are divided by interface.eta (as pbrt-v4 does).
//
// | parameter                  | default                    | meaning                                  |
// |----------------------------|----------------------------|------------------------------------------|
// | float interface.roughness  | 0                          | coat roughness (float texture or value)  |
// | float interface.uroughness | interface.roughness        | coat roughness along s                   |
// | float interface.vroughness | interface.roughness        | coat roughness along t                   |
// | float interface.eta        | 1.5                        | coat IOR (a spectrum: its luminance mean)|
// | rgb conductor.eta          | 0.200438 0.924033 1.102212 | base IOR, real part (copper)             |
// | rgb conductor.k            | 3.912949 2.452848 2.142188 | base IOR, imaginary part (copper)        |
// | rgb reflectance            | (none)                     | replaces conductor.eta/k: eta 1, k from R|
// | float conductor.roughness  | 0                          | base roughness                           |
// | float conductor.uroughness | conductor.roughness        | base roughness along s                   |
// | float conductor.vroughness | conductor.roughness        | base roughness along t                   |
// | bool remaproughness        | true                       | alpha = sqrt(roughness) for both layers  |
// | float thickness            | 0.01                       | slab thickness (unit extinction)         |
// | rgb albedo                 | 0 0 0                      | medium single-scattering albedo          |
// | float g                    | 0                          | medium Henyey-Greenstein asymmetry       |
// | integer maxdepth           | 10                         | most events of a walk                    |
// | integer nsamples           | 1                          | walks per f() and pdf() estimate         |
// Spectra ("spectrum conductor.eta" "metal-Au-eta") are reduced to RGB as for "conductor".
#include <bxdf_bsdf.h>
#include <layer_inputs.h>
#include <layered_bxdf.h>

#include <penumbra/bsdf.h>
#include <penumbra/plugin.h>

#include <optional>

namespace {

using namespace penumbra;
using namespace penumbra::bxdf;
using CoatedConductorBsdf = BxdfBsdf<CoatedConductorBxdf>;

struct Inputs {
  MicrofacetRoughness interface_rough, conductor_rough;
  float interface_eta = 1.5f;
  TexturedRgb eta, k;
  std::optional<TexturedRgb> reflectance;
  LayerInputs layer;

  bool is_constant() const {
    return interface_rough.is_constant() && conductor_rough.is_constant() && eta.is_constant() && k.is_constant() &&
           (!reflectance || reflectance->is_constant()) && layer.is_constant();
  }
  CoatedConductorBxdf at(const TextureEvalContext& tc) const {
    Rgb ce, ck;
    if (reflectance) {
      ce = Rgb(1.f);
      ck = k_from_reflectance(reflectance->evaluate(tc));
    } else {
      ce = glm::max(eta.evaluate(tc), Rgb(1e-4f));
      ck = glm::max(k.evaluate(tc), Rgb(0.f));
    }
    ce /= interface_eta;
    ck /= interface_eta;
    return CoatedConductorBxdf(DielectricBxdf(interface_eta, interface_rough.at(tc)),
                               ConductorBxdf(conductor_rough.at(tc), ce, ck), layer.at(tc));
  }
};

// Textured parameters: each call evaluates them at the hit and forwards to the layered BxDF made on
// the stack. Flags are the union over the parameters' range.
class TexturedCoatedConductorBsdf final : public PerHitBsdf<TexturedCoatedConductorBsdf> {
  friend class PerHitBsdf<TexturedCoatedConductorBsdf>;

 public:
  explicit TexturedCoatedConductorBsdf(Inputs in) : in_(std::move(in)) {}
  uint32_t flags() const override { return BsdfReflection | BsdfSpecular | BsdfGlossy | BsdfDiffuse; }

 private:
  CoatedConductorBsdf at(const ShadingContext& ctx) const { return CoatedConductorBsdf(in_.at(ctx.tex)); }
  Inputs in_;
};

const ParamSpec kParams[] = {
    {"float texture", "interface.roughness", "0", "coat roughness (0: smooth)"},
    {"float texture", "interface.uroughness", "", "coat roughness along s (default: interface.roughness)"},
    {"float texture", "interface.vroughness", "", "coat roughness along t (default: interface.roughness)"},
    {"float|spectrum", "interface.eta", "1.5", "coat index of refraction; a spectrum gives its luminance-weighted mean"},
    {"rgb texture", "conductor.eta", "0.200438 0.924033 1.102212", "base IOR, real part per channel (default: copper)"},
    {"rgb texture", "conductor.k", "3.912949 2.452848 2.142188", "base absorption per channel (default: copper)"},
    {"rgb texture", "reflectance", "", "base reflectance at normal incidence; replaces conductor.eta and conductor.k"},
    {"float texture", "conductor.roughness", "0", "base roughness (0: a mirror)"},
    {"float texture", "conductor.uroughness", "", "base roughness along s (default: conductor.roughness)"},
    {"float texture", "conductor.vroughness", "", "base roughness along t (default: conductor.roughness)"},
    {"bool", "remaproughness", "true", "alpha = sqrt(roughness) when true (both layers), alpha = roughness otherwise"},
    {"float texture", "thickness", "0.01", "thickness of the slab between coat and base (unit extinction)"},
    {"rgb texture", "albedo", "0 0 0", "single-scattering albedo of the medium in the slab (0: absorbing)"},
    {"float texture", "g", "0", "Henyey-Greenstein asymmetry of the medium"},
    {"integer", "maxdepth", "10", "most scattering events of a random walk through the layers"},
    {"integer", "nsamples", "1", "random walks averaged per f() and pdf() estimate"},
};

Object* create(const CreateContext& ctx) {
  const ParamSet& p = ctx.params;
  if (p.has("reflectance") && (p.has("conductor.eta") || p.has("conductor.k")))
    throw Error(p.loc_of("reflectance"), "give either reflectance or conductor.eta and conductor.k, not both");
  Inputs in;
  in.interface_rough = prefixed_roughness(ctx, "interface.");
  in.conductor_rough = prefixed_roughness(ctx, "conductor.");
  in.interface_eta = checked_eta(p, "interface.eta");
  in.eta = ctx.rgb_input("conductor.eta", RgbKind::Unbounded);
  in.k = ctx.rgb_input("conductor.k", RgbKind::Unbounded);
  if (p.has("reflectance")) {
    in.reflectance = ctx.rgb_input("reflectance");
    if (in.reflectance->is_constant()) {
      Rgb r = in.reflectance->constant();
      if (!(glm::all(glm::greaterThanEqual(r, Rgb(0.f))) && glm::all(glm::lessThanEqual(r, Rgb(1.f)))))
        throw Error(p.loc_of("reflectance"), "reflectance must be in [0, 1]");
    }
  }
  if (in.eta.is_constant() && !glm::all(glm::greaterThan(in.eta.constant(), Rgb(0.f))))
    throw Error(p.loc_of("conductor.eta"), "conductor.eta must be > 0 in every channel");
  if (in.k.is_constant() && !glm::all(glm::greaterThanEqual(in.k.constant(), Rgb(0.f))))
    throw Error(p.loc_of("conductor.k"), "conductor.k must be >= 0 in every channel");
  in.layer = layer_inputs(ctx);
  if (!in.is_constant() || ctx.spectral) return new TexturedCoatedConductorBsdf(std::move(in));
  return new CoatedConductorBsdf(in.at({}));
}

}  // namespace

PENUMBRA_PLUGIN(Bsdf, "coatedconductor", "conductor base under a dielectric coat (stochastic layered BxDF)",
                kParams, create)
