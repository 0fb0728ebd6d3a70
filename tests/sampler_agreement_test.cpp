// The three samplers on the Cornell box: their images agree with each other and with a 2048-spp
// reference, and at equal spp the low-discrepancy samplers have the lower error.
#include "render/render_session.h"
#include "support/image_stats.h"

#include <gtest/gtest.h>

using namespace penumbra;

namespace {

ImageRgb render_cornell(const std::string& sampler, int spp, uint32_t seed) {
  RenderSettings s;
  s.scene_file = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt";
  s.sampler = sampler;
  s.spp = spp;
  s.seed = seed;
  s.resolution = std::make_pair(32, 32);
  s.quiet = true;
  return render(s).image;
}

// relMSE = mean (I - R)^2 / (R^2 + 0.01) (docs/algorithms.md, "Image error metrics"): the light's few pixels, 20x
// brighter than the rest, do not dominate it.
double rel_mse(const ImageRgb& img, const ImageRgb& ref) {
  double sum = 0;
  for (size_t i = 0; i < img.pixels.size(); ++i) {
    double d = img.pixels[i] - ref.pixels[i];
    sum += d * d / (ref.pixels[i] * ref.pixels[i] + 0.01);
  }
  return sum / img.pixels.size();
}

double rmse(const ImageRgb& img, const ImageRgb& ref) {
  double sum = 0;
  for (size_t i = 0; i < img.pixels.size(); ++i) sum += (img.pixels[i] - ref.pixels[i]) * (img.pixels[i] - ref.pixels[i]);
  return std::sqrt(sum / img.pixels.size());
}

// Mean below the top quarter of the image, where the light is: walls, floor and blocks.
double mean_below_light(const ImageRgb& img) {
  double sum = 0;
  int n = 0;
  for (int y = img.height / 4; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x, ++n)
      for (int c = 0; c < 3; ++c) sum += img.pixels[3 * (y * img.width + x) + c];
  return sum / (3.0 * n);
}

}  // namespace

// Reference: 32x32 pixels at 1024 spp (independent sampler, its own seed). Each sampler renders 16 spp
// with 3 seeds. Measured (averaged over the seeds): RMSE independent 0.146, halton 0.090, sobol 0.061;
// relMSE 0.0309, 0.0271, 0.0262. The low-discrepancy samplers gain most where the first dimensions
// decide (pixel filter and light edges); dark indirectly lit pixels depend on deep dimensions and gain
// less. Asserted: the mean below the light within 2 % of the reference's for every render; RMSE at least
// 1.4x (halton) and 1.8x (sobol) lower than independent's; relMSE lower for both.
TEST(SamplerAgreement, LowDiscrepancySamplersAgreeAndHaveLowerErrorOnCornellBox) {
  ImageRgb ref = render_cornell("independent", 1024, 1000);
  double ref_mean = mean_below_light(ref);
  double err[3] = {0, 0, 0}, rel[3] = {0, 0, 0};
  const char* names[3] = {"independent", "halton", "sobol"};
  for (int k = 0; k < 3; ++k)
    for (uint32_t seed = 1; seed <= 3; ++seed) {
      ImageRgb img = render_cornell(names[k], 16, seed);
      EXPECT_EQ(test::count_nonfinite(img), 0);
      EXPECT_NEAR(mean_below_light(img), ref_mean, 0.02 * ref_mean) << names[k] << " seed " << seed;
      err[k] += rmse(img, ref) / 3.0;
      rel[k] += rel_mse(img, ref) / 3.0;
    }
  std::printf("RMSE at 16 spp vs 1024-spp reference: independent %.4f, halton %.4f, sobol %.4f\n", err[0], err[1], err[2]);
  std::printf("relMSE: independent %.5f, halton %.5f, sobol %.5f\n", rel[0], rel[1], rel[2]);
  EXPECT_LT(err[1] * 1.4, err[0]);
  EXPECT_LT(err[2] * 1.8, err[0]);
  EXPECT_LT(rel[1], rel[0]);
  EXPECT_LT(rel[2], rel[0]);
}
