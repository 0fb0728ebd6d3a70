// Material "dielectric": glass or water, an interface between two non-absorbing media (the BxDF is
// libs/bxdf/dielectric_bxdf.h, shared with the coated materials).
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
#include <bxdf_bsdf.h>
#include <dielectric_bxdf.h>

#include <penumbra/bsdf.h>
#include <penumbra/microfacet.h>
#include <penumbra/plugin.h>

namespace {

using namespace penumbra;
using bxdf::BxdfBsdf;
using bxdf::DielectricBxdf;

// Textured roughness: each call builds the distribution at the hit and forwards to a DielectricBxdf
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
  BxdfBsdf<DielectricBxdf> at(const ShadingContext& ctx) const {
    return BxdfBsdf<DielectricBxdf>(DielectricBxdf(eta_, r_.at(ctx.tex)));
  }
  float eta_;
  MicrofacetRoughness r_;
};

const ParamSpec kParams[] = {
    {"float|spectrum", "eta", "1.5", "index of refraction inside relative to outside; a spectrum gives its luminance-weighted mean (no dispersion)"},
    {"float texture", "roughness", "0", "isotropic microfacet roughness (0: smooth)"},
    {"float texture", "uroughness", "", "roughness along the shading frame's s axis (default: roughness)"},
    {"float texture", "vroughness", "", "roughness along the shading frame's t axis (default: roughness)"},
    {"bool", "remaproughness", "true", "alpha = sqrt(roughness) if true, else alpha = roughness"},
};

Object* create(const CreateContext& ctx) {
  const ParamSet& p = ctx.params;
  float eta = p.get_float("eta");
  if (!(eta > 0.f) || !std::isfinite(eta)) throw Error(p.loc_of("eta"), "eta must be a positive number");
  MicrofacetRoughness rough = microfacet_roughness(ctx);
  if (!rough.is_constant()) return new TexturedDielectricBsdf(eta, rough);
  Vec2 alpha = microfacet_alphas(p);
  float ur = alpha.x, vr = alpha.y;
  return new BxdfBsdf<DielectricBxdf>(DielectricBxdf(eta, TrowbridgeReitz(ur, vr)));
}

}  // namespace

PENUMBRA_PLUGIN(Bsdf, "dielectric", "glass and water: smooth or rough GGX reflection and refraction", kParams, create)
