// Multilayer EXR output: every AOV is written under its documented channel names with the values a
// simple scene predicts, read back through OpenImageIO's own reader, with the header metadata.
#include "image/film_aovs.h"
#include "support/command.h"
#include "support/exr_channels.h"

#include <penumbra/version.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>

using namespace penumbra;
using ::testing::HasSubstr;

namespace {

// An emitting diffuse square (L = 1, reflectance 0.5 0.25 0.125, normal +z) in the plane z = 0,
// covering x >= 0 only, seen head-on from z = 5 through a 10 degree lens: half the pixels see the
// square and every sample there returns exactly 1, the other half see nothing.
const char* kPlaneScene = R"(
LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 10 ]
Film "rgb" "integer xresolution" [ 8 ] "integer yresolution" [ 8 ]
PixelFilter "box"
Sampler "independent" "integer pixelsamples" [ 16 ]
WorldBegin
AreaLightSource "diffuse" "rgb L" [ 1 1 1 ]
Material "diffuse" "rgb reflectance" [ 0.5 0.25 0.125 ]
Shape "trianglemesh" "point3 P" [ 0 -10 0  10 -10 0  10 10 0  0 10 0 ]
    "normal N" [ 0 0 1  0 0 1  0 0 1  0 0 1 ] "integer indices" [ 0 1 2  0 2 3 ]
)";

const std::vector<std::string> kAllChannels = {
    "R", "G", "B", "albedo.R", "albedo.G", "albedo.B", "normal.X", "normal.Y", "normal.Z", "depth.Z",
    "samples.count", "samples.weight", "variance.R", "variance.G", "variance.B", "nonfinite.count"};

// Distance from the camera to the plane along the ray through raster point (px, py).
double plane_depth(double px, double py) {
  double t = std::tan(5.0 * M_PI / 180.0);
  double sx = t * (2.0 * px / 8.0 - 1.0), sy = t * (2.0 * py / 8.0 - 1.0);
  return 5.0 * std::sqrt(1.0 + sx * sx + sy * sy);
}

}  // namespace

TEST(Aov, EveryLayerHasItsDocumentedNameAndTheValuesOfAnEmittingPlane) {
  std::string dir = test::temp_dir("aov-plane");
  std::string scene = test::write_file(dir, "plane.pbrt", kPlaneScene);
  test::CommandResult r = test::run_penumbra(
      {"render", scene, "-o", dir + "/out.exr", "--aov", "all", "--seed", "7", "--stats", dir + "/s.json", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  test::ExrChannels img = test::read_exr_channels(dir + "/out.exr");
  ASSERT_EQ(img.width, 8);
  for (const auto& name : kAllChannels) EXPECT_TRUE(img.has(name)) << name;
  EXPECT_EQ(img.names.size(), kAllChannels.size());

  int hits = 0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      SCOPED_TRACE(testing::Message() << "pixel " << x << "," << y);
      EXPECT_EQ(img.at("samples.count", x, y), 16.f);
      EXPECT_EQ(img.at("samples.weight", x, y), 16.f);  // box filter: weight 1 per sample
      EXPECT_EQ(img.at("nonfinite.count", x, y), 0.f);
      for (const char* c : {"variance.R", "variance.G", "variance.B"}) EXPECT_EQ(img.at(c, x, y), 0.f);
      float depth = img.at("depth.Z", x, y);
      if (std::isinf(depth)) {  // a pixel beside the square: black, no surface
        for (const char* c : {"R", "albedo.R", "normal.Z"}) EXPECT_EQ(img.at(c, x, y), 0.f) << c;
        continue;
      }
      ++hits;
      EXPECT_NEAR(img.at("R", x, y), 1.f, 1e-6);
      EXPECT_NEAR(img.at("albedo.R", x, y), 0.5f, 1e-5);
      EXPECT_NEAR(img.at("albedo.G", x, y), 0.25f, 1e-5);
      EXPECT_NEAR(img.at("albedo.B", x, y), 0.125f, 1e-5);
      EXPECT_NEAR(img.at("normal.X", x, y), 0.f, 1e-6);
      EXPECT_NEAR(img.at("normal.Y", x, y), 0.f, 1e-6);
      EXPECT_NEAR(img.at("normal.Z", x, y), 1.f, 1e-6);
      // The nearest hit of the pixel's samples lies between the pixel's nearest and farthest points.
      double cx = std::clamp(4.0, double(x), x + 1.0), cy = std::clamp(4.0, double(y), y + 1.0);
      double fx = std::abs(x - 4.0) > std::abs(x + 1 - 4.0) ? x : x + 1.0;
      double fy = std::abs(y - 4.0) > std::abs(y + 1 - 4.0) ? y : y + 1.0;
      EXPECT_GE(depth, plane_depth(cx, cy) * (1 - 1e-6));
      EXPECT_LE(depth, plane_depth(fx, fy) * (1 + 1e-6));
    }
  EXPECT_EQ(hits, 32);  // the square covers exactly half of the image

  EXPECT_EQ(img.meta.at("penumbra:version"), PENUMBRA_VERSION_STRING);
  EXPECT_EQ(img.meta.at("penumbra:integrator"), "path");
  EXPECT_EQ(img.meta.at("penumbra:sampler"), "independent");
  EXPECT_EQ(img.meta.at("penumbra:spp"), "16");
  EXPECT_EQ(img.meta.at("penumbra:spp_total"), "16");
  EXPECT_EQ(img.meta.at("penumbra:seed"), "7");
  EXPECT_EQ(img.meta.at("penumbra:sample_range"), "0-16");
  EXPECT_EQ(img.meta.at("penumbra:aovs"), "albedo,normal,depth,samples,variance,nonfinite");
  EXPECT_EQ(img.meta.at("penumbra:scene_hash").size(), 16u);
  auto stats = nlohmann::json::parse(test::read_file(dir + "/s.json"));
  EXPECT_EQ(stats["scene_hash"], img.meta.at("penumbra:scene_hash"));
}

TEST(Aov, SceneFileRequestsAovsAndTheHashIgnoresOutputChoices) {
  std::string dir = test::temp_dir("aov-scene");
  std::string text = kPlaneScene;
  text.replace(text.find("Film \"rgb\""), 10, "Film \"rgb\" \"string aovs\" [ \"depth\" \"samples\" ]");
  std::string scene = test::write_file(dir, "plane.pbrt", text);
  ASSERT_EQ(test::run_penumbra({"render", scene, "-o", dir + "/a.exr", "-q"}).exit_code, 0);
  test::ExrChannels a = test::read_exr_channels(dir + "/a.exr");
  EXPECT_EQ(a.names.size(), 6u);  // R G B depth.Z samples.count samples.weight
  EXPECT_TRUE(a.has("depth.Z") && a.has("samples.count"));
  EXPECT_FALSE(a.has("albedo.R"));

  // More AOVs on the command line and another output name: same scene, same hash.
  ASSERT_EQ(test::run_penumbra({"render", scene, "-o", dir + "/b.exr", "--aov", "normal", "-q"}).exit_code, 0);
  test::ExrChannels b = test::read_exr_channels(dir + "/b.exr");
  EXPECT_TRUE(b.has("normal.Z") && b.has("depth.Z"));
  EXPECT_EQ(a.meta.at("penumbra:scene_hash"), b.meta.at("penumbra:scene_hash"));
  // Another seed is another render.
  ASSERT_EQ(test::run_penumbra({"render", scene, "-o", dir + "/c.exr", "--seed", "3", "-q"}).exit_code, 0);
  EXPECT_NE(a.meta.at("penumbra:scene_hash"), test::read_exr_channels(dir + "/c.exr").meta.at("penumbra:scene_hash"));
}

TEST(Aov, NonfiniteLayerCountsDiscardedSamples) {
  std::string dir = test::temp_dir("aov-nan");
  std::string scene = test::write_file(dir, "plane.pbrt", kPlaneScene);
  test::CommandResult r = test::run_penumbra({"render", scene, "-o", dir + "/out.exr", "--integrator", "nan",
                                              "--aov", "nonfinite,samples", "--stats", dir + "/s.json", "-q"},
                                             std::string("PENUMBRA_PLUGIN_PATH=") + PENUMBRA_TEST_PLUGIN_DIR);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  test::ExrChannels img = test::read_exr_channels(dir + "/out.exr");
  double total = 0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      EXPECT_EQ(img.at("nonfinite.count", x, y) + img.at("samples.count", x, y), 16.f);
      total += img.at("nonfinite.count", x, y);
    }
  auto stats = nlohmann::json::parse(test::read_file(dir + "/s.json"));
  EXPECT_GT(total, 0);
  EXPECT_EQ(total, stats["nonfinite_samples"].get<double>());
}

TEST(Aov, UnknownNamesAndNonExrOutputsAreErrors) {
  std::string dir = test::temp_dir("aov-errors");
  std::string scene = test::write_file(dir, "plane.pbrt", kPlaneScene);
  test::CommandResult r = test::run_penumbra({"render", scene, "-o", dir + "/o.exr", "--aov", "albedo,dpeth", "-q"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("unknown AOV 'dpeth'; available: albedo, normal, depth, samples, variance, nonfinite, all"));
  r = test::run_penumbra({"render", scene, "-o", dir + "/o.png", "--aov", "depth", "-q"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("AOVs (depth) are written as EXR layers: the output '" + dir + "/o.png' must be .exr"));
}

TEST(FilmAovs, VarianceIsThatOfTheWeightedMean) {
  FilmAovs aovs(Point2i(1, 1), parse_aovs({"variance,samples"}));
  for (float v : {1.f, 2.f, 3.f, 4.f}) aovs.add_sample(0, Rgb(v, 2.f * v, 5.f), 1.f);
  std::vector<ImageLayer> layers = aovs.layers();
  ASSERT_EQ(layers.size(), 2u);
  EXPECT_EQ(layers[0].name, "samples");
  EXPECT_EQ(layers[0].pixels, (std::vector<float>{4.f, 4.f}));
  EXPECT_EQ(layers[1].name, "variance");
  // Sample variance 5/3 over 4 samples; doubling the values quadruples it; a constant has none.
  EXPECT_NEAR(layers[1].pixels[0], 5.0 / 12.0, 1e-6);
  EXPECT_NEAR(layers[1].pixels[1], 4 * 5.0 / 12.0, 1e-6);
  EXPECT_EQ(layers[1].pixels[2], 0.f);
}

// Every integrator renders through the core's loop, which fills the first-hit AOVs the same way for
// all of them: the plane's albedo, normal and depth where a pixel sees it, zeros elsewhere.
class AovEveryIntegrator : public ::testing::TestWithParam<std::string> {};

TEST_P(AovEveryIntegrator, FirstHitLayersHoldThePlanesValues) {
  std::string dir = test::temp_dir("aov-" + GetParam());
  std::string scene = test::write_file(dir, "plane.pbrt", kPlaneScene);
  test::CommandResult r = test::run_penumbra({"render", scene, "--integrator", GetParam(), "-o", dir + "/out.exr",
                                              "--aov", "albedo,normal,depth", "--seed", "3", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  test::ExrChannels img = test::read_exr_channels(dir + "/out.exr");
  int hits = 0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      SCOPED_TRACE(testing::Message() << "pixel " << x << "," << y);
      float depth = img.at("depth.Z", x, y);
      if (std::isinf(depth)) {
        for (const char* c : {"albedo.R", "normal.Z"}) EXPECT_EQ(img.at(c, x, y), 0.f) << c;
        continue;
      }
      ++hits;
      EXPECT_NEAR(img.at("albedo.R", x, y), 0.5f, 1e-5);
      EXPECT_NEAR(img.at("albedo.G", x, y), 0.25f, 1e-5);
      EXPECT_NEAR(img.at("albedo.B", x, y), 0.125f, 1e-5);
      EXPECT_NEAR(img.at("normal.Z", x, y), 1.f, 1e-6);
      EXPECT_GE(depth, 5.0 * (1 - 1e-6));
      EXPECT_LE(depth, plane_depth(0, 0) * (1 + 1e-6));
    }
  EXPECT_EQ(hits, 32);
}

INSTANTIATE_TEST_SUITE_P(Integrators, AovEveryIntegrator,
                         ::testing::Values("path", "bdpt", "lighttracing", "sppm"));
