// Point, spot and distant lights against analytic irradiance on a diffuse plane: the radiance of a
// plane of albedo a is a/pi * E, with E = I cos(theta) / d^2 for point and spot lights and
// E = L cos(theta) for a distant light. The camera looks straight down through a 2-degree field of
// view at the spot below the light, where the irradiance varies by under 0.2 %.
#include "render/render_session.h"
#include "support/command.h"
#include "support/image_stats.h"

#include <fmt/core.h>
#include <gtest/gtest.h>

using namespace penumbra;
using namespace penumbra::test;

namespace {

RenderResult render_light(const std::string& name, const std::string& light, float look_x = 0.f) {
  std::string scene = fmt::format(R"(
LookAt {0} 2 0  {0} 0 0  0 0 1
Camera "perspective" "float fov" [ 2 ]
Film "rgb" "integer xresolution" [ 8 ] "integer yresolution" [ 8 ]
PixelFilter "box"
Sampler "independent" "integer pixelsamples" [ 4 ]
Integrator "path" "integer maxdepth" [ 2 ]
WorldBegin
{1}
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -100 0 -100  100 0 -100  100 0 100  -100 0 100 ] "integer indices" [ 0 1 2 0 2 3 ]
)",
                                  look_x, light);
  RenderSettings s;
  s.scene_file = write_file(temp_dir(name), "scene.pbrt", scene);
  s.quiet = true;
  return render(s);
}

constexpr double kAlbedoOverPi = 0.5 / 3.14159265358979;

}  // namespace

TEST(DeltaLights, PointLightGivesInverseSquareIrradiance) {
  RenderResult r = render_light("point", R"(LightSource "point" "rgb I" [ 3 2 1 ] "point3 from" [ 0 1 0 ])");
  EXPECT_NEAR(mean_channel(r.image, 0), kAlbedoOverPi * 3.0, 0.005 * kAlbedoOverPi * 3.0);
  EXPECT_NEAR(mean_channel(r.image, 2), kAlbedoOverPi * 1.0, 0.005 * kAlbedoOverPi);
  EXPECT_EQ(r.stats.nonfinite_samples, 0u);
}

TEST(DeltaLights, PointLightFollowsTheCurrentTransformAndScale) {
  RenderResult r = render_light("point-xf", R"(AttributeBegin
Translate 0 0.5 0
LightSource "point" "rgb I" [ 1 1 1 ] "float scale" [ 2 ] "point3 from" [ 0 1.5 0 ]
AttributeEnd)");
  // The light ends up at height 2: E = 2 / 4.
  EXPECT_NEAR(mean_channel(r.image, 1), kAlbedoOverPi * 0.5, 0.005 * kAlbedoOverPi * 0.5);
}

TEST(DeltaLights, SpotLightIsFullInsideAndDarkOutsideItsCone) {
  const char* spot = R"(LightSource "spot" "rgb I" [ 4 4 4 ] "point3 from" [ 0 1 0 ] "point3 to" [ 0 0 0 ] "float coneangle" [ 20 ] "float conedelta" [ 5 ])";
  RenderResult inside = render_light("spot-in", spot);
  EXPECT_NEAR(mean_channel(inside.image, 0), kAlbedoOverPi * 4.0, 0.005 * kAlbedoOverPi * 4.0);
  // At x = 0.7 the direction is 35 degrees off the axis: beyond the 20-degree cone.
  RenderResult outside = render_light("spot-out", spot, 0.7f);
  EXPECT_EQ(mean_channel(outside.image, 0), 0.0);
}

TEST(DeltaLights, DistantLightGivesLTimesCosine) {
  // Light arriving 60 degrees from the normal: E = L cos 60 = L / 2.
  RenderResult r = render_light("distant", R"(LightSource "distant" "rgb L" [ 2 2 2 ] "point3 from" [ 0.8660254 0.5 0 ] "point3 to" [ 0 0 0 ])");
  EXPECT_NEAR(mean_channel(r.image, 1), kAlbedoOverPi * 1.0, 0.005 * kAlbedoOverPi);
}

TEST(DeltaLights, PointLightTouchingTheSurfaceStaysFinite) {
  RenderResult r = render_light("touching", R"(LightSource "point" "rgb I" [ 1 1 1 ] "point3 from" [ 0 0 0 ])");
  EXPECT_EQ(count_nonfinite(r.image), 0);
  EXPECT_EQ(r.stats.nonfinite_samples, 0u);
}
