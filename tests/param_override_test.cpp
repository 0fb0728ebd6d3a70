// Integrator parameter overrides from the command line, end to end through the real program:
// `penumbra render --param NAME=VALUE` (typed by the integrator's parameter table, applied after
// --integrator) and the `integrator/NAME=VALUE:sampler` configurations of `penumbra converge`.
// Only long-standing parameters (path's maxdepth, strategy, ...) are used here.
#include "image/image_io.h"
#include "support/command.h"
#include "support/image_stats.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

using namespace penumbra;
using ::testing::HasSubstr;
using ::testing::Not;

namespace {

const std::string kCornell = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt";

struct Rendered {
  test::CommandResult result;
  ImageRgb image;
  nlohmann::json stats;
};

// Renders the Cornell box at 24x24, 4 spp with `extra` options.
Rendered render_cornell(const std::string& name, std::vector<std::string> extra) {
  std::string dir = test::temp_dir(name);
  std::vector<std::string> args = {"render", kCornell, "-o", dir + "/out.exr", "--res", "24x24", "--spp", "4",
                                   "--stats", dir + "/s.json", "-q"};
  args.insert(args.end(), extra.begin(), extra.end());
  Rendered r;
  r.result = test::run_penumbra(args);
  if (r.result.exit_code == 0) {
    r.image = read_image(dir + "/out.exr");
    r.stats = nlohmann::json::parse(test::read_file(dir + "/s.json"));
  }
  return r;
}

double nonzero_fraction(const ImageRgb& img) {
  int n = 0;
  for (int i = 0; i < img.width * img.height; ++i)
    n += img.pixels[3 * i] > 0.f || img.pixels[3 * i + 1] > 0.f || img.pixels[3 * i + 2] > 0.f;
  return static_cast<double>(n) / (img.width * img.height);
}

// Runs `render --integrator path --param TEXT` on the Cornell box and expects exit 1 with `message`.
void expect_param_error(const std::string& text, const std::string& message) {
  auto r = test::run_penumbra({"render", kCornell, "--integrator", "path", "--param", text, "--res", "8x8",
                               "--spp", "1", "-q", "-o", test::temp_dir("param-error") + "/out.exr"});
  EXPECT_EQ(r.exit_code, 1) << text;
  EXPECT_THAT(r.err, HasSubstr(message)) << text;
  EXPECT_THAT(r.err, Not(HasSubstr("wrote "))) << text;  // nothing was rendered
}

}  // namespace

TEST(ParamOverride, MaxDepthZeroLeavesOnlyTheEmitter) {
  // The scene says maxdepth 8; --param maxdepth=0 leaves the directly visible light and nothing else.
  Rendered full = render_cornell("param-full", {"--integrator", "path"});
  Rendered direct = render_cornell("param-depth0", {"--integrator", "path", "--param", "maxdepth=0"});
  ASSERT_EQ(full.result.exit_code, 0) << full.result.err;
  ASSERT_EQ(direct.result.exit_code, 0) << direct.result.err;
  double mean_full = test::mean_luminance_free(full.image), mean_direct = test::mean_luminance_free(direct.image);
  EXPECT_GT(mean_direct, 0.0);                 // the light itself is seen
  EXPECT_LT(mean_direct, 0.7 * mean_full);     // but none of the light it sheds on the walls
  EXPECT_LT(nonzero_fraction(direct.image), 0.05);
  EXPECT_GT(nonzero_fraction(full.image), 0.5);
  // The stats record the override as given.
  EXPECT_EQ(direct.stats["integrator"], "path");
  EXPECT_EQ(direct.stats["integrator_params"]["maxdepth"], "0");
  EXPECT_TRUE(full.stats["integrator_params"].empty());
}

TEST(ParamOverride, AppliesAfterIntegratorOverrideWhateverTheOrder) {
  // "strategy" belongs to path only: given before --integrator path on a bdpt scene, it still applies
  // to path (overrides act on the final integrator), and a later value of a name replaces an earlier one.
  std::string dir = test::temp_dir("param-order");
  std::string scene = test::write_file(
      dir, "scene.pbrt",
      "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\n"
      "Film \"rgb\" \"integer xresolution\" [ 8 ] \"integer yresolution\" [ 8 ]\n"
      "Integrator \"bdpt\" \"integer maxdepth\" [ 3 ]\nWorldBegin\n");
  auto r = test::run_penumbra({"render", scene, "--param", "strategy=bsdf", "--param", "maxdepth=1", "--param",
                               "maxdepth=2", "--integrator", "path", "--spp", "1", "-q", "-o", dir + "/out.exr",
                               "--stats", dir + "/s.json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto stats = nlohmann::json::parse(test::read_file(dir + "/s.json"));
  EXPECT_EQ(stats["integrator"], "path");
  EXPECT_EQ(stats["integrator_params"]["strategy"], "bsdf");
  EXPECT_EQ(stats["integrator_params"]["maxdepth"], "2");
}

TEST(ParamOverride, FloatAndBoolParametersAreTyped) {
  std::string dir = test::temp_dir("param-types");
  auto r = test::run_penumbra({"render", kCornell, "--integrator", "sppm", "--param", "radius=0.05", "--param",
                               "alpha=0.5", "--res", "8x8", "--spp", "2", "-q", "-o", dir + "/out.exr"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  r = test::run_penumbra({"render", kCornell, "--integrator", "bdpt", "--param", "visualizeweights=false", "--res",
                          "8x8", "--spp", "1", "-q", "-o", dir + "/out2.exr"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  r = test::run_penumbra({"render", kCornell, "--integrator", "sppm", "--param", "radius=wide", "-q"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--param radius=wide: 'wide' is not a float"));
  r = test::run_penumbra({"render", kCornell, "--integrator", "bdpt", "--param", "visualizeweights=maybe", "-q"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--param visualizeweights=maybe: 'maybe' is not a bool (true or false)"));
}

TEST(ParamOverride, ErrorsNameTheOptionAndTheParameter) {
  expect_param_error("maxdepth=abc", "error: --param maxdepth=abc: 'abc' is not an integer");
  expect_param_error("maxdepth=2.5", "error: --param maxdepth=2.5: '2.5' is not an integer");
  expect_param_error("maxdepth=", "error: --param maxdepth=: '' is not an integer");
  expect_param_error("maxdeph=3", "error: --param maxdeph=3: unknown parameter 'maxdeph' for integrator 'path'; "
                                  "did you mean 'maxdepth'?");
  expect_param_error("nonsense=3", "error: --param nonsense=3: unknown parameter 'nonsense' for integrator 'path'; "
                                   "it takes: maxdepth, rrdepth");
  expect_param_error("maxdepth", "error: --param: expected NAME=VALUE (e.g. maxdepth=8), got 'maxdepth'");
  expect_param_error("=3", "error: --param: expected NAME=VALUE with a parameter name before '='");
  expect_param_error("regularize=true", "error: --param regularize=true: parameter 'regularize' of integrator "
                                        "'path' is not supported by Penumbra");
  // Values the type accepts but the integrator rejects name the option too, not a scene position.
  expect_param_error("maxdepth=-1", "error: --param maxdepth=-1: maxdepth must be >= 0");
  expect_param_error("strategy=guess", "error: --param strategy=guess: strategy 'guess' is not supported");
}

TEST(ParamOverride, ConvergeConfigurationsTakeOverridesAndKeepTheirNames) {
  std::string dir = test::temp_dir("converge-params");
  const std::string with_params = "path/maxdepth=1/strategy=bsdf:sobol";
  auto r = test::run_penumbra({"converge", kCornell, "--configs", "path:sobol," + with_params, "--make-reference",
                               "0.4", "--reference-config", "path/maxdepth=3:sobol", "--time", "0.2", "--runs", "1",
                               "--snapshots", "2", "--res", "12x12", "-o", dir});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::string csv = test::read_file(dir + "/results.csv");
  EXPECT_THAT(csv, HasSubstr("\n" + with_params + ",0,0,"));
  auto summary = nlohmann::json::parse(test::read_file(dir + "/summary.json"));
  ASSERT_TRUE(summary["configs"].contains(with_params));
  ASSERT_TRUE(summary["configs"].contains("path:sobol"));
  EXPECT_EQ(summary["configs"][with_params]["points"].size(), 2u);
  EXPECT_TRUE(summary["time_to_reach"]["seconds"].contains(with_params));
  // Direct light only plus one bounce is biased against the full reference: its error stays higher.
  EXPECT_GT(summary["configs"][with_params]["final_relmse"].get<double>(),
            summary["configs"]["path:sobol"]["final_relmse"].get<double>());
}

TEST(ParamOverride, ConvergeRejectsBadOverridesBeforeRendering) {
  auto converge = [](const std::string& configs, const std::string& ref_config) {
    std::vector<std::string> args = {"converge", kCornell, "--configs", configs, "--make-reference", "30",
                                     "-o", test::temp_dir("converge-bad")};
    if (!ref_config.empty()) args.insert(args.end(), {"--reference-config", ref_config});
    return test::run_penumbra(args);
  };
  // Each would otherwise spend 30 s on the reference first.
  auto r = converge("path:sobol,path/maxdepth=abc:sobol", "");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("error: --configs 'path/maxdepth=abc:sobol': maxdepth=abc: 'abc' is not an integer"));
  EXPECT_THAT(r.err, Not(HasSubstr("reference half")));
  r = converge("path/maxdepth:sobol", "");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("error: --configs 'path/maxdepth:sobol': expected NAME=VALUE"));
  r = converge("path/maxdeph=2", "");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("unknown parameter 'maxdeph' for integrator 'path'; did you mean 'maxdepth'?"));
  r = converge("path:sobol", "path/regularize=true:sobol");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("error: --reference-config 'path/regularize=true:sobol': regularize=true: parameter "
                               "'regularize' of integrator 'path' is not supported"));
  r = converge("path:sobol,path:sobol", "");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--configs: 'path:sobol' is given twice"));
}
