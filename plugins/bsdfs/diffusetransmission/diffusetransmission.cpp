// Material "diffusetransmission" (pbrt-v4's): Lambertian reflection R / pi on the side of wo and
// Lambertian transmission T / pi to the other side, for thin sheets (paper, leaves, lamp shades).
// Sampled like pbrt-v4: reflection with probability max(R) / (max(R) + max(T)), transmission
// otherwise, each by the cosine-weighted hemisphere on its side. Directional albedo: R + T.
//
// | parameter         | default        | meaning                                          |
// |-------------------|----------------|--------------------------------------------------|
// | rgb reflectance   | 0.25 0.25 0.25 | diffuse reflectance, or a spectrum texture       |
// | rgb transmittance | 0.25 0.25 0.25 | diffuse transmittance, or a spectrum texture     |
// | float scale       | 1              | multiplies both                                  |
//
// As in pbrt-v4, R + T above 1 is accepted (it adds energy); each of them must be in [0, 1] (textured
// values are clamped to it at each hit).
#include <penumbra/bsdf.h>
#include <penumbra/plugin.h>
#include <penumbra/sampling.h>

namespace {

using namespace penumbra;

class DiffuseTransmissionBsdf final : public Bsdf {
 public:
  DiffuseTransmissionBsdf(Rgb r, Rgb t) : r_(r), t_(t) {
    float pr = max_component(r_), pt = max_component(t_);
    p_reflect_ = pr + pt > 0.f ? pr / (pr + pt) : 0.f;
  }

  uint32_t flags() const override {
    uint32_t f = 0;
    if (!is_black(r_)) f |= BsdfReflection | BsdfDiffuse;
    if (!is_black(t_)) f |= BsdfTransmission | BsdfDiffuse;
    return f;
  }

  Rgb f(const Vec3& wo, const Vec3& wi, const ShadingContext&) const override {
    return (same_hemisphere(wo, wi) ? r_ : t_) * InvPi;
  }

  std::optional<BsdfSample> sample_f(const Vec3& wo, float uc, Vec2 u, const ShadingContext&) const override {
    if (wo.z == 0.f || flags() == 0u) return std::nullopt;
    Vec3 wi = sample_cosine_hemisphere(u);
    bool reflect = uc < p_reflect_;
    // Reflection stays on wo's side, transmission goes to the other.
    if ((wo.z < 0.f) == reflect) wi.z = -wi.z;
    float pdf = (reflect ? p_reflect_ : 1.f - p_reflect_) * cosine_hemisphere_pdf(std::abs(wi.z));
    if (pdf == 0.f) return std::nullopt;
    return BsdfSample{(reflect ? r_ : t_) * InvPi, wi, pdf,
                      (reflect ? BsdfReflection : BsdfTransmission) | BsdfDiffuse};
  }

  float pdf(const Vec3& wo, const Vec3& wi, const ShadingContext&) const override {
    float p = same_hemisphere(wo, wi) ? p_reflect_ : 1.f - p_reflect_;
    return p * cosine_hemisphere_pdf(std::abs(wi.z));
  }

  LobeSummary lobe(const Vec3& wo, const ShadingContext&) const override {
    // The stronger of the two cosine lobes, with the albedo of both.
    LobeSummary l;
    bool reflect = p_reflect_ >= 0.5f;
    l.peak = Vec3(0.f, 0.f, (wo.z < 0.f) == reflect ? -1.f : 1.f);
    l.coefficient = max_component(r_ + t_);
    l.cosine = true;
    return l;
  }

 private:
  Rgb r_, t_;
  float p_reflect_;
};

// Textured reflectance or transmittance: a DiffuseTransmissionBsdf made on the stack at each call.
class TexturedDiffuseTransmissionBsdf final : public PerHitBsdf<TexturedDiffuseTransmissionBsdf> {
  friend class PerHitBsdf<TexturedDiffuseTransmissionBsdf>;

 public:
  TexturedDiffuseTransmissionBsdf(TexturedRgb r, TexturedRgb t, float scale) : r_(r), t_(t), scale_(scale) {}
  uint32_t flags() const override { return BsdfReflection | BsdfTransmission | BsdfDiffuse; }

 private:
  DiffuseTransmissionBsdf at(const ShadingContext& ctx) const {
    auto value = [&](const TexturedRgb& tex) { return glm::clamp(scale_ * tex.evaluate(ctx.tex), Rgb(0.f), Rgb(1.f)); };
    return DiffuseTransmissionBsdf(value(r_), value(t_));
  }
  TexturedRgb r_, t_;
  float scale_;
};

const ParamSpec kParams[] = {
    {"rgb texture", "reflectance", "0.25 0.25 0.25", "diffuse reflectance, each channel in [0, 1], or a spectrum texture"},
    {"rgb texture", "transmittance", "0.25 0.25 0.25", "diffuse transmittance, each channel in [0, 1], or a spectrum texture"},
    {"float", "scale", "1", "scales reflectance and transmittance"},
};

Object* create(const CreateContext& ctx) {
  const ParamSet& p = ctx.params;
  float scale = p.get_float("scale");
  if (!(scale >= 0.f)) throw Error(p.loc_of("scale"), "scale must be >= 0");
  TexturedRgb r_tex = ctx.rgb_input("reflectance"), t_tex = ctx.rgb_input("transmittance");
  if (!r_tex.is_constant() || !t_tex.is_constant()) return new TexturedDiffuseTransmissionBsdf(r_tex, t_tex, scale);
  Rgb r = scale * r_tex.constant(), t = scale * t_tex.constant();
  auto in_unit = [](Rgb c) { return c.r >= 0.f && c.g >= 0.f && c.b >= 0.f && c.r <= 1.f && c.g <= 1.f && c.b <= 1.f; };
  if (!in_unit(r)) throw Error(p.loc_of("reflectance"), "scale * reflectance must be in [0, 1]");
  if (!in_unit(t)) throw Error(p.loc_of("transmittance"), "scale * transmittance must be in [0, 1]");
  if (ctx.spectral) return new TexturedDiffuseTransmissionBsdf(r_tex, t_tex, scale);  // spectra per path
  return new DiffuseTransmissionBsdf(r, t);
}

}  // namespace

PENUMBRA_PLUGIN(Bsdf, "diffusetransmission", "Lambertian reflection and transmission (thin sheets)", kParams, create)
