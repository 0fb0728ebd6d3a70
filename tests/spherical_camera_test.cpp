// pbrt-v4's spherical camera (core/src/scene/spherical_camera.h): equal-area pixels see equal solid
// angles (a blocker's share of the image is its solid angle over 4 pi), the map's pole is the
// camera's up (+y), equirectangular puts it on the top row, and errors are located.
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "render/render_session.h"
#include "scene/scene_builder.h"
#include "scene/spherical_camera.h"
#include "support/command.h"
#include "support/image_stats.h"

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace penumbra;
using namespace penumbra::test;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A camera at the origin looking along +z with +y up, inside a constant environment of radiance 1,
// with a black sphere of radius r at distance 2 along `where`.
ImageRgb render_blocked(const std::string& mapping, int w, int h, const char* where, float r, const std::string& name) {
  std::string scene = fmt::format(R"(LookAt 0 0 0  0 0 1  0 1 0
Camera "spherical" "string mapping" "{}"
Film "rgb" "integer xresolution" [ {} ] "integer yresolution" [ {} ]
PixelFilter "box"
Sampler "independent" "integer pixelsamples" [ 64 ]
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ]
Material "diffuse" "rgb reflectance" [ 0 0 0 ]
Translate {}
Shape "sphere" "float radius" [ {} ]
)",
                                  mapping, w, h, where, r);
  RenderSettings s;
  s.scene_file = write_file(temp_dir(name), "scene.pbrt", scene);
  s.quiet = true;
  s.seed = 3;
  return render(s).image;
}

}  // namespace

// The sphere of radius 1 at distance 2 subtends 2 pi (1 - cos 30 deg) = 0.8418 sr: the equal-area
// image mean is 1 - 0.8418 / (4 pi) = 0.93301 up to the pixels the silhouette crosses (64 samples
// each: measured within 1e-3). The equirectangular image of the same view weighs pixels, not solid
// angle, and is off by more than 10x the tolerance: the test tells the mappings apart.
TEST(SphericalCamera, EqualAreaPixelsSeeEqualSolidAngles) {
  const double expected = 1.0 - 2.0 * kPi * (1.0 - std::sqrt(3.0) / 2.0) / (4.0 * kPi);
  ImageRgb ea = render_blocked("equalarea", 64, 64, "0 0 2", 1.f, "sph-ea");
  ImageRgb er = render_blocked("equirectangular", 128, 64, "0 0 2", 1.f, "sph-er");
  double m_ea = mean_channel(ea, 1), m_er = mean_channel(er, 1);
  std::printf("[ measured ] equal area %.5f, equirectangular %.5f, expected %.5f\n", m_ea, m_er, expected);
  EXPECT_NEAR(m_ea, expected, 2e-3);
  EXPECT_GT(std::abs(m_er - expected), 2e-2);
  // The same blocker anywhere else casts the same share.
  EXPECT_NEAR(mean_channel(render_blocked("equalarea", 64, 64, "1.2 -0.9 1.3", 1.f, "sph-ea2"), 1), expected, 2e-3);
}

// The camera's up is the map's pole: the equal-area square's centre, the equirectangular top row.
TEST(SphericalCamera, UpIsThePole) {
  ImageRgb ea = render_blocked("equalarea", 32, 32, "0 2 0", 1.f, "sph-up-ea");
  auto at = [](const ImageRgb& img, int x, int y) { return img.pixels[3 * (y * img.width + x) + 1]; };
  EXPECT_EQ(at(ea, 16, 16), 0.f);
  EXPECT_EQ(at(ea, 0, 0), 1.f);
  EXPECT_EQ(at(ea, 31, 31), 1.f);
  ImageRgb er = render_blocked("equirectangular", 64, 32, "0 2 0", 1.f, "sph-up-er");
  for (int x = 0; x < 64; x += 7) {
    EXPECT_EQ(at(er, x, 0), 0.f) << x;
    EXPECT_EQ(at(er, x, 31), 1.f) << x;
  }
  // Forward (+z) in equirectangular: the middle row, at azimuth 90 degrees from camera +x (u = 1/4).
  ImageRgb fwd = render_blocked("equirectangular", 64, 32, "0 0 2", 0.5f, "sph-fwd");
  EXPECT_EQ(at(fwd, 16, 16), 0.f);
  EXPECT_EQ(at(fwd, 48, 16), 1.f);
}

TEST(SphericalCamera, ErrorsAreLocated) {
  Registry registry(Registry::default_search_dirs());
  auto error_of = [&](const std::string& camera, const std::string& film) -> std::string {
    try {
      SceneDescription d =
          parse_scene_string(camera + "\nFilm \"rgb\" " + film + "\nWorldBegin\nShape \"sphere\"\n", "c.pbrt");
      build_scene(d, registry);
    } catch (const Error& e) {
      return e.formatted();
    }
    return "";
  };
  std::string e = error_of("Camera \"spherical\"", "\"integer xresolution\" [ 64 ] \"integer yresolution\" [ 32 ]");
  EXPECT_NE(e.find("c.pbrt:1:1"), std::string::npos) << e;
  EXPECT_NE(e.find("square film"), std::string::npos) << e;
  e = error_of("Camera \"spherical\" \"string mapping\" \"cube\"", "");
  EXPECT_NE(e.find("c.pbrt:1:20"), std::string::npos) << e;
  e = error_of("Camera \"spherical\" \"float lensradius\" [ 0.1 ]", "");
  EXPECT_NE(e.find("c.pbrt:1:20"), std::string::npos) << e;
  EXPECT_EQ(error_of("Camera \"spherical\" \"string mapping\" \"equirectangular\"",
                     "\"integer xresolution\" [ 64 ] \"integer yresolution\" [ 32 ]"),
            "");
}
