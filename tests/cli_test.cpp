// The command-line program end to end: renders of the bundled scenes with their stats, overrides,
// and every class of user error, each with its message, location and exit status 1.
#include "image/image_io.h"
#include "support/command.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <set>

using namespace penumbra;
using ::testing::HasSubstr;
using ::testing::Not;

namespace {

const std::string kSource = PENUMBRA_SOURCE_DIR;

// A valid minimal scene with `world` inserted after WorldBegin.
std::string scene_with(const std::string& options, const std::string& world) {
  return "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\n"
         "Film \"rgb\" \"integer xresolution\" [ 8 ] \"integer yresolution\" [ 8 ]\n" +
         options + "WorldBegin\n" + world;
}

test::CommandResult render_text(const std::string& name, const std::string& text,
                                std::vector<std::string> extra = {}) {
  std::string dir = test::temp_dir(name);
  std::string path = test::write_file(dir, "scene.pbrt", text);
  std::vector<std::string> args = {"render", path, "-o", dir + "/out.exr", "-q"};
  args.insert(args.end(), extra.begin(), extra.end());
  return test::run_penumbra(args);
}

}  // namespace

TEST(Cli, CornellBoxRendersAndStatsListExactlyTheNamedPlugins) {
  std::string dir = test::temp_dir("cornell");
  test::CommandResult r = test::run_penumbra({"render", kSource + "/scenes/cornell-box/scene.pbrt", "-o",
                                              dir + "/cb.exr", "--spp", "8", "--res", "32x32", "--stats",
                                              dir + "/s.json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto stats = nlohmann::json::parse(test::read_file(dir + "/s.json"));
  std::set<std::string> plugins(stats["plugins_loaded"].begin(), stats["plugins_loaded"].end());
  EXPECT_EQ(plugins, (std::set<std::string>{"integrator/path", "sampler/independent", "bsdf/diffuse", "light/diffuse"}));
  std::set<std::string> built(stats["structures_built"].begin(), stats["structures_built"].end());
  EXPECT_EQ(built, (std::set<std::string>{"embree_scene", "light_power_distribution"}));
  EXPECT_EQ(stats["spp"], 8);
  EXPECT_EQ(stats["pixels"], 32 * 32);
  EXPECT_EQ(stats["nonfinite_samples"], 0);
  EXPECT_GT(stats["rays"].get<double>(), 32 * 32 * 8);
  EXPECT_GT(stats["mrays_per_second"].get<double>(), 0.0);
  EXPECT_GT(stats["peak_memory_bytes"].get<double>(), 0.0);
  for (const char* key : {"seconds", "integrator", "sampler", "threads", "seed"}) EXPECT_TRUE(stats.contains(key)) << key;
  // Progress and a summary go to stderr.
  EXPECT_THAT(r.err, HasSubstr("wrote " + dir + "/cb.exr"));
}

TEST(Cli, RealPbrtCornellBoxLoadsUnchangedWithSamplerOverride) {
  std::string dir = test::temp_dir("pbrt-cornell");
  test::CommandResult r = test::run_penumbra({"render", kSource + "/scenes/pbrt-v4/cornell-box/scene-v4.pbrt", "-o",
                                              dir + "/cb.exr", "--sampler", "random", "--spp", "4", "--res",
                                              "24x24", "--stats", dir + "/s.json", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("warning: Accelerator"));  // accepted with a warning, not an error
  auto stats = nlohmann::json::parse(test::read_file(dir + "/s.json"));
  std::set<std::string> plugins(stats["plugins_loaded"].begin(), stats["plugins_loaded"].end());
  // The scene's "sobol" was never looked up: the override acts first.
  EXPECT_EQ(plugins, (std::set<std::string>{"integrator/path", "sampler/independent", "bsdf/diffuse", "light/diffuse"}));
}

TEST(Cli, RealPbrtVeachMisRendersUnchanged) {
  std::string dir = test::temp_dir("veach-mis");
  test::CommandResult r = test::run_penumbra({"render", kSource + "/scenes/pbrt-v4/veach-mis/scene-v4.pbrt", "-o",
                                              dir + "/v.exr", "--res", "32x18", "--spp", "2", "--stats", dir + "/s.json", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto stats = nlohmann::json::parse(test::read_file(dir + "/s.json"));
  std::set<std::string> plugins(stats["plugins_loaded"].begin(), stats["plugins_loaded"].end());
  EXPECT_EQ(plugins, (std::set<std::string>{"integrator/path", "sampler/sobol", "bsdf/diffuse", "bsdf/conductor", "light/diffuse"}));
  EXPECT_EQ(stats["nonfinite_samples"], 0);
}

TEST(Cli, RealPbrtCornellBoxRendersWithItsOwnSobolSampler) {
  std::string dir = test::temp_dir("pbrt-cornell-sobol");
  test::CommandResult r = test::run_penumbra({"render", kSource + "/scenes/pbrt-v4/cornell-box/scene-v4.pbrt", "-o",
                                              dir + "/cb.exr", "--res", "16x16", "-q"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST(Cli, NoArgumentsRendersBundledCornellBox) {
  // Run in a temp folder: the default scene writes its Film filename relative to the working dir.
  std::string dir = test::temp_dir("noargs");
  std::string cmd = "cd '" + dir + "' && '" + std::string(PENUMBRA_BINARY) + "' > out.txt 2> err.txt";
  // Full resolution takes a few seconds on 2 cores; the scene is 256x256 at 64 spp.
  ASSERT_EQ(std::system(cmd.c_str()), 0) << test::read_file(dir + "/err.txt");
  EXPECT_THAT(test::read_file(dir + "/err.txt"), HasSubstr("wrote cornell-box.png"));
}

TEST(Cli, UnknownParameterSuggestsTheNearestName) {
  auto r = render_text("maxdeph", scene_with("Integrator \"path\" \"integer maxdeph\" [ 3 ]\n", ""));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("scene.pbrt:4:19: error: unknown parameter 'maxdeph' for integrator 'path'; did you mean 'maxdepth'?"));
  EXPECT_THAT(r.err, HasSubstr("^"));  // the line is quoted with a caret
}

TEST(Cli, WrongParameterTypeIsLocated) {
  auto r = render_text("type", scene_with("Integrator \"path\" \"float maxdepth\" [ 3 ]\n", ""));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("scene.pbrt:4:19: error: parameter 'maxdepth' of integrator 'path' must have type 'integer', not 'float'"));
}

TEST(Cli, WrongValueCountIsLocated) {
  auto r = render_text("count", scene_with("", "Material \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 ]\n"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("scene.pbrt:5:20: error: parameter 'reflectance' of bsdf 'diffuse' takes 3 values, got 2"));
}

TEST(Cli, UnknownPluginListsAvailable) {
  auto r = render_text("plugin", scene_with("Integrator \"whitted\"\n", ""));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("scene.pbrt:4:1: error: unknown integrator 'whitted'; available: bdpt, lighttracing, path, sppm, volpath"));
}

TEST(Cli, MissingPlyFileIsLocated) {
  auto r = render_text("ply", scene_with("", "Shape \"plymesh\" \"string filename\" [ \"nope.ply\" ]\n"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("scene.pbrt:5:17: error: PLY file '"));
  EXPECT_THAT(r.err, HasSubstr("nope.ply"));
}

TEST(Cli, EmptyMeshIsAnError) {
  auto r = render_text("empty", scene_with("", "Shape \"trianglemesh\" \"point3 P\" [ ] \"integer indices\" [ ]\n"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("scene.pbrt:5:"));
  EXPECT_THAT(r.err, HasSubstr("error:"));
}

TEST(Cli, OutOfRangeIndexIsLocated) {
  auto r = render_text("index", scene_with("", "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"integer indices\" [ 0 1 3 ]\n"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("scene.pbrt:5:55: error: index 2 (value 3) is out of range: the mesh has 3 vertices"));
}

TEST(Cli, UndefinedNamedMaterialIsLocated) {
  auto r = render_text("named", scene_with("", "NamedMaterial \"gold\"\nShape \"sphere\"\n"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("scene.pbrt:5:1: error: named material 'gold' is not defined"));
}

TEST(Cli, UnsupportedShapeIsLocated) {
  auto r = render_text("heightfield", scene_with("", "Shape \"heightfield\"\n"));  // pbrt-v3's, gone from pbrt-v4
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("scene.pbrt:5:1: error: unsupported shape 'heightfield'; available: bilinearmesh, curve, cylinder, "
                               "disk, gltf, loopsubdiv, plymesh, sphere, trianglemesh"));
}

TEST(Cli, KnownButUnsupportedPbrtParameterSaysSo) {
  auto r = render_text("iso", "Film \"rgb\" \"float iso\" [ 100 ]\nWorldBegin\n");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("scene.pbrt:1:12: error: parameter 'iso' of film 'rgb' is not supported by Penumbra"));
}

TEST(Cli, BadCommandLineOptionsNameTheOption) {
  auto r = test::run_penumbra({"render", kSource + "/scenes/cornell-box/scene.pbrt", "--res", "big"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--res: expected WIDTHxHEIGHT"));
  r = test::run_penumbra({"render", kSource + "/scenes/cornell-box/scene.pbrt", "--spp", "-3"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--spp"));
  r = test::run_penumbra({"render", "/no/such/scene.pbrt"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("/no/such/scene.pbrt"));
  r = test::run_penumbra({"render", kSource + "/scenes/cornell-box/scene.pbrt", "--integrator", "nope", "-q"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("unknown integrator 'nope'; available: bdpt, lighttracing, path, sppm, volpath"));
}

// A diffuse sphere under a point light: nothing emits where the camera looks, so maxdepth 0 renders
// black and maxdepth 1 does not. --integrator bdpt over the scene's "path" keeps maxdepth (bdpt takes
// it) and drops what bdpt does not take, saying so.
TEST(Cli, IntegratorOverrideKeepsParametersTheNewPluginTakes) {
  const std::string world = "LightSource \"point\" \"point3 from\" [ 0 0 5 ] \"rgb I\" [ 10 10 10 ]\n"
                            "Material \"diffuse\"\nShape \"sphere\" \"float radius\" [ 1 ]\n";
  for (int depth : {0, 1}) {
    std::string dir = test::temp_dir("override-" + std::to_string(depth));
    std::string scene = test::write_file(
        dir, "scene.pbrt",
        scene_with(fmt::format("Integrator \"path\" \"integer maxdepth\" [ {} ] \"string strategy\" \"mis\"\n", depth),
                   world));
    auto r = test::run_penumbra({"render", scene, "-o", dir + "/out.exr", "--integrator", "bdpt", "--spp", "4", "-q"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_THAT(r.err, HasSubstr("parameter 'strategy' dropped: integrator 'bdpt' does not take it"));
    EXPECT_THAT(r.err, Not(HasSubstr("'maxdepth' dropped")));
    ImageRgb img = read_image(dir + "/out.exr");
    double sum = 0.0;
    for (float v : img.pixels) sum += v;
    if (depth == 0)
      EXPECT_EQ(sum, 0.0) << "maxdepth 0 was not carried over to bdpt";
    else
      EXPECT_GT(sum, 0.1) << "maxdepth 1 renders the lit sphere";
  }
}

TEST(Cli, NonFiniteSamplesAreDiscardedCountedAndReported) {
  std::string dir = test::temp_dir("nan");
  std::string scene = test::write_file(dir, "scene.pbrt", scene_with("Integrator \"nan\"\n", ""));
  auto r = test::run_penumbra({"render", scene, "-o", dir + "/out.exr", "--spp", "16", "--stats", dir + "/s.json", "-q"},
                              std::string("PENUMBRA_PLUGIN_PATH=") + PENUMBRA_TEST_PLUGIN_DIR);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto stats = nlohmann::json::parse(test::read_file(dir + "/s.json"));
  // 8x8 pixels x 16 spp = 1024 samples, about 20 % of them non-finite.
  int64_t n = stats["nonfinite_samples"];
  EXPECT_GT(n, 100);
  EXPECT_LT(n, 320);
  EXPECT_TRUE(stats["first_nonfinite_pixel"].is_array());
  EXPECT_THAT(r.err, HasSubstr(std::to_string(n) + " non-finite samples were discarded (first at pixel "));
  // Only finite samples of value 1 reached the film: every pixel is exactly 1.
  std::string dump = dir + "/out.exr";
  auto img = read_image(dump);
  for (float v : img.pixels) EXPECT_FLOAT_EQ(v, 1.f);
}
