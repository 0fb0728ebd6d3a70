// Light "infinite": radiance arriving from infinitely far away, either constant ("rgb L") or from an
// HDR image ("string filename", any float format OpenImageIO reads), oriented by the transform in
// effect at the LightSource directive.
//
// | parameter       | default | meaning                                                          |
// |-----------------|---------|------------------------------------------------------------------|
// | rgb L           | 1 1 1   | constant radiance (when there is no image)                       |
// | string filename | ""      | environment image                                                |
// | string mapping  | ""      | Penumbra: "equalarea" or "equirectangular"; empty: by the shape  |
// | float scale     | 1       | multiplies the radiance                                          |
//
// Mappings (libs/environment-map, light space z-up): a square image is pbrt-v4's equal-area
// octahedral map; an equirectangular one (u = phi / 2pi, v = theta / pi, row 0 is +z) is read only
// when "mapping" says so, or, for a 2:1 image without it, with a warning (pbrt-v4 refuses those).
// Radiance is constant over each texel, and the texels are importance sampled by a 2D piecewise-
// constant distribution over the image, so the pdf per solid angle is exact: pdf_uv / (4 pi) for the
// equal-area map (its texels all cover the same solid angle, the distribution is luminance alone),
// pdf_uv / (2 pi^2 sin theta) for the equirectangular one (distribution luminance x sin theta). The
// distribution is built only when the scene has an image-based environment. A constant sky seen
// from a surface (a receiving normal in the LightSampleContext) is sampled cosine-weighted about the
// normal: on both sides, or on the normal's side alone when the caller allows an incomplete density;
// without a normal (emission, media), uniformly over the sphere.
#include <penumbra/image.h>
#include <penumbra/light.h>
#include <penumbra/plugin.h>
#include <penumbra/sampling.h>

#include "environment_map.h"

#include <filesystem>

namespace {

using namespace penumbra;
using envmap::Mapping;

class InfiniteLight final : public Light {
 public:
  InfiniteLight(const Mat4& to_world, Rgb constant, ImageRgb image, Mapping mapping, float scale)
      : constant_(constant * scale), image_(std::move(image)), mapping_(mapping), scale_(scale) {
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
    std::optional<LightLiSample> ls;  // returned by name on every path (emplace_li_sample())
    // The target is outside the scene's bounding sphere, so a shadow ray tests all geometry.
    auto set = [&](const Rgb& L, const Vec3& wi, float pdf) {
      emplace_li_sample(ls, L, wi, pdf, ctx.p + wi * (2.f * radius_));
    };
    Vec3 w_light;
    float pdf;
    if (!has_image() && ctx.n != Vec3(0.f)) {
      // Constant radiance seen from a surface: cosine-weighted about the normal. On the normal's side
      // only when the caller MIS-combines with BSDF sampling (LightSampleContext), else on both
      // sides, each with probability 1/2 (the first coordinate picks the side).
      Vec3 n = ctx.n;
      if (!ctx.allow_incomplete_pdf) {
        bool below = u.x >= 0.5f;
        u.x = std::min(below ? 2.f * u.x - 1.f : 2.f * u.x, OneMinusEpsilon);
        if (below) n = -n;
      }
      Vec3 wi = Frame(n).to_world(sample_cosine_hemisphere(u));
      pdf = constant_pdf(ctx, wi);  // as pdf_li() computes it
      if (pdf > 0.f && !is_black(constant_)) set(constant_, wi, pdf);
      return ls;
    }
    if (!has_image()) {
      w_light = sample_uniform_sphere(u);
      pdf = uniform_sphere_pdf();
    } else {
      float pdf_uv;
      Vec2 uv = distribution_.sample_continuous(u, &pdf_uv);
      if (pdf_uv == 0.f) return ls;
      w_light = envmap::uv_to_direction(mapping_, uv);
      pdf = pdf_uv_to_solid_angle(pdf_uv, w_light);
    }
    Rgb L = radiance(w_light);
    if (is_black(L) || !(pdf > 0.f)) return ls;
    set(L, glm::normalize(to_world_ * w_light), pdf);
    return ls;
  }

  // A constant sky samples about the receiving normal; a map by its distribution alone.
  bool li_density_depends_on_receiver() const override { return !has_image(); }

  float pdf_li(const LightSampleContext& ctx, const Vec3& wi, const SurfaceInteraction&) const override {
    if (!has_image()) return constant_pdf(ctx, wi);
    Vec3 w = to_light_ * glm::normalize(wi);
    return pdf_uv_to_solid_angle(distribution_.pdf(envmap::direction_to_uv(mapping_, w)), w);
  }

  // A direction as sample_li() draws it, and an origin on a disk of the scene's radius perpendicular
  // to it, outside the scene's bounding sphere.
  std::optional<LightLeSample> sample_le(Vec2 u_pos, Vec2 u_dir) const override {
    std::optional<LightLeSample> le;  // the one object every path returns
    auto s = sample_li(LightSampleContext{center_}, u_dir);
    if (!s) return le;
    Vec2 d = sample_uniform_disk_concentric(u_pos);
    Frame f(s->wi);
    le.emplace();
    le->ray = Ray{center_ + radius_ * (s->wi + d.x * f.s + d.y * f.t), -s->wi};
    le->L = s->L;
    le->pdf_pos = 1.f / (Pi * radius_ * radius_);
    le->pdf_dir = s->pdf;
    return le;
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
  // sample_li()'s density for a constant sky: uniform over the sphere without a receiving normal,
  // else cosine-weighted about it, on its side only (allow_incomplete_pdf) or on both.
  static float constant_pdf(const LightSampleContext& ctx, const Vec3& wi) {
    if (ctx.n == Vec3(0.f)) return uniform_sphere_pdf();
    float cos = glm::dot(glm::normalize(wi), ctx.n);
    return ctx.allow_incomplete_pdf ? cosine_hemisphere_pdf(cos) : 0.5f * cosine_hemisphere_pdf(std::abs(cos));
  }

  // Equal-area texels all cover 4 pi / (w h) sr; equirectangular ones d(omega) = 2 pi^2 sin(theta) du dv.
  float pdf_uv_to_solid_angle(float pdf_uv, const Vec3& w_light) const {
    if (mapping_ == Mapping::EqualArea) return pdf_uv * Inv4Pi;
    float sin_theta = safe_sqrt(1.f - w_light.z * w_light.z);
    return sin_theta > 0.f ? pdf_uv / (2.f * Pi * Pi * sin_theta) : 0.f;
  }

  Rgb texel(int x, int y) const {
    const float* p = &image_.pixels[3 * (static_cast<size_t>(y) * image_.width + x)];
    return Rgb(p[0], p[1], p[2]) * scale_;
  }

  Rgb radiance(const Vec3& w_light) const {
    if (!has_image()) return constant_;
    return envmap::lookup_nearest(image_, envmap::direction_to_uv(mapping_, w_light)) * scale_;
  }

  // Texel weights proportional to luminance times solid angle (the equirectangular rows' sin theta at
  // the row centre), and the sphere mean of the radiance for power().
  void build_distribution() {
    std::vector<float> f(static_cast<size_t>(image_.width) * image_.height);
    for (int y = 0; y < image_.height; ++y) {
      float row_weight = mapping_ == Mapping::EqualArea ? 1.f : std::sin(Pi * (y + 0.5f) / image_.height);
      for (int x = 0; x < image_.width; ++x)
        f[static_cast<size_t>(y) * image_.width + x] = std::max(0.f, luminance(texel(x, y))) * row_weight;
    }
    distribution_ = Distribution2D(f, image_.width, image_.height);
    envmap::RgbD mean = envmap::sphere_mean(image_, mapping_);
    mean_radiance_ = Rgb(static_cast<float>(mean.r), static_cast<float>(mean.g), static_cast<float>(mean.b)) * scale_;
  }

  glm::mat3 to_world_{1.f}, to_light_{1.f};
  Rgb constant_;
  ImageRgb image_;
  Mapping mapping_;
  float scale_;
  Distribution2D distribution_;
  Rgb mean_radiance_{0.f};
  Vec3 center_{0.f};
  float radius_ = 1.f;
};

const ParamSpec kParams[] = {
    {"rgb", "L", "1 1 1", "constant radiance (used when there is no image)"},
    {"string", "filename", "", "environment image (.exr, .hdr, .pfm, ...): square = pbrt-v4's equal-area map"},
    {"string", "mapping", "", "Penumbra: \"equalarea\" or \"equirectangular\" (default: equal area for a square "
                              "image, equirectangular with a warning for a 2:1 one)"},
    {"float", "scale", "1", "multiplies the radiance"},
    {"float", "illuminance", "", "pbrt-v4's: scales the radiance so that the light-space upper hemisphere (+z) "
                                 "gives this illuminance on a surface facing +z"},
    {"unsupported", "portal", "", "portals are not supported"},
};

// Which mapping an image is read in: the scene's "mapping" if given, else pbrt-v4's rule (a square
// image is equal-area), else for a 2:1 image equirectangular with a warning; any other shape is an
// error, as in pbrt-v4.
Mapping choose_mapping(const CreateContext& ctx, const std::string& path, const ImageRgb& image) {
  std::string size = std::to_string(image.width) + "x" + std::to_string(image.height);
  if (ctx.params.has("mapping")) {
    std::string name = ctx.params.get_string("mapping");
    std::optional<Mapping> m = envmap::parse_mapping(name);
    if (!m) throw Error(ctx.params.loc_of("mapping"), "unknown mapping \"" + name + "\": expected \"equalarea\" or \"equirectangular\"");
    if (*m == Mapping::EqualArea && image.width != image.height)
      throw Error(ctx.params.loc_of("mapping"), "environment map " + path + " is " + size +
                                                    ": an equal-area map must be square");
    return *m;
  }
  std::optional<Mapping> m = envmap::mapping_from_shape(image.width, image.height);
  if (!m)
    throw Error(ctx.params.loc_of("filename"),
                "environment map " + path + " is " + size + ": neither square (pbrt-v4's equal-area map) nor 2:1; "
                "say \"string mapping\" \"equirectangular\" if it is a latitude-longitude image");
  if (*m == Mapping::Equirectangular)
    warning(ctx.params.loc_of("filename"),
            "environment map " + path + " is " + size + ", not square: read as equirectangular (latitude-longitude, "
            "+z at the top row), which pbrt-v4 would refuse. Say \"string mapping\" \"equirectangular\" to confirm, "
            "or convert it with `penumbra envmap --to equalarea`");
  return *m;
}

// Illuminance on a surface facing light-space +z: the sum over texels of luminance * cos(theta) *
// solid angle, for texels whose centre is above the horizon (as pbrt-v4 sums it).
double upper_hemisphere_illuminance(const ImageRgb& image, Mapping mapping) {
  double e = 0.0;
  for (int y = 0; y < image.height; ++y) {
    double omega = envmap::texel_solid_angle(mapping, image.width, image.height, y);
    for (int x = 0; x < image.width; ++x) {
      Vec3 w = envmap::uv_to_direction(mapping, Vec2((x + 0.5f) / image.width, (y + 0.5f) / image.height));
      if (w.z <= 0.f) continue;
      const float* t = &image.pixels[3 * (size_t(y) * image.width + x)];
      e += luminance(Rgb(t[0], t[1], t[2])) * w.z * omega;
    }
  }
  return e;
}

Object* create(const CreateContext& ctx) {
  float scale = ctx.params.get_float("scale");
  if (!(scale >= 0.f) || !std::isfinite(scale)) throw Error(ctx.params.loc_of("scale"), "scale must be finite and >= 0");
  std::string file = ctx.params.get_string("filename");
  ImageRgb image;
  Mapping mapping = Mapping::EqualArea;
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
    mapping = choose_mapping(ctx, p.string(), image);
  } else if (ctx.params.has("mapping")) {
    throw Error(ctx.params.loc_of("mapping"), "\"mapping\" applies to an image: give \"filename\" too");
  }
  Rgb L = ctx.params.get_rgb("L");
  if (!(L.r >= 0.f && L.g >= 0.f && L.b >= 0.f) || !is_finite(L))
    throw Error(ctx.params.loc_of("L"), "radiance must be finite and non-negative");
  if (ctx.params.has("illuminance")) {
    float target = ctx.params.get_float("illuminance");
    if (!(target > 0.f) || !std::isfinite(target))
      throw Error(ctx.params.loc_of("illuminance"), "illuminance must be finite and > 0");
    // pbrt-v4: a constant light's colour counts at luminance 1 (its hemisphere gives pi); an image
    // counts by the luminance its texels send onto a +z-facing surface.
    double k = file.empty() ? Pi : upper_hemisphere_illuminance(image, mapping);
    if (!(k > 0.0)) throw Error(ctx.params.loc_of("illuminance"), "the image sends no light from its upper hemisphere");
    scale *= static_cast<float>(target / k);
  }
  return new InfiniteLight(ctx.to_world, L, std::move(image), mapping, scale);
}

}  // namespace

PENUMBRA_PLUGIN(Light, "infinite", "environment light: constant or HDR image (equal-area or equirectangular), importance sampled",
                kParams, create)
