// Whole renders with analytic answers: the white furnace of an emitting, reflecting closed sphere and
// the truncated series that checks the depth convention; determinism under thread counts.
#include "render/render_session.h"
#include "support/command.h"
#include "support/image_stats.h"

#include <gtest/gtest.h>

#include <fmt/core.h>

using namespace penumbra;

namespace {

// The camera sits at the centre of a sphere whose inside has albedo `a` and emits `Le` everywhere.
// Radiance inside is L = Le + a L at every point and direction, so L = Le / (1 - a); with paths of
// at most D bounces it is Le * sum_{k=0..D} a^k.
std::string furnace_scene(float albedo, float Le, int maxdepth, const std::string& sampler = "independent") {
  return fmt::format(R"(
LookAt 0 0 0  0 0 1  0 1 0
Camera "perspective" "float fov" [ 60 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ] "string filename" [ "furnace.exr" ]
PixelFilter "box"
Sampler "{}" "integer pixelsamples" [ 64 ]
Integrator "path" "integer maxdepth" [ {} ]
WorldBegin
Material "diffuse" "rgb reflectance" [ {} {} {} ]
AreaLightSource "diffuse" "rgb L" [ {} {} {} ]
ReverseOrientation
Shape "sphere" "float radius" [ 1 ]
)", sampler, maxdepth, albedo, albedo, albedo, Le, Le, Le);
}

RenderResult render_text(const std::string& name, const std::string& text, int threads = 0, int seed = -1,
                         int spp = 0) {
  std::string dir = test::temp_dir(name);
  RenderSettings s;
  s.scene_file = test::write_file(dir, "scene.pbrt", text);
  s.quiet = true;
  s.threads = threads;
  if (seed >= 0) s.seed = static_cast<uint32_t>(seed);
  if (spp > 0) s.spp = spp;
  return render(s);
}

}  // namespace

// Furnace: Le = 1, a = 0.5 -> L = 2. 16x16 pixels x 64 spp; maxdepth 200 makes truncation a^201 ~ 0.
// Tolerances: the image mean within 1 % (4 standard errors: the per-pixel standard deviation at 64 spp
// measures 0.079, so the mean of 256 pixels has 0.005), and every pixel within 0.4 (5 sigma).
TEST(PathIntegrator, FurnaceSphereRendersLeOverOneMinusAlbedo) {
  RenderResult r = render_text("furnace", furnace_scene(0.5f, 1.f, 200));
  EXPECT_EQ(r.stats.nonfinite_samples, 0u);
  EXPECT_EQ(test::count_nonfinite(r.image), 0);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(test::mean_channel(r.image, c), 2.0, 0.02);
  EXPECT_LT(test::max_abs_pixel_deviation(r.image, 2.0), 0.4);
}

// Higher albedo makes long paths matter: a = 0.8 -> L = 5 (Russian roulette must stay unbiased).
TEST(PathIntegrator, FurnaceWithHighAlbedoStaysUnbiased) {
  RenderResult r = render_text("furnace08", furnace_scene(0.8f, 1.f, 400));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(test::mean_channel(r.image, c), 5.0, 0.05);
}

// Depth convention: maxdepth D collects exactly D bounces, so the image is sum_{k=0..D} a^k * Le.
// 512 spp. The tolerance is 4 standard errors of the image mean, measured from the pixels' spread; the test
// asserts that it separates D from D - 1 and D + 1 (a^(D+1) = 1.6 % of the image at D = 5), so an
// integrator that adds or drops a bounce fails.
TEST(PathIntegrator, MaxDepthTruncatesSeriesExactly) {
  const float a = 0.5f;
  auto series = [a](int depth) {
    double sum = 0.0;
    for (int k = 0; k <= depth; ++k) sum += std::pow(a, k);
    return sum;
  };
  for (int depth : {0, 1, 2, 5}) {
    RenderResult r = render_text(fmt::format("series{}", depth), furnace_scene(a, 1.f, depth), 0, -1, 512);
    double mean = test::mean_channel(r.image, 1), tol = 4.0 * test::standard_error_of_mean(r.image, 1) + 1e-6;
    EXPECT_NEAR(mean, series(depth), tol) << "maxdepth " << depth;
    EXPECT_GT(std::abs(mean - series(depth + 1)), tol) << "maxdepth " << depth << " is not told from " << depth + 1;
    if (depth > 0)
      EXPECT_GT(std::abs(mean - series(depth - 1)), tol) << "maxdepth " << depth << " is not told from " << depth - 1;
  }
}

TEST(PathIntegrator, SameSeedGivesBitIdenticalImagesAcrossThreadCounts) {
  std::string scene = furnace_scene(0.5f, 1.f, 5);
  RenderResult one = render_text("det1", scene, 1, 3);
  RenderResult two = render_text("det2", scene, 2, 3);
  ASSERT_EQ(one.image.pixels.size(), two.image.pixels.size());
  EXPECT_EQ(one.image.pixels, two.image.pixels);
  RenderResult other_seed = render_text("det3", scene, 2, 4);
  EXPECT_NE(one.image.pixels, other_seed.image.pixels);
}
