// Light "infinite": radiance arriving from infinitely far away, either constant ("rgb L") or from an
// equirectangular HDR image ("string filename", any float format OpenImageIO reads), oriented by the
// transform in effect at the LightSource directive.
//
// | parameter       | default | meaning                                               |
// |-----------------|---------|-------------------------------------------------------|
// | rgb L           | 1 1 1   | constant radiance (when there is no image)            |
// | string filename | ""      | equirectangular environment map                       |
// | float scale     | 1       | multiplies the radiance                               |
//
// Mapping, in light space: u = phi / 2pi, v = theta / pi (row 0 is +z, theta = 0), with
// w = (sin theta cos phi, sin theta sin phi, cos theta). Radiance is constant over each texel, and the
// texels are importance sampled by a 2D piecewise-constant distribution of luminance x sin(theta), so
// the pdf per solid angle is pdf_uv / (2 pi^2 sin theta) exactly. The distribution is built only when
// the scene has an image-based environment.
#include <penumbra/image.h>
#include <penumbra/light.h>
#include <penumbra/plugin.h>
#include <penumbra/sampling.h>

#include <filesystem>

namespace {

using namespace penumbra;

class InfiniteLight final : public Light {
 public:
  InfiniteLight(const Mat4& to_world, Rgb constant, ImageRgb image, float scale)
      : constant_(constant * scale), image_(std::move(image)), scale_(scale) {
    glm::mat3 m(to_world);
    // Only the rotation matters for directions; remove any uniform scale.
    to_world_ = glm::mat3(glm::normalize(m[0]), glm::normalize(m[1]), glm::normalize(m[2]));
    to_light_ = glm::inverse(to_world_);
    if (has_image())
      build_distribution();
    else
      mean_radiance_ = constant_;
  }

  LightType type() const override { return LightType::Infinite; }

  void preprocess(const Vec3& center, float radius) override {
    center_ = center;
    radius_ = radius;
  }

  Rgb power() const override {
    // Flux through a disk of the scene's radius from all directions: pi r^2 times the integral of L
    // over the sphere (pbrt-v4's convention).
    return Pi * radius_ * radius_ * 4.f * Pi * mean_radiance_;
  }

  Rgb Le(const Ray& ray) const override { return radiance(to_light_ * glm::normalize(ray.d)); }

  std::optional<LightLiSample> sample_li(const LightSampleContext& ctx, Vec2 u) const override {
    Vec3 w_light;
    float pdf;
    if (!has_image()) {
      w_light = sample_uniform_sphere(u);
      pdf = uniform_sphere_pdf();
    } else {
      float pdf_uv;
      Vec2 uv = distribution_.sample_continuous(u, &pdf_uv);
      float theta = uv.y * Pi, phi = uv.x * 2.f * Pi;
      float sin_theta = std::sin(theta);
      if (pdf_uv == 0.f || sin_theta <= 0.f) return std::nullopt;
      w_light = Vec3(sin_theta * std::cos(phi), sin_theta * std::sin(phi), std::cos(theta));
      pdf = pdf_uv / (2.f * Pi * Pi * sin_theta);
    }
    Rgb L = radiance(w_light);
    if (is_black(L) || !(pdf > 0.f)) return std::nullopt;
    Vec3 wi = glm::normalize(to_world_ * w_light);
    // A target outside the scene's bounding sphere, so a shadow ray tests all geometry.
    return LightLiSample{L, wi, pdf, ctx.p + wi * (2.f * radius_), Vec3(0.f)};
  }

  float pdf_li(const LightSampleContext&, const Vec3& wi, const SurfaceInteraction&) const override {
    if (!has_image()) return uniform_sphere_pdf();
    Vec3 w = to_light_ * glm::normalize(wi);
    float cos_theta = std::clamp(w.z, -1.f, 1.f);
    float sin_theta = std::sqrt(std::max(0.f, 1.f - cos_theta * cos_theta));
    if (sin_theta <= 0.f) return 0.f;
    return distribution_.pdf(direction_to_uv(w)) / (2.f * Pi * Pi * sin_theta);
  }

  // A direction as sample_li() draws it, and an origin on a disk of the scene's radius perpendicular
  // to it, outside the scene's bounding sphere.
  std::optional<LightLeSample> sample_le(Vec2 u_pos, Vec2 u_dir) const override {
    auto s = sample_li(LightSampleContext{center_}, u_dir);
    if (!s) return std::nullopt;
    Vec2 d = sample_uniform_disk_concentric(u_pos);
    Frame f(s->wi);
    Vec3 origin = center_ + radius_ * (s->wi + d.x * f.s + d.y * f.t);
    return LightLeSample{Ray{origin, -s->wi}, Vec3(0.f), s->L, 1.f / (Pi * radius_ * radius_), s->pdf};
  }

  void pdf_le(const Ray& ray, const Vec3&, float* pdf_pos, float* pdf_dir) const override {
    SurfaceInteraction none;
    *pdf_pos = 1.f / (Pi * radius_ * radius_);
    *pdf_dir = pdf_li(LightSampleContext{center_}, -glm::normalize(ray.d), none);
  }

  std::vector<std::string> structures_built() const override {
    if (has_image()) return {"environment_distribution"};
    return {};
  }

 private:
  bool has_image() const { return image_.width > 0; }

  static Vec2 direction_to_uv(const Vec3& w) {
    float theta = std::acos(std::clamp(w.z, -1.f, 1.f));
    float phi = std::atan2(w.y, w.x);
    if (phi < 0.f) phi += 2.f * Pi;
    return Vec2(std::min(phi * Inv2Pi, OneMinusEpsilon), std::min(theta * InvPi, OneMinusEpsilon));
  }

  Rgb texel(int x, int y) const {
    const float* p = &image_.pixels[3 * (static_cast<size_t>(y) * image_.width + x)];
    return Rgb(p[0], p[1], p[2]) * scale_;
  }

  Rgb radiance(const Vec3& w_light) const {
    if (!has_image()) return constant_;
    Vec2 uv = direction_to_uv(w_light);
    int x = std::min(static_cast<int>(uv.x * image_.width), image_.width - 1);
    int y = std::min(static_cast<int>(uv.y * image_.height), image_.height - 1);
    return texel(x, y);
  }

  void build_distribution() {
    std::vector<float> f(static_cast<size_t>(image_.width) * image_.height);
    Rgb sum(0.f);
    double weight = 0.0;
    for (int y = 0; y < image_.height; ++y) {
      float sin_theta = std::sin(Pi * (y + 0.5f) / image_.height);
      for (int x = 0; x < image_.width; ++x) {
        Rgb L = texel(x, y);
        f[static_cast<size_t>(y) * image_.width + x] = std::max(0.f, luminance(L)) * sin_theta;
        sum += L * sin_theta;
        weight += sin_theta;
      }
    }
    distribution_ = Distribution2D(f, image_.width, image_.height);
    mean_radiance_ = sum / static_cast<float>(weight);
  }

  glm::mat3 to_world_{1.f}, to_light_{1.f};
  Rgb constant_;
  ImageRgb image_;
  float scale_;
  Distribution2D distribution_;
  Rgb mean_radiance_{0.f};
  Vec3 center_{0.f};
  float radius_ = 1.f;
};

const ParamSpec kParams[] = {
    {"rgb", "L", "1 1 1", "constant radiance (used when there is no image)"},
    {"string", "filename", "", "equirectangular environment map (.exr, .hdr, ...)"},
    {"float", "scale", "1", "multiplies the radiance"},
    {"unsupported", "illuminance", "", "give the radiance scale instead"},
    {"unsupported", "portal", "", "portals are not supported"},
};

Object* create(const CreateContext& ctx) {
  float scale = ctx.params.get_float("scale");
  if (!(scale >= 0.f) || !std::isfinite(scale)) throw Error(ctx.params.loc_of("scale"), "scale must be finite and >= 0");
  std::string file = ctx.params.get_string("filename");
  ImageRgb image;
  if (!file.empty()) {
    if (ctx.params.has("L")) throw Error(ctx.params.loc_of("L"), "give either \"L\" or \"filename\", not both");
    std::filesystem::path p(file);
    if (p.is_relative() && !ctx.scene_dir.empty()) p = std::filesystem::path(ctx.scene_dir) / p;
    try {
      image = read_image(p.string());
    } catch (const Error& e) {
      throw Error(ctx.params.loc_of("filename"), e.what());
    }
    if (image.width <= 0 || image.height <= 0) throw Error(ctx.params.loc_of("filename"), "environment map " + p.string() + " is empty");
    for (float v : image.pixels)
      if (!std::isfinite(v) || v < 0.f)
        throw Error(ctx.params.loc_of("filename"), "environment map " + p.string() + " has negative or non-finite texels");
  }
  Rgb L = ctx.params.get_rgb("L");
  if (!(L.r >= 0.f && L.g >= 0.f && L.b >= 0.f) || !is_finite(L))
    throw Error(ctx.params.loc_of("L"), "radiance must be finite and non-negative");
  return new InfiniteLight(ctx.to_world, L, std::move(image), scale);
}

}  // namespace

PENUMBRA_PLUGIN(Light, "infinite", "environment light: constant or equirectangular HDR image, importance sampled", kParams, create)
