// pbrt-v4's analytic render tests: the inside of a unit sphere with diffuse reflectance 0.5 seen from
// its centre, lit either by a point light of intensity pi at the centre (irradiance pi everywhere,
// so the reflected radiance of one bounce is 0.5) or by the sphere's own emission 0.5 towards the
// inside. Interreflection doubles it: the radiance is 0.5 / (1 - 0.5) = 1 in every direction. Every
// integrator and sampler, through the perspective and the orthographic camera.
#include "render/render_session.h"
#include "support/command.h"
#include "support/image_stats.h"

#include <fmt/core.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <tuple>

using namespace penumbra;
using namespace penumbra::test;

namespace {

struct Lighting {
  const char* name;
  const char* world;
};

const Lighting kPointLight = {"point", R"(LightSource "point" "rgb I" [ 3.14159265 3.14159265 3.14159265 ]
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "sphere" "float radius" 1)"};
const Lighting kEmission = {"emission", R"(AttributeBegin
ReverseOrientation
AreaLightSource "diffuse" "rgb L" [ 0.5 0.5 0.5 ]
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "sphere" "float radius" 1
AttributeEnd)"};

const char* camera_line(const std::string& camera) {
  // The orthographic window (camera units) stays well inside the sphere.
  return camera == "perspective" ? R"(Camera "perspective" "float fov" [ 90 ])"
                                 : R"(Camera "orthographic" "float screenwindow" [ -0.5 0.5 -0.5 0.5 ])";
}

// maxdepth 40 leaves 0.5^41 of the series out.
std::string scene(const std::string& camera, const std::string& integrator, const std::string& sampler,
                  const Lighting& light) {
  // The light tracer splats one light path per sample wherever it lands: 4x the samples for the
  // same noise.
  int spp = integrator == "lighttracing" ? 256 : 64;
  return fmt::format(R"(LookAt 0 0 0  0 0 1  0 1 0
{}
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 32 ]
PixelFilter "box"
Sampler "{}" "integer pixelsamples" [ {} ]
Integrator "{}" "integer maxdepth" [ 40 ]
WorldBegin
{}
)",
                     camera_line(camera), sampler, spp, integrator, light.world);
}

using Case = std::tuple<std::string, std::string, std::string, const Lighting*>;

class AnalyticSphere : public ::testing::TestWithParam<Case> {};

TEST_P(AnalyticSphere, RadianceIsOne) {
  auto [camera, integrator, sampler, light] = GetParam();
  std::string name = fmt::format("analytic-{}-{}-{}-{}", camera, integrator, sampler, light->name);
  RenderSettings s;
  s.scene_file = write_file(temp_dir(name), "scene.pbrt", scene(camera, integrator, sampler, *light));
  s.quiet = true;
  s.seed = 3;
  RenderResult r = render(s);
  ASSERT_EQ(count_nonfinite(r.image), 0);
  for (int c = 0; c < 3; ++c) {
    double mean = mean_channel(r.image, c), se = standard_error_of_mean(r.image, c);
    // 4 standard errors of the image mean (measured from the pixels' spread; fixed seed) plus
    // 0.2 % for SPPM's density-estimation bias at its final radius.
    double tol = 4.0 * se + (integrator == "sppm" ? 0.002 : 0.0);
    EXPECT_NEAR(mean, 1.0, tol) << name << " channel " << c << " (standard error " << se << ")";
    // Negative control: a 2 % error would be seen.
    EXPECT_LT(tol, 0.02) << name;
    if (c == 0) std::printf("%-48s mean %.4f +- %.4f\n", name.c_str(), mean, se);
  }
}

std::vector<Case> cases() {
  std::vector<Case> out;
  for (const char* camera : {"perspective", "orthographic"})
    for (const char* integrator : {"path", "bdpt", "lighttracing", "sppm"})
      for (const char* sampler : {"independent", "halton", "sobol"})
        for (const Lighting* light : {&kPointLight, &kEmission}) {
          // A light tracer connects every light vertex to the lens, which an orthographic camera
          // (one direction per film point) cannot receive: that combination is an error (below).
          if (std::string(camera) == "orthographic" && std::string(integrator) == "lighttracing") continue;
          out.emplace_back(camera, integrator, sampler, light);
        }
  return out;
}

INSTANTIATE_TEST_SUITE_P(AllIntegratorsSamplersCameras, AnalyticSphere, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           return std::get<0>(info.param) + "_" + std::get<1>(info.param) + "_" +
                                  std::get<2>(info.param) + "_" + std::get<3>(info.param)->name;
                         });

}  // namespace

namespace {

TEST(OrthographicCamera, LightTracingThroughItIsAnError) {
  RenderSettings s;
  s.scene_file = write_file(temp_dir("ortho-lighttracing"), "scene.pbrt",
                            scene("orthographic", "lighttracing", "independent", kEmission));
  s.quiet = true;
  try {
    render(s);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr("integrator 'lighttracing' connects every light vertex to the lens"));
  }
}

// The screen window maps the film onto camera-space x, y: a ray through raster (x, y) starts at
// (xmin + x / w (xmax - xmin), ymax - y / h (ymax - ymin), 0) and runs along +z.
TEST(OrthographicCamera, ScreenWindowAndFrameAspectRatio) {
  // Check the image of an emitting square of half-size 0.25 centred on the axis: with screenwindow [-0.5 0.5 -0.5 0.5]
  // it covers the middle quarter of the film (area fraction 0.25), with the default window of a
  // 2:1 film ([-2, 2] x [-1, 1]) 0.25 / 8 of it, and with frameaspectratio 1 on that film 0.25 / 4.
  auto covered = [](const std::string& camera, int w, int h) {
    std::string text = fmt::format(R"(LookAt 0 0 0  0 0 1  0 1 0
{}
Film "rgb" "integer xresolution" [ {} ] "integer yresolution" [ {} ]
PixelFilter "box"
Sampler "independent" "integer pixelsamples" [ 16 ]
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
AreaLightSource "diffuse" "rgb L" [ 1 1 1 ]
ReverseOrientation
Shape "trianglemesh" "point3 P" [ -0.25 -0.25 1  0.25 -0.25 1  0.25 0.25 1  -0.25 0.25 1 ] "integer indices" [ 0 1 2 0 2 3 ]
)",
                                   camera, w, h);
    RenderSettings s;
    s.scene_file = write_file(temp_dir("ortho-window"), "scene.pbrt", text);
    s.quiet = true;
    return mean_channel(render(s).image, 1);
  };
  EXPECT_NEAR(covered(R"(Camera "orthographic" "float screenwindow" [ -0.5 0.5 -0.5 0.5 ])", 32, 32), 0.25, 1e-3);
  EXPECT_NEAR(covered(R"(Camera "orthographic")", 64, 32), 0.25 / 8, 1e-3);
  EXPECT_NEAR(covered(R"(Camera "orthographic" "float frameaspectratio" 1)", 64, 32), 0.25 / 4, 1e-3);
  // The perspective camera shares the window rule: fov 90 puts z = 1 at the same scale.
  EXPECT_NEAR(covered(R"(Camera "perspective" "float fov" 90 "float screenwindow" [ -0.5 0.5 -0.5 0.5 ])", 32, 32), 0.25,
              1e-3);
}

TEST(OrthographicCamera, LensIsAnError) {
  RenderSettings s;
  s.scene_file = write_file(temp_dir("ortho-lens"), "scene.pbrt",
                            "Camera \"orthographic\" \"float lensradius\" 0.1\nWorldBegin\n");
  s.quiet = true;
  try {
    render(s);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_THAT(e.formatted(), ::testing::HasSubstr("scene.pbrt:1:23: error: parameter 'lensradius' of camera 'orthographic' is not supported by Penumbra"));
  }
}

}  // namespace
