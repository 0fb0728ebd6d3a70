// Material "diffuse": Lambertian reflection, f = R / pi, sampled by the cosine-weighted hemisphere
// on the side of wo.
//
// | parameter       | default     | meaning                 |
// |-----------------|-------------|-------------------------|
// | rgb reflectance | 0.5 0.5 0.5 | albedo, each in [0, 1]; or a spectrum texture (clamped to [0, 1]) |
#include <penumbra/bsdf.h>
#include <penumbra/plugin.h>
#include <penumbra/sampling.h>

namespace {

using namespace penumbra;

class DiffuseBsdf final : public Bsdf {
 public:
  explicit DiffuseBsdf(Rgb r) : r_(r) {}
  uint32_t flags() const override { return is_black(r_) ? 0u : (BsdfReflection | BsdfDiffuse); }
  Rgb f(const Vec3& wo, const Vec3& wi, const ShadingContext&) const override {
    return same_hemisphere(wo, wi) ? r_ * InvPi : Rgb(0.f);
  }
  std::optional<BsdfSample> sample_f(const Vec3& wo, float, Vec2 u, const ShadingContext&) const override {
    if (wo.z == 0.f || is_black(r_)) return std::nullopt;
    Vec3 wi = sample_cosine_hemisphere(u);
    if (wo.z < 0.f) wi.z = -wi.z;
    float pdf = cosine_hemisphere_pdf(std::abs(wi.z));
    if (pdf == 0.f) return std::nullopt;
    return BsdfSample{r_ * InvPi, wi, pdf, BsdfReflection | BsdfDiffuse};
  }
  float pdf(const Vec3& wo, const Vec3& wi, const ShadingContext&) const override {
    return same_hemisphere(wo, wi) ? cosine_hemisphere_pdf(std::abs(wi.z)) : 0.f;
  }
  LobeSummary lobe(const Vec3& wo, const ShadingContext&) const override {
    LobeSummary l;
    l.peak = Vec3(0.f, 0.f, wo.z < 0.f ? -1.f : 1.f);
    l.coefficient = max_component(r_);
    l.cosine = true;
    return l;
  }

 private:
  Rgb r_;
};

// A textured reflectance: each call evaluates the texture and forwards to a DiffuseBsdf made on the
// stack, so the constant material above keeps its code and its cost.
class TexturedDiffuseBsdf final : public PerHitBsdf<TexturedDiffuseBsdf> {
  friend class PerHitBsdf<TexturedDiffuseBsdf>;

 public:
  explicit TexturedDiffuseBsdf(TexturedRgb r) : r_(r) {}
  uint32_t flags() const override { return BsdfReflection | BsdfDiffuse; }

 private:
  DiffuseBsdf at(const ShadingContext& ctx) const {
    return DiffuseBsdf(glm::clamp(r_.evaluate(ctx.tex), Rgb(0.f), Rgb(1.f)));
  }
  TexturedRgb r_;
};

const ParamSpec kParams[] = {
    {"rgb texture", "reflectance", "0.5 0.5 0.5", "albedo, each channel in [0, 1], or a spectrum texture"},
    {"unsupported", "displacement", "", "displacement is not supported"},
    {"unsupported", "normalmap", "", "normal maps are not supported yet"},
};

Object* create(const CreateContext& ctx) {
  TexturedRgb tex = ctx.rgb_input("reflectance");
  if (!tex.is_constant()) return new TexturedDiffuseBsdf(tex);
  Rgb r = tex.constant();
  if (!(r.r >= 0.f && r.g >= 0.f && r.b >= 0.f && r.r <= 1.f && r.g <= 1.f && r.b <= 1.f))
    throw Error(ctx.params.loc_of("reflectance"), "reflectance must be in [0, 1] (energy would not be conserved)");
  return new DiffuseBsdf(r);
}

}  // namespace

PENUMBRA_PLUGIN(Bsdf, "diffuse", "Lambertian reflection", kParams, create)
