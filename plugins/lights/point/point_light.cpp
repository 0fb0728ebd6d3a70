// Light "point": an isotropic point source of intensity I (a delta light: sampled, never hit).
//
// | parameter    | default | meaning                                   |
// |--------------|---------|-------------------------------------------|
// | rgb I        | 1 1 1   | radiant intensity                         |
// | float scale  | 1       | multiplies I                              |
// | point3 from  | 0 0 0   | position (before the current transform)   |
#include <penumbra/light.h>
#include <penumbra/plugin.h>
#include <penumbra/sampling.h>

namespace {

using namespace penumbra;

class PointLight final : public Light {
 public:
  PointLight(Vec3 position, Rgb intensity) : p_(position), I_(intensity) {}
  LightType type() const override { return LightType::DeltaPosition; }
  Rgb power() const override { return 4.f * Pi * I_; }
  std::optional<LightLiSample> sample_li(const LightSampleContext& ctx, Vec2) const override {
    std::optional<LightLiSample> ls;  // returned by name on every path (emplace_li_sample())
    Vec3 d = p_ - ctx.p;
    float dist2 = glm::dot(d, d);
    if (dist2 == 0.f) return ls;  // a point light on the receiving point delivers nothing finite
    emplace_li_sample(ls, I_ / dist2, d / std::sqrt(dist2), 1.f, p_);
    return ls;
  }
  float pdf_li(const LightSampleContext&, const Vec3&, const SurfaceInteraction&) const override { return 0.f; }
  std::optional<LightLeSample> sample_le(Vec2, Vec2 u_dir) const override {
    return LightLeSample{Ray{p_, sample_uniform_sphere(u_dir)}, Vec3(0.f), I_, 1.f, uniform_sphere_pdf()};
  }
  void pdf_le(const Ray&, const Vec3&, float* pdf_pos, float* pdf_dir) const override {
    *pdf_pos = 0.f;  // a delta in position: no ray hits it
    *pdf_dir = uniform_sphere_pdf();
  }

 private:
  Vec3 p_;
  Rgb I_;
};

const ParamSpec kParams[] = {
    {"rgb", "I", "1 1 1", "radiant intensity"},
    {"float", "scale", "1", "multiplies I"},
    {"point3", "from", "0 0 0", "position"},
    {"float", "power", "", "pbrt-v4's: scales I by power / (4 pi) (the flux of I's colour at luminance 1)"},
};

Object* create(const CreateContext& ctx) {
  Rgb I = ctx.params.get_rgb("I") * ctx.params.get_float("scale");
  if (!(I.r >= 0.f && I.g >= 0.f && I.b >= 0.f) || !is_finite(I))
    throw Error(ctx.params.loc_of("I"), "intensity must be finite and non-negative");
  if (const ParamSet& p = ctx.params; p.has("power")) {
    float target = p.get_float("power");
  if (!(target > 0.f) || !std::isfinite(target)) throw Error(p.loc_of("power"), "power must be finite and > 0");
    I *= target / (4.f * Pi);
  }
  Vec3 from = Vec3(ctx.to_world * Vec4(ctx.params.get_point3("from"), 1.f));
  return new PointLight(from, I);
}

}  // namespace

PENUMBRA_PLUGIN(Light, "point", "isotropic point light", kParams, create)
