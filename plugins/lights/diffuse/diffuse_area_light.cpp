// Area light "diffuse": uniform radiance L leaving the front side of a triangle or sphere (both
// sides with twosided). Sampled through its shape's solid-angle sampling; samples where the shape's
// alpha cut-out removes the surface (Shape::present) emit nothing, as in pbrt-v4.
//
// | parameter     | default | meaning                                      |
// |---------------|---------|----------------------------------------------|
// | rgb L         | 1 1 1   | emitted radiance                             |
// | float scale   | 1       | multiplies L                                 |
// | bool twosided | false   | emit from both sides of the surface          |
#include <penumbra/light.h>
#include <penumbra/plugin.h>
#include <penumbra/sampling.h>

namespace {

using namespace penumbra;

class DiffuseAreaLight final : public Light {
 public:
  DiffuseAreaLight(const Shape* shape, Rgb L, bool twosided) : shape_(shape), L_(L), twosided_(twosided) {}
  LightType type() const override { return LightType::Area; }
  Rgb power() const override { return L_ * shape_->area() * Pi * (twosided_ ? 2.f : 1.f); }

  Rgb L(const Vec3&, const Vec3& n, const Vec2&, const Vec3& w) const override {
    if (!twosided_ && glm::dot(n, w) < 0.f) return Rgb(0.f);
    return L_;
  }

  std::optional<LightLiSample> sample_li(const LightSampleContext& ctx, Vec2 u) const override {
    std::optional<LightLiSample> ls;  // returned by name on every path (emplace_li_sample())
    // One-sided: a point behind a flat shape gets nothing from it, and the shape may skip sampling.
    std::optional<ShapeSample> ss = shape_->sample_solid_angle(ShapeSampleContext{ctx.p, ctx.n, !twosided_}, u);
    if (!ss || !(ss->pdf > 0.f) || !shape_->present(*ss)) return ls;
    if (ss->distance == 0.f) return ls;
    const Vec3& wi = ss->wi;  // the shape's, computed for the density
    Rgb Le = L(ss->p, ss->n, ss->uv, -wi);
    if (is_black(Le)) return ls;
    emplace_li_sample(ls, Le, wi, ss->pdf, ss->p, ss->n);
    return ls;
  }

  float pdf_li(const LightSampleContext& ctx, const Vec3& wi, const SurfaceInteraction& hit) const override {
    return shape_->pdf_solid_angle(ShapeSampleContext{ctx.p, ctx.n, !twosided_}, wi, hit.p, hit.ng);
  }

  // Emitted rays: a point uniform in area, a cosine-distributed direction on the emitting side (a
  // side chosen with probability 1/2 each when two-sided).
  std::optional<LightLeSample> sample_le(Vec2 u_pos, Vec2 u_dir) const override {
    ShapeSample ss = shape_->sample_area(u_pos);
    if (!shape_->present(ss)) return std::nullopt;  // cut out by the shape's alpha: no photon
    float side = 1.f;
    if (twosided_) {
      side = u_dir.x < 0.5f ? 1.f : -1.f;
      u_dir.x = std::min(u_dir.x < 0.5f ? 2.f * u_dir.x : 2.f * u_dir.x - 1.f, OneMinusEpsilon);
    }
    Vec3 w_local = sample_cosine_hemisphere(u_dir);
    float pdf_dir = cosine_hemisphere_pdf(w_local.z) * (twosided_ ? 0.5f : 1.f);
    if (!(pdf_dir > 0.f)) return std::nullopt;
    Vec3 w = Frame(ss.n).to_world(Vec3(w_local.x, w_local.y, side * w_local.z));
    return LightLeSample{spawn_ray(ss.p, ss.n, w), ss.n, L(ss.p, ss.n, ss.uv, w), ss.pdf, pdf_dir};
  }

  void pdf_le(const Ray& ray, const Vec3& n, float* pdf_pos, float* pdf_dir) const override {
    float c = glm::dot(n, glm::normalize(ray.d));
    *pdf_pos = 1.f / shape_->area();
    *pdf_dir = twosided_ ? 0.5f * std::abs(c) * InvPi : std::max(c, 0.f) * InvPi;
  }

 private:
  const Shape* shape_;
  Rgb L_;
  bool twosided_;
};

const ParamSpec kParams[] = {
    {"rgb", "L", "1 1 1", "emitted radiance"},
    {"float", "scale", "1", "multiplies L"},
    {"bool", "twosided", "false", "emit from both sides of the surface"},
    {"unsupported", "filename", "", "image-textured emitters are not supported"},
    {"float", "power", "", "pbrt-v4's: scales L by power / (pi area (2 if two-sided)) over the whole shape"},
};

Object* create(const CreateContext& ctx) {
  if (!ctx.shape) throw Error(ctx.loc, "light 'diffuse' must be used with AreaLightSource before a shape");
  Rgb L = ctx.params.get_rgb("L") * ctx.params.get_float("scale");
  if (!(L.r >= 0.f && L.g >= 0.f && L.b >= 0.f) || !is_finite(L))
    throw Error(ctx.params.loc_of("L"), "emitted radiance must be finite and non-negative");
  bool two_sided = ctx.params.get_bool("twosided");
  if (const ParamSet& p = ctx.params; p.has("power")) {
    float target = p.get_float("power");
  if (!(target > 0.f) || !std::isfinite(target)) throw Error(p.loc_of("power"), "power must be finite and > 0");
    float area = ctx.shape_area > 0.f ? ctx.shape_area : ctx.shape->area();
    if (area > 0.f) L *= target / (Pi * area * (two_sided ? 2.f : 1.f));
  }
  return new DiffuseAreaLight(ctx.shape, L, two_sided);
}

}  // namespace

PENUMBRA_PLUGIN(Light, "diffuse", "area light with uniform radiance", kParams, create)
