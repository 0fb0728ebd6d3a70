// Light "distant": parallel light arriving from direction from - to, with radiance L (a delta in
// direction: sampled, never hit).
//
// | parameter    | default | meaning                                   |
// |--------------|---------|-------------------------------------------|
// | rgb L        | 1 1 1   | radiance                                  |
// | float scale  | 1       | multiplies L                              |
// | point3 from  | 0 0 0   | light travels from `from` ...             |
// | point3 to    | 0 0 1   | ... towards `to`                          |
#include <penumbra/light.h>
#include <penumbra/plugin.h>
#include <penumbra/sampling.h>

namespace {

using namespace penumbra;

class DistantLight final : public Light {
 public:
  DistantLight(Vec3 w_light, Rgb L) : w_(w_light), L_(L) {}
  LightType type() const override { return LightType::DeltaDirection; }
  void preprocess(const Vec3& center, float radius) override {
    center_ = center;
    radius_ = radius;
  }
  Rgb power() const override { return L_ * Pi * radius_ * radius_; }
  std::optional<LightLiSample> sample_li(const LightSampleContext& ctx, Vec2) const override {
    return LightLiSample{L_, w_, 1.f, ctx.p + w_ * (2.f * radius_), Vec3(0.f)};
  }
  float pdf_li(const LightSampleContext&, const Vec3&, const SurfaceInteraction&) const override { return 0.f; }
  // Parallel rays from a disk of the scene's radius, facing the scene, outside its bounding sphere.
  std::optional<LightLeSample> sample_le(Vec2 u_pos, Vec2) const override {
    Vec2 d = sample_uniform_disk_concentric(u_pos);
    Frame f(w_);
    Vec3 origin = center_ + radius_ * (w_ + d.x * f.s + d.y * f.t);
    return LightLeSample{Ray{origin, -w_}, Vec3(0.f), L_, 1.f / (Pi * radius_ * radius_), 1.f};
  }
  void pdf_le(const Ray&, const Vec3&, float* pdf_pos, float* pdf_dir) const override {
    *pdf_pos = 1.f / (Pi * radius_ * radius_);
    *pdf_dir = 0.f;  // a delta in direction
  }

 private:
  Vec3 w_;  // towards the light
  Vec3 center_{0.f};
  Rgb L_;
  float radius_ = 1.f;
};

const ParamSpec kParams[] = {
    {"rgb", "L", "1 1 1", "radiance"},
    {"float", "scale", "1", "multiplies L"},
    {"point3", "from", "0 0 0", "the light travels from this point ..."},
    {"point3", "to", "0 0 1", "... towards this one"},
    {"float", "illuminance", "", "pbrt-v4's: scales L by illuminance (the irradiance of L's colour at luminance 1)"},
};

Object* create(const CreateContext& ctx) {
  const ParamSet& p = ctx.params;
  Rgb L = p.get_rgb("L") * p.get_float("scale");
  if (!(L.r >= 0.f && L.g >= 0.f && L.b >= 0.f) || !is_finite(L))
    throw Error(p.loc_of("L"), "radiance must be finite and non-negative");
  if (p.has("illuminance")) {
    float target = p.get_float("illuminance");
  if (!(target > 0.f) || !std::isfinite(target)) throw Error(p.loc_of("illuminance"), "illuminance must be finite and > 0");
    L *= target;
  }
  Vec3 w = glm::mat3(ctx.to_world) * (p.get_point3("from") - p.get_point3("to"));
  if (glm::length(w) == 0.f) throw Error(ctx.loc, "distant light: \"from\" and \"to\" are the same point");
  return new DistantLight(glm::normalize(w), L);
}

}  // namespace

PENUMBRA_PLUGIN(Light, "distant", "directional light", kParams, create)
