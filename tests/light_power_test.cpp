// pbrt-v4's photometric light parameters: "power" on point, spot and area lights (the flux of the
// light's colour taken at luminance 1) and "illuminance" on distant and infinite lights (the
// irradiance on a surface facing the light, or light-space +z for an environment). Each is checked
// against a quantity the light computes another way: its power(), its incident radiance, or a Monte
// Carlo estimate of the irradiance from its own sampling.
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "scene/scene_builder.h"
#include "support/command.h"
#include "support/pcg32.h"

#include "image/image_io.h"

#include <penumbra/light.h>

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>

using namespace penumbra;
using namespace penumbra::test;

namespace {

BuiltScene build(const std::string& world, const std::string& name = "l.pbrt") {
  static Registry registry(Registry::default_search_dirs());
  SceneDescription d = parse_scene_string("WorldBegin\n" + world, name);
  return build_scene(d, registry);
}

double total_power_luminance(const BuiltScene& b) {
  double sum = 0.0;
  for (const auto& l : b.lights) sum += luminance(l->power());
  return sum;
}

// Irradiance at the origin on a surface facing +z, from the light's own sampling (4096 samples).
double estimated_irradiance(const Light& light) {
  Pcg32 rng(11);
  LightSampleContext ctx{Vec3(0.f), Vec3(0.f, 0.f, 1.f)};
  double sum = 0.0;
  const int n = 1 << 16;
  for (int i = 0; i < n; ++i) {
    auto s = light.sample_li(ctx, Vec2(rng.next_float(), rng.next_float()));
    if (!s || !(s->pdf > 0.f)) continue;
    sum += luminance(s->L) * std::max(0.f, s->wi.z) / s->pdf;
  }
  return sum / n;
}

}  // namespace

TEST(LightPower, PointAndSpotPowerIsTheirFlux) {
  EXPECT_NEAR(total_power_luminance(build("LightSource \"point\" \"float power\" [ 100 ]\n")), 100.0, 1e-3);
  EXPECT_NEAR(total_power_luminance(build("LightSource \"spot\" \"float power\" [ 50 ] \"float coneangle\" [ 40 ] "
                                          "\"float conedelta\" [ 10 ]\n")),
              50.0, 1e-3);
  // The colour keeps its hue; pbrt-v4 takes it at luminance 1, so a colour of luminance 0.5 gives half.
  double half = total_power_luminance(build("LightSource \"point\" \"rgb I\" [ 0.5 0.5 0.5 ] \"float power\" [ 100 ]\n"));
  EXPECT_NEAR(half, 50.0, 1e-3);
}

// An area light's power spreads over the whole shape: a mesh of two triangles of different areas, a
// sphere, and two-sided emission (which halves the radiance for the same power).
TEST(LightPower, AreaPowerCoversTheWholeShape) {
  const char* quad = "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  3 0 0  3 1 0  0 2 0 ] \"integer indices\" [ 0 1 2  0 2 3 ]\n";
  EXPECT_NEAR(total_power_luminance(build(std::string("AreaLightSource \"diffuse\" \"float power\" [ 20 ]\n") + quad)), 20.0, 1e-3);
  EXPECT_NEAR(total_power_luminance(build(std::string("AreaLightSource \"diffuse\" \"float power\" [ 20 ] "
                                                      "\"bool twosided\" [ true ]\n") + quad)),
              20.0, 1e-3);
  EXPECT_NEAR(total_power_luminance(build("AreaLightSource \"diffuse\" \"float power\" [ 7 ]\nShape \"sphere\" \"float radius\" [ 0.5 ]\n")),
              7.0, 1e-3);
  // Negative control: without power the quad's L = 1 gives pi * area (1.5 + 3).
  EXPECT_NEAR(total_power_luminance(build(std::string("AreaLightSource \"diffuse\"\n") + quad)), 4.5 * Pi, 1e-3);
}

TEST(LightPower, DistantAndInfiniteIlluminance) {
  BuiltScene distant = build("LightSource \"distant\" \"point3 from\" [ 0 0 1 ] \"point3 to\" [ 0 0 0 ] \"float illuminance\" [ 3 ]\n");
  EXPECT_NEAR(estimated_irradiance(*distant.lights[0]), 3.0, 1e-4);
  // A constant sky of radiance E / pi gives irradiance E.
  BuiltScene uniform = build("LightSource \"infinite\" \"float illuminance\" [ 2 ]\n");
  double e = luminance(uniform.lights[0]->Le(Ray{Vec3(0.f), Vec3(0.f, 0.f, 1.f)})) * Pi;

  // An image: a bright cap towards +x+z on a dim sky, 32 x 32 equal area.
  ImageRgb img;
  img.width = img.height = 32;
  img.pixels.assign(3 * 32 * 32, 0.1f);
  for (int y = 10; y < 14; ++y)
    for (int x = 20; x < 24; ++x)
      for (int c = 0; c < 3; ++c) img.pixels[3 * (y * 32 + x) + c] = 40.f;
  std::string dir = temp_dir("light-power-image");
  write_image(dir + "/sky.exr", img);
  BuiltScene image = build(fmt::format("LightSource \"infinite\" \"string filename\" \"{}/sky.exr\" \"float illuminance\" [ 20 ]\n", dir));
  double ei = estimated_irradiance(*image.lights[0]);
  std::printf("[ measured ] uniform %.4f (target 2), image %.4f (target 20)\n", e, ei);
  EXPECT_NEAR(e, 2.0, 1e-4);
  // The sum over texel centres and the light's exact texels differ by the texels the horizon cuts;
  // the estimate's own noise is below 0.5 %.
  EXPECT_NEAR(ei, 20.0, 0.4);
  BuiltScene unscaled = build(fmt::format("LightSource \"infinite\" \"string filename\" \"{}/sky.exr\"\n", dir));
  EXPECT_GT(std::abs(estimated_irradiance(*unscaled.lights[0]) - 20.0), 1.0);  // the scale did something
}

TEST(LightPower, NonPositiveValuesAreLocatedErrors) {
  for (const char* world : {"LightSource \"point\" \"float power\" [ 0 ]\n", "LightSource \"spot\" \"float power\" [ -1 ]\n",
                            "LightSource \"distant\" \"float illuminance\" [ 0 ]\n",
                            "AreaLightSource \"diffuse\" \"float power\" [ -2 ]\nShape \"sphere\"\n"}) {
    try {
      build(world);
      ADD_FAILURE() << world;
    } catch (const Error& err) {
      EXPECT_NE(err.formatted().find("l.pbrt:2:"), std::string::npos) << err.formatted();
    }
  }
}
