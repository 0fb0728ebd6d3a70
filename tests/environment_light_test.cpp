// The environment light ("infinite"): analytic radiance under a constant sky, importance sampling of
// maps against the pdf by chi-square (a single very bright texel and a smooth map), the pdf
// integrating to one, and the distribution being built only when a scene has such a light.
#include "image/image_io.h"
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "render/render_session.h"
#include "support/chi_square.h"
#include "support/command.h"
#include "support/image_stats.h"

#include <penumbra/light.h>
#include <penumbra/rng.h>

#include <fmt/core.h>
#include <gtest/gtest.h>

using namespace penumbra;
using namespace penumbra::test;

namespace {

constexpr int kChiTests = 2;

std::unique_ptr<Light> make_env(const std::string& params_text, Registry& registry, const std::string& dir = "") {
  SceneDescription d = parse_scene_string("WorldBegin\nLightSource \"infinite\" " + params_text + "\n");
  SceneEntity& e = d.lights.at(0);
  auto light = registry.create<Light>(PluginKind::Light, "infinite", e.params,
                                      CreateContext{e.params, {}, dir, e.to_world}, e.loc);
  light->preprocess(Vec3(0.f), 1.f);
  return light;
}

std::string write_map(const std::string& dir, const std::string& name, int w, int h,
                      const std::function<Rgb(int, int)>& texel) {
  ImageRgb img;
  img.width = w;
  img.height = h;
  img.pixels.resize(3 * w * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Rgb c = texel(x, y);
      for (int k = 0; k < 3; ++k) img.pixels[3 * (y * w + x) + k] = c[k];
    }
  std::string path = dir + "/" + name;
  write_image(path, img);
  return path;
}

ChiSquareResult env_chi_square(const Light& light, int refinements, double z_min = -1.0) {
  LightSampleContext ctx{Vec3(0.f), Vec3(0.f)};
  SurfaceInteraction none;
  auto sample = [&](Vec2 u, float) -> std::optional<Vec3> {
    auto s = light.sample_li(ctx, u);
    if (!s) return std::nullopt;
    return s->wi;
  };
  auto pdf = [&](const Vec3& w) -> double { return light.pdf_li(ctx, w, none); };
  // The pdf is piecewise constant over texels that do not align with the histogram's cells, so the
  // expected counts need adaptive refinement: more levels where one texel holds most of the mass.
  SphereChart chart;
  chart.max_refinements = refinements;
  chart.z_min = z_min;
  return chi_square_sphere(sample, pdf, 500000, 32, 64, 99, chart);
}

}  // namespace

// A plane of albedo a under a constant sky L, seen from above, reflects a L exactly (it sees the whole
// upper hemisphere and nothing else). 16x16 pixels x 64 spp; tolerance 1 %.
TEST(EnvironmentLight, DiffusePlaneUnderConstantSkyRendersAlbedoTimesL) {
  std::string dir = temp_dir("env-plane");
  std::string scene = R"(
LookAt 0 1 0  0 0 0  0 0 1
Camera "perspective" "float fov" [ 30 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
PixelFilter "box"
Sampler "independent" "integer pixelsamples" [ 64 ]
Integrator "path" "integer maxdepth" [ 3 ]
WorldBegin
LightSource "infinite" "rgb L" [ 2 1 0.5 ]
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -1000 0 -1000  1000 0 -1000  1000 0 1000  -1000 0 1000 ] "integer indices" [ 0 1 2 0 2 3 ]
)";
  RenderSettings s;
  s.scene_file = write_file(dir, "scene.pbrt", scene);
  s.quiet = true;
  RenderResult r = render(s);
  EXPECT_NEAR(mean_channel(r.image, 0), 1.0, 0.01);
  EXPECT_NEAR(mean_channel(r.image, 1), 0.5, 0.005);
  EXPECT_NEAR(mean_channel(r.image, 2), 0.25, 0.0025);
  EXPECT_EQ(count_nonfinite(r.image), 0);
  // A constant sky needs no sampling distribution.
  EXPECT_EQ(std::count(r.stats.structures_built.begin(), r.stats.structures_built.end(), "environment_distribution"), 0);
}

TEST(EnvironmentLight, SingleBrightTexelSamplingMatchesPdfChiSquare) {
  std::string dir = temp_dir("env-bright");
  std::string map = write_map(dir, "bright.exr", 64, 32, [](int x, int y) {
    return (x == 40 && y == 1) ? Rgb(1e5f) : Rgb(0.01f, 0.02f, 0.03f);
  });
  Registry registry(Registry::default_search_dirs());
  auto light = make_env(fmt::format("\"string filename\" [ \"{}\" ]", map), registry);
  EXPECT_EQ(light->structures_built(), std::vector<std::string>{"environment_distribution"});
  // The bright texel (theta in [pi/32, pi/16]) lies in the cap z >= cos(0.2), which the histogram
  // zooms into; the rest of the sphere is one cell.
  ChiSquareResult r = env_chi_square(*light, 4, std::cos(0.2));
  EXPECT_TRUE(r.passes(sidak_alpha(0.01, kChiTests))) << r.summary();
  EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
}

TEST(EnvironmentLight, SmoothMapSamplingMatchesPdfChiSquare) {
  std::string dir = temp_dir("env-smooth");
  std::string map = write_map(dir, "smooth.exr", 64, 32, [](int x, int y) {
    float t = (y + 0.5f) / 32.f, s = (x + 0.5f) / 64.f;
    return Rgb(1.f + std::sin(6.28f * s) * 0.8f, 0.5f + t, 2.f - t);
  });
  Registry registry(Registry::default_search_dirs());
  auto light = make_env(fmt::format("\"string filename\" [ \"{}\" ] \"float scale\" [ 3 ]", map), registry);
  ChiSquareResult r = env_chi_square(*light, 2);
  EXPECT_TRUE(r.passes(sidak_alpha(0.01, kChiTests))) << r.summary();
  EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
}

TEST(EnvironmentLight, OneHotMapSamplesOnlyThatTexelAndConstantPdfIsUniform) {
  std::string dir = temp_dir("env-onehot");
  std::string map = write_map(dir, "onehot.exr", 32, 16, [](int x, int y) { return (x == 5 && y == 3) ? Rgb(7.f) : Rgb(0.f); });
  Registry registry(Registry::default_search_dirs());
  auto light = make_env(fmt::format("\"string filename\" [ \"{}\" ]", map), registry);
  Pcg32 rng(1, 1);
  for (int i = 0; i < 10000; ++i) {
    auto s = light->sample_li(LightSampleContext{Vec3(0.f)}, Vec2(rng.next_float(), rng.next_float()));
    ASSERT_TRUE(s);
    float theta = std::acos(s->wi.z), phi = std::atan2(s->wi.y, s->wi.x);
    if (phi < 0) phi += 2 * Pi;
    EXPECT_EQ(static_cast<int>(phi / (2 * Pi) * 32), 5);
    EXPECT_EQ(static_cast<int>(theta / Pi * 16), 3);
    EXPECT_FLOAT_EQ(s->L.g, 7.f);
  }
  auto constant = make_env("\"rgb L\" [ 1 1 1 ]", registry);
  SurfaceInteraction none;
  EXPECT_FLOAT_EQ(constant->pdf_li(LightSampleContext{Vec3(0.f)}, Vec3(0, 1, 0), none), Inv4Pi);
}

TEST(EnvironmentLight, MissingOrBrokenMapIsLocatedError) {
  std::string dir = temp_dir("env-missing");
  std::string scene = "Camera \"perspective\"\nWorldBegin\nLightSource \"infinite\" \"string filename\" [ \"nope.exr\" ]\n";
  auto r = run_penumbra({"render", write_file(dir, "scene.pbrt", scene), "-o", dir + "/o.exr", "-q"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("scene.pbrt:3:24: error:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nope.exr"), std::string::npos) << r.err;
  write_file(dir, "bad.exr", "this is not an image");
  scene = "Camera \"perspective\"\nWorldBegin\nLightSource \"infinite\" \"string filename\" [ \"bad.exr\" ]\n";
  r = run_penumbra({"render", write_file(dir, "scene2.pbrt", scene), "-o", dir + "/o.exr", "-q"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("bad.exr"), std::string::npos) << r.err;
}

TEST(EnvironmentLight, EnvironmentSceneRendersWithoutNonFiniteValues) {
  std::string dir = temp_dir("env-scene");
  auto r = run_penumbra({"render", std::string(PENUMBRA_SOURCE_DIR) + "/scenes/environment/scene.pbrt", "-o", dir + "/e.exr",
                         "--res", "40x25", "--spp", "8", "--stats", dir + "/s.json", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ImageRgb img = read_image(dir + "/e.exr");
  EXPECT_EQ(count_nonfinite(img), 0);
  EXPECT_NE(read_file(dir + "/s.json").find("environment_distribution"), std::string::npos);
}
