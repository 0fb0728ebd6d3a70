// scenes/surface-detail/ against pbrt-v4 renders of the same files, made with
//   pbrt --nthreads 2 --spp 1024 --outfile ref.exr scenes/surface-detail/<name>.pbrt
// and reduced to their channel means (oiiotool --printstats).
#include "render/render_session.h"
#include "support/command.h"
#include "support/image_stats.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

using namespace penumbra;

namespace {

std::string scene_path(const std::string& name) {
  return std::string(PENUMBRA_SOURCE_DIR) + "/scenes/surface-detail/" + name + ".pbrt";
}

ImageRgb render_file(const std::string& file, const std::string& out) {
  RenderSettings s;
  s.scene_file = file;
  s.output = out;
  s.quiet = true;
  s.seed = 1;
  return render(s).image;
}

}  // namespace

// A sphere bumped by d = 2 u: pbrt-v4's mean is 12.5 % below the unbumped sphere's, so the mean checks
// the bump's direction and size. At 64 spp (the file's) Penumbra measured 0.9978 / 0.9992 / 0.9972 of
// pbrt-v4's mean with seeds 1, 2 and 3 (0.9993 at 1024 spp). Tolerance 1 %; the same file without the
// displacement is 14 % off and fails it.
TEST(SurfaceDetailScene, BumpedSphereMatchesPbrtV4) {
  const double pbrt_mean = 0.097923;  // mean of its three channels
  ImageRgb img = render_file(scene_path("bump-ramp"), test::temp_dir("bump-ramp") + "/bump-ramp.exr");
  EXPECT_EQ(test::count_nonfinite(img), 0);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(test::mean_channel(img, c) / pbrt_mean, 1.0, 0.01);
  std::ifstream in(scene_path("bump-ramp"));
  std::stringstream text;
  text << in.rdbuf();
  std::string flat = text.str();
  flat.replace(flat.find("\"texture displacement\" \"ramp\""), 29, "");
  std::string dir = test::temp_dir("bump-ramp-control");
  ImageRgb control = render_file(test::write_file(dir, "flat.pbrt", flat), dir + "/flat.exr");
  EXPECT_GT(std::abs(test::mean_channel(control, 0) / pbrt_mean - 1.0), 0.01);
}

// The feature scene (normal-mapped floor, bumped copper sphere, checkerboard-alpha quad before an
// emitter): 0.9919 / 0.9887 / 0.9866 of pbrt-v4 at 64 spp, 0.9932 / 0.9898 / 0.9876 at 1024 spp. What
// remains is Penumbra's path tracer rejecting directions on which the shading and geometric normals
// disagree (pbrt-v4 keeps them): with that test removed the ratios were 0.9991 / 0.9990 / 1.0015 on a map
// tilting normals by up to 62 degrees. Tolerance 2 %. (Without its alpha texture the scene renders a third darker.)
TEST(SurfaceDetailScene, FeatureSceneMatchesPbrtV4) {
  const Rgb pbrt_mean(0.482739f, 0.395929f, 0.315755f);
  ImageRgb img = render_file(scene_path("scene"), test::temp_dir("surface-detail") + "/scene.exr");
  EXPECT_EQ(test::count_nonfinite(img), 0);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(test::mean_channel(img, c) / pbrt_mean[c], 1.0, 0.02);
}
