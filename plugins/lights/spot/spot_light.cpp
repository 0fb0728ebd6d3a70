// Light "spot": a point source emitting in a cone from `from` towards `to`, full intensity within
// coneangle - conedelta and falling off smoothly to zero at coneangle (pbrt-v4's smoothstep).
//
// | parameter        | default | meaning                                    |
// |------------------|---------|--------------------------------------------|
// | rgb I            | 1 1 1   | radiant intensity on the axis              |
// | float scale      | 1       | multiplies I                               |
// | point3 from      | 0 0 0   | position                                   |
// | point3 to        | 0 0 1   | a point on the axis                        |
// | float coneangle  | 30      | half angle of the cone, in degrees         |
// | float conedelta  | 5       | width of the falloff band, in degrees      |
#include <penumbra/light.h>
#include <penumbra/plugin.h>
#include <penumbra/sampling.h>

namespace {

using namespace penumbra;

float smooth_step(float x, float a, float b) {
  if (a == b) return x < a ? 0.f : 1.f;
  float t = std::clamp((x - a) / (b - a), 0.f, 1.f);
  return t * t * (3.f - 2.f * t);
}

class SpotLight final : public Light {
 public:
  SpotLight(Vec3 p, Vec3 axis, Rgb I, float cos_falloff_start, float cos_falloff_end)
      : p_(p), axis_(axis), I_(I), cos_start_(cos_falloff_start), cos_end_(cos_falloff_end) {}
  LightType type() const override { return LightType::DeltaPosition; }
  Rgb power() const override { return I_ * 2.f * Pi * ((1.f - cos_start_) + (cos_start_ - cos_end_) / 2.f); }
  std::optional<LightLiSample> sample_li(const LightSampleContext& ctx, Vec2) const override {
    Vec3 d = p_ - ctx.p;
    float dist2 = glm::dot(d, d);
    if (dist2 == 0.f) return std::nullopt;
    Vec3 wi = d / std::sqrt(dist2);
    float falloff = smooth_step(glm::dot(-wi, axis_), cos_end_, cos_start_);
    if (falloff == 0.f) return std::nullopt;
    return LightLiSample{I_ * falloff / dist2, wi, 1.f, p_, Vec3(0.f)};
  }
  float pdf_li(const LightSampleContext&, const Vec3&, const SurfaceInteraction&) const override { return 0.f; }
  // Directions uniform within the whole cone (falloff band included); the falloff weights L.
  std::optional<LightLeSample> sample_le(Vec2, Vec2 u_dir) const override {
    Vec3 w = Frame(axis_).to_world(sample_uniform_cone(u_dir, cos_end_));
    Rgb L = I_ * smooth_step(glm::dot(w, axis_), cos_end_, cos_start_);
    return LightLeSample{Ray{p_, w}, Vec3(0.f), L, 1.f, uniform_cone_pdf(cos_end_)};
  }
  void pdf_le(const Ray& ray, const Vec3&, float* pdf_pos, float* pdf_dir) const override {
    *pdf_pos = 0.f;
    *pdf_dir = glm::dot(glm::normalize(ray.d), axis_) >= cos_end_ ? uniform_cone_pdf(cos_end_) : 0.f;
  }

 private:
  Vec3 p_, axis_;
  Rgb I_;
  float cos_start_, cos_end_;
};

const ParamSpec kParams[] = {
    {"rgb", "I", "1 1 1", "radiant intensity on the axis"},
    {"float", "scale", "1", "multiplies I"},
    {"point3", "from", "0 0 0", "position"},
    {"point3", "to", "0 0 1", "a point on the cone's axis"},
    {"float", "coneangle", "30", "half angle of the cone in degrees"},
    {"float", "conedelta", "5", "width of the falloff band in degrees"},
    {"float", "power", "", "pbrt-v4's: scales I by power over the cone's solid angle (falloff counted half)"},
    {"unsupported", "illuminance", "", "give the intensity I instead"},
};

Object* create(const CreateContext& ctx) {
  const ParamSet& p = ctx.params;
  Rgb I = p.get_rgb("I") * p.get_float("scale");
  if (!(I.r >= 0.f && I.g >= 0.f && I.b >= 0.f) || !is_finite(I))
    throw Error(p.loc_of("I"), "intensity must be finite and non-negative");
  float cone = p.get_float("coneangle"), delta = p.get_float("conedelta");
  if (!(cone > 0.f && cone <= 180.f)) throw Error(p.loc_of("coneangle"), "coneangle must be in (0, 180]");
  if (!(delta >= 0.f && delta <= cone)) throw Error(p.loc_of("conedelta"), "conedelta must be in [0, coneangle]");
  float cos_start = std::cos(radians(cone - delta)), cos_end = std::cos(radians(cone));
  if (p.has("power")) {
    float target = p.get_float("power");
  if (!(target > 0.f) || !std::isfinite(target)) throw Error(p.loc_of("power"), "power must be finite and > 0");
    I *= target / (2.f * Pi * ((1.f - cos_start) + (cos_start - cos_end) / 2.f));
  }
  Vec3 from = Vec3(ctx.to_world * Vec4(p.get_point3("from"), 1.f));
  Vec3 to = Vec3(ctx.to_world * Vec4(p.get_point3("to"), 1.f));
  if (from == to) throw Error(ctx.loc, "spot light: \"from\" and \"to\" are the same point");
  return new SpotLight(from, glm::normalize(to - from), I, cos_start, cos_end);
}

}  // namespace

PENUMBRA_PLUGIN(Light, "spot", "spot light with a smooth falloff", kParams, create)
