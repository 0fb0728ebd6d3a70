// Material "conductor" (BxDF in libs/bxdf/conductor_bxdf.h): metal reflection, a Trowbridge-Reitz (GGX) microfacet BRDF with the exact
// Fresnel equations of a complex index of refraction, f = D G F / (4 |cos_o cos_i|), sampled from
// the visible normals. Below alpha 1e-3 it is a perfect mirror (a delta lobe). Two-sided.
//
// | parameter          | default                    | meaning                                        |
// |--------------------|----------------------------|------------------------------------------------|
// | rgb eta            | 0.200438 0.924033 1.102212 | real part of the IOR per channel (copper)      |
// | rgb k              | 3.912949 2.452848 2.142188 | imaginary part (absorption) per channel        |
// | rgb reflectance    | (none)                     | if given, replaces eta/k: eta 1, k from R      |
// | float roughness    | 0                          | isotropic roughness                            |
// | float uroughness   | roughness                  | roughness along the shading frame's s axis     |
// | float vroughness   | roughness                  | roughness along the shading frame's t axis     |
// | bool remaproughness| true                       | alpha = sqrt(roughness) (else alpha = roughness)|
//
// pbrt-v4's defaults are the measured copper spectra "metal-Cu-eta"/"metal-Cu-k"; without spectral
// rendering we use their RGB reduction (the values pbrt-v4's own exporter writes, e.g. veach-mis).
// Every parameter but remaproughness may be a texture (eta, k, reflectance: spectrum textures;
// the roughnesses: float textures), as in pbrt-v4.
// "rgb reflectance" is pbrt-v4's artist-friendly mode: eta = 1 and k = 2 sqrt(R) / sqrt(1 - R),
// which makes the reflectance at normal incidence exactly R.
#include <bxdf_bsdf.h>
#include <conductor_bxdf.h>

#include <penumbra/bsdf.h>
#include <penumbra/microfacet.h>
#include <penumbra/plugin.h>

namespace {

using namespace penumbra;
using bxdf::BxdfBsdf;
using bxdf::ConductorBxdf;
using bxdf::k_from_reflectance;
using ConductorBsdf = BxdfBsdf<ConductorBxdf>;

// Textured parameters: each call evaluates them at the hit and forwards to a ConductorBsdf made on
// the stack (the constant material keeps its code and cost). Flags are the union over roughness.
class TexturedConductorBsdf final : public PerHitBsdf<TexturedConductorBsdf> {
  friend class PerHitBsdf<TexturedConductorBsdf>;

 public:
  TexturedConductorBsdf(MicrofacetRoughness r, TexturedRgb eta, TexturedRgb k, std::optional<TexturedRgb> reflectance)
      : r_(r), eta_(eta), k_(k), reflectance_(reflectance) {}
  uint32_t flags() const override { return BsdfReflection | BsdfGlossy | BsdfSpecular; }

 private:
  ConductorBsdf at(const ShadingContext& ctx) const {
    if (reflectance_) return ConductorBsdf(ConductorBxdf(r_.at(ctx.tex), Rgb(1.f), k_from_reflectance(reflectance_->evaluate(ctx.tex))));
    return ConductorBsdf(ConductorBxdf(r_.at(ctx.tex), glm::max(eta_.evaluate(ctx.tex), Rgb(1e-4f)),
                                       glm::max(k_.evaluate(ctx.tex), Rgb(0.f))));
  }
  MicrofacetRoughness r_;
  TexturedRgb eta_, k_;
  std::optional<TexturedRgb> reflectance_;
};

const ParamSpec kParams[] = {
    {"rgb texture", "eta", "0.200438 0.924033 1.102212", "real part of the IOR per channel (default: copper)"},
    {"rgb texture", "k", "3.912949 2.452848 2.142188", "absorption coefficient per channel (default: copper)"},
    {"rgb texture", "reflectance", "", "reflectance at normal incidence; replaces eta and k (eta = 1)"},
    {"float texture", "roughness", "0", "isotropic microfacet roughness (0: perfect mirror)"},
    {"float texture", "uroughness", "", "roughness along the shading frame's s axis (default: roughness)"},
    {"float texture", "vroughness", "", "roughness along the shading frame's t axis (default: roughness)"},
    {"bool", "remaproughness", "true", "alpha = sqrt(roughness) if true, else alpha = roughness"},
};

Object* create(const CreateContext& ctx) {
  const ParamSet& p = ctx.params;
  if (p.has("reflectance") && (p.has("eta") || p.has("k")))
    throw Error(p.loc_of("reflectance"), "give either reflectance or eta and k, not both");
  MicrofacetRoughness rough = microfacet_roughness(ctx);
  TexturedRgb eta_in = ctx.rgb_input("eta", RgbKind::Unbounded), k_in = ctx.rgb_input("k", RgbKind::Unbounded);
  std::optional<TexturedRgb> refl_in;
  if (p.has("reflectance")) refl_in = ctx.rgb_input("reflectance");
  if (!rough.is_constant() || !eta_in.is_constant() || !k_in.is_constant() || (refl_in && !refl_in->is_constant()))
    return new TexturedConductorBsdf(rough, eta_in, k_in, refl_in);
  Vec2 alpha = microfacet_alphas(p);
  float ur = alpha.x, vr = alpha.y;
  Rgb eta = p.get_rgb("eta"), k = p.get_rgb("k");
  if (p.has("reflectance")) {
    if (p.has("eta") || p.has("k"))
      throw Error(p.loc_of("reflectance"), "give either reflectance or eta and k, not both");
    Rgb r = p.get_rgb("reflectance");
    if (!(r.r >= 0.f && r.g >= 0.f && r.b >= 0.f && r.r <= 1.f && r.g <= 1.f && r.b <= 1.f))
      throw Error(p.loc_of("reflectance"), "reflectance must be in [0, 1]");
    eta = Rgb(1.f);
    k = k_from_reflectance(r);
  }
  if (!(eta.r > 0.f && eta.g > 0.f && eta.b > 0.f))
    throw Error(p.loc_of("eta"), "eta must be > 0 in every channel");
  if (!(k.r >= 0.f && k.g >= 0.f && k.b >= 0.f)) throw Error(p.loc_of("k"), "k must be >= 0 in every channel");
  if (ctx.spectral) return new TexturedConductorBsdf(rough, eta_in, k_in, refl_in);  // spectra per path
  return new ConductorBsdf(ConductorBxdf(TrowbridgeReitz(ur, vr), eta, k));
}

}  // namespace

PENUMBRA_PLUGIN(Bsdf, "conductor", "metal: rough or smooth GGX reflection with complex Fresnel", kParams, create)
