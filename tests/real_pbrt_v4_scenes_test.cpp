// The eight real pbrt-v4 scenes in scenes/pbrt-v4/ load unchanged and render with path, bdpt and
// sppm, in RGB and with spectral transport (as pbrt-v4 renders them), at low resolution: no error,
// no NaN or infinity in any sample, and light in the image.
// (How close they come to pbrt-v4's own renders is measured in docs/pbrt-v4-comparison.md.)
#include "render/render_session.h"
#include "support/image_stats.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <tuple>

using namespace penumbra;

namespace {

const char* const kScenes[] = {"coffee",     "cornell-box", "living-room", "material-testball",
                               "staircase2", "veach-bidir", "veach-mis",   "water-caustic"};
const char* const kIntegrators[] = {"path", "bdpt", "sppm"};
const char* const kTransports[] = {"rgb", "spectral"};

class RealPbrtV4Scene : public ::testing::TestWithParam<std::tuple<const char*, const char*, const char*>> {};

}  // namespace

TEST_P(RealPbrtV4Scene, RendersWithoutNonFiniteValues) {
  auto [scene, integrator, transport] = GetParam();
  std::string file = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/pbrt-v4/" + scene + "/scene-v4.pbrt";
  ASSERT_TRUE(std::filesystem::exists(file)) << file;
  RenderSettings s;
  s.scene_file = file;
  s.integrator = integrator;
  s.spp = 2;
  s.resolution = std::make_pair(32, 32);
  s.seed = 5;
  s.spectral = std::string(transport) == "spectral";
  s.quiet = true;
  RenderResult r = render(s);
  EXPECT_EQ(r.stats.nonfinite_samples, 0u);
  EXPECT_EQ(test::count_nonfinite(r.image), 0);
  EXPECT_GT(test::mean_luminance_free(r.image), 0.0) << "black image";
}

INSTANTIATE_TEST_SUITE_P(Scenes, RealPbrtV4Scene,
                         ::testing::Combine(::testing::ValuesIn(kScenes), ::testing::ValuesIn(kIntegrators),
                                            ::testing::ValuesIn(kTransports)),
                         [](const auto& info) {
                           std::string name = std::string(std::get<0>(info.param)) + "_" + std::get<1>(info.param) +
                                              "_" + std::get<2>(info.param);
                           for (char& c : name)
                             if (c == '-') c = '_';
                           return name;
                         });
