// Error metrics for convergence studies, and the property they exist to show: for an unbiased
// estimator MSE falls as 1/N, so doubling the samples halves it.
#include "render/image_metrics.h"
#include "render/render_session.h"
#include "support/command.h"

#include <penumbra/error.h>

#include <fmt/core.h>
#include <gtest/gtest.h>

using namespace penumbra;

namespace {

ImageRgb constant_image(int w, int h, float v) {
  ImageRgb img;
  img.width = w, img.height = h;
  img.pixels.assign(3 * w * h, v);
  return img;
}

}  // namespace

TEST(ImageMetrics, IdenticalImagesHaveZeroError) {
  ImageRgb a = constant_image(4, 3, 0.7f);
  ImageErrors e = image_errors(a, a);
  EXPECT_EQ(e.mse, 0.0);
  EXPECT_EQ(e.rel_mse, 0.0);
  EXPECT_EQ(e.mae, 0.0);
}

TEST(ImageMetrics, KnownValuesAndRelMseEpsilon) {
  ImageRgb ref = constant_image(2, 2, 1.0f), img = constant_image(2, 2, 1.5f);
  ImageErrors e = image_errors(img, ref);
  EXPECT_DOUBLE_EQ(e.mse, 0.25);
  EXPECT_DOUBLE_EQ(e.rmse, 0.5);
  EXPECT_DOUBLE_EQ(e.mae, 0.5);
  EXPECT_NEAR(e.rel_mse, 0.25 / 1.01, 1e-12);
  EXPECT_THROW(image_errors(constant_image(2, 1, 0), ref), Error);
}

TEST(ImageMetrics, HalfReferenceVarianceIsSubtracted) {
  ImageRgb a = constant_image(2, 2, 1.0f), b = constant_image(2, 2, 1.2f), mean;
  ImageRgb var = half_reference_variance(a, b, &mean);
  EXPECT_FLOAT_EQ(mean.pixels[0], 1.1f);
  EXPECT_NEAR(var.pixels[0], 0.01f, 1e-6f);
  ImageErrors raw = image_errors(constant_image(2, 2, 1.3f), mean);
  ImageErrors corrected = image_errors(constant_image(2, 2, 1.3f), mean, &var);
  EXPECT_NEAR(raw.mse - corrected.mse, 0.01, 1e-6);
}

// Furnace sphere (exact answer 2 everywhere), 16x16 pixels, 24 seeds: MSE at 8 spp over MSE at 16 spp
// is 2 within 10 % (the ratio's standard error from 24 x 768 squared errors is about 3.5 %).
TEST(ImageMetrics, DoublingSamplesHalvesMseForPathTracing) {
  std::string scene = R"(
LookAt 0 0 0  0 0 1  0 1 0
Camera "perspective" "float fov" [ 60 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
PixelFilter "box"
Integrator "path" "integer maxdepth" [ 100 ]
WorldBegin
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
AreaLightSource "diffuse" "rgb L" [ 1 1 1 ]
ReverseOrientation
Shape "sphere"
)";
  std::string path = test::write_file(test::temp_dir("mse-halves"), "scene.pbrt", scene);
  ImageRgb exact = constant_image(16, 16, 2.0f);
  double mse[2] = {0, 0};
  for (int k = 0; k < 2; ++k)
    for (uint32_t seed = 1; seed <= 24; ++seed) {
      RenderSettings s;
      s.scene_file = path;
      s.spp = 8 << k;
      s.seed = seed;
      s.quiet = true;
      mse[k] += image_errors(render(s).image, exact).mse / 24.0;
    }
  EXPECT_NEAR(mse[0] / mse[1], 2.0, 0.2) << "MSE 8 spp " << mse[0] << ", 16 spp " << mse[1];
}

// The robust metrics on an image whose 2,000 pixels all have error 0.1 except 2 fireflies (0.1 %)
// of error 100: relMSE is dominated by the fireflies, the clamped relMSE and the median are not, and
// the worst-0.1 % share says how much of relMSE they hold.
TEST(ImageMetrics, RobustMetricsSeeThroughFireflies) {
  ImageRgb ref = constant_image(100, 20, 1.0f), img = constant_image(100, 20, 1.1f);
  for (int k : {17, 1234})
    for (int c = 0; c < 3; ++c) img.pixels[3 * k + c] = 101.f;
  ImageErrors e = image_errors(img, ref);
  double small = 0.01 / 1.01, big = 1e4 / 1.01;  // per-pixel (I - R)^2 / (R^2 + 0.01)
  EXPECT_NEAR(e.rel_mse, (1998 * small + 2 * big) / 2000, 1e-4);
  EXPECT_NEAR(e.rel_se_median, small, 1e-6);
  // The 99.9th percentile of 2000 sorted values is the 1998th, one of the small ones: both fireflies
  // are clamped to it.
  EXPECT_NEAR(e.rel_mse_clamped, small, 1e-6);
  EXPECT_NEAR(e.worst_share, 2 * big / (1998 * small + 2 * big), 1e-6);
  // Without fireflies the worst 0.1 % hold 0.1 %.
  ImageErrors plain = image_errors(constant_image(100, 20, 1.1f), ref);
  EXPECT_NEAR(plain.worst_share, 0.001, 1e-9);
  EXPECT_NEAR(plain.rel_mse_clamped, plain.rel_mse, 1e-9);
}
