// Material "diffuse": Lambertian reflection, f = R / pi, sampled by the cosine-weighted hemisphere
// on the side of wo (libs/bxdf/diffuse_bxdf.h).
//
// | parameter       | default     | meaning                 |
// |-----------------|-------------|-------------------------|
// | rgb reflectance | 0.5 0.5 0.5 | albedo, each in [0, 1]; or a spectrum texture (clamped to [0, 1]) |
#include <bxdf_bsdf.h>
#include <diffuse_bxdf.h>

#include <penumbra/bsdf.h>
#include <penumbra/plugin.h>

namespace {

using namespace penumbra;
using DiffuseBsdf = bxdf::BxdfBsdf<bxdf::DiffuseBxdf>;

// A textured reflectance: each call evaluates the texture and forwards to a DiffuseBsdf made on the
// stack, so the constant material keeps its code and its cost.
class TexturedDiffuseBsdf final : public PerHitBsdf<TexturedDiffuseBsdf> {
  friend class PerHitBsdf<TexturedDiffuseBsdf>;

 public:
  explicit TexturedDiffuseBsdf(TexturedRgb r) : r_(r) {}
  uint32_t flags() const override { return BsdfReflection | BsdfDiffuse; }

 private:
  DiffuseBsdf at(const ShadingContext& ctx) const {
    return DiffuseBsdf(bxdf::DiffuseBxdf(glm::clamp(r_.evaluate(ctx.tex), Rgb(0.f), Rgb(1.f))));
  }
  TexturedRgb r_;
};

const ParamSpec kParams[] = {
    {"rgb texture", "reflectance", "0.5 0.5 0.5", "albedo, each channel in [0, 1], or a spectrum texture"},
};

Object* create(const CreateContext& ctx) {
  TexturedRgb tex = ctx.rgb_input("reflectance");
  if (!tex.is_constant()) return new TexturedDiffuseBsdf(tex);
  Rgb r = tex.constant();
  if (!(r.r >= 0.f && r.g >= 0.f && r.b >= 0.f && r.r <= 1.f && r.g <= 1.f && r.b <= 1.f))
    throw Error(ctx.params.loc_of("reflectance"), "reflectance must be in [0, 1] (energy would not be conserved)");
  if (ctx.spectral) return new TexturedDiffuseBsdf(tex);  // the spectrum at each path's wavelengths
  return new DiffuseBsdf(bxdf::DiffuseBxdf(r));
}

}  // namespace

PENUMBRA_PLUGIN(Bsdf, "diffuse", "Lambertian reflection", kParams, create)
