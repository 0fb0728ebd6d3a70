// Statistical image regression (Mitsuba's approach): for each integrator on three small scenes, a
// reference mean and variance image are stored in the repository (tests/data/regression/, 20x12
// float EXRs at 512 spp). The test renders one image with a seed the references never used and compares it pixel
// by pixel with a Z-test,
//   Z_p = (I_p - mean_p) / sqrt(var_p (1 + 1/K)),
// where var_p is the variance of one render at the test's spp (measured over the K renders that made
// the reference) and mean_p their mean. A pixel fails below the Sidak-corrected level
// 1 - (1 - 0.01)^(1/pixels); the image fails when more than 0.5 % of its pixels do (a rule on the
// fraction, since a path tracer's pixel values are heavy-tailed, not normal), or when the mean of its
// Z values is more than 4 standard deviations of the same statistic over the K reference renders
// from 0 (a small bias spread over the whole image shows there, not in any single pixel; the
// measured spread includes the correlations between pixels that splats and shared photons bring). On failure a p-value image
// is written beside the render.
//
// Negative controls: the same render 2 % too bright fails the mean-Z rule, and a render that misses
// light (maxdepth 1) fails the per-pixel rule.
//
// The references are made by the test itself: `PENUMBRA_MAKE_REFERENCES=1 build/bin/test-image-regression`
// (K = 64 renders per case, seeds 5000-5063) rewrites tests/data/regression/.
#include "image/image_io.h"
#include "render/render_session.h"
#include "support/exr_channels.h"

#include <gtest/gtest.h>
#include <fmt/core.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

using namespace penumbra;

namespace {

const bool g_make_references = std::getenv("PENUMBRA_MAKE_REFERENCES") != nullptr;

const std::string kDataDir = std::string(PENUMBRA_SOURCE_DIR) + "/tests/data/regression";
constexpr int kReferenceRenders = 64;
constexpr int kSpp = 512;
constexpr int kWidth = 20, kHeight = 12;

struct Case {
  std::string scene, integrator;
  std::string name() const { return fmt::format("{}-{}", scene, integrator); }
};

std::vector<Case> cases() {
  std::vector<Case> out;
  for (const char* scene : {"cornell-box", "sphere-lights", "environment"})
    for (const char* integrator : {"path", "bdpt", "lighttracing", "sppm"}) {
      if (std::string(integrator) == "lighttracing" && std::string(scene) == "environment") continue;  // sky unseen
      out.push_back({scene, integrator});
    }
  return out;
}

ImageRgb render_case(const Case& c, uint32_t seed, int max_depth = -1) {
  RenderSettings s;
  s.scene_file = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/" + c.scene + "/scene.pbrt";
  s.integrator = c.integrator;
  s.spp = kSpp;
  s.seed = seed;
  s.resolution = std::make_pair(kWidth, kHeight);
  s.threads = 2;
  s.quiet = true;
  if (c.integrator == "sppm") s.integrator_params.push_back({"seed", std::to_string(seed), "test"});
  if (max_depth >= 0) s.integrator_params.push_back({"maxdepth", std::to_string(max_depth), "test"});
  return render(s).image;
}

struct Verdict {
  int pixels = 0, rejected = 0;
  double mean_z = 0.0;   // mean of the pixels' Z values
  double image_z = 0.0;  // mean_z in standard deviations of the references' own mean_z
  ImageRgb p_values;
  bool passes() const { return rejected <= 0.005 * pixels && std::abs(image_z) <= 4.0; }
};

double two_sided_p(double z) { return std::erfc(std::abs(z) / std::sqrt(2.0)); }

Verdict compare(const ImageRgb& img, const ImageRgb& mean, const ImageRgb& var, double mean_z_sd) {
  Verdict v;
  v.p_values = img;
  const size_t n = img.pixels.size();
  const double level = 1.0 - std::pow(1.0 - 0.01, 1.0 / static_cast<double>(n));
  double sum_z = 0.0;
  int counted = 0;
  for (size_t i = 0; i < n; ++i) {
    double s2 = var.pixels[i] * (1.0 + 1.0 / kReferenceRenders);
    double d = img.pixels[i] - mean.pixels[i];
    double p = 1.0;
    if (s2 > 0.0) {
      double z = d / std::sqrt(s2);
      p = two_sided_p(z);
      sum_z += z;
      ++counted;
    } else if (std::abs(d) > 1e-6 * (1.0 + std::abs(mean.pixels[i]))) {
      p = 0.0;  // a pixel that never varied (black, or a constant emitter) must not change
    }
    v.p_values.pixels[i] = static_cast<float>(p);
    v.rejected += p < level;
  }
  v.pixels = static_cast<int>(n);
  // The mean Z (an inverse-variance weighting, the most sensitive to a bias over the whole image)
  // against its own spread over the K reference renders, measured, so that the pixels' correlations
  // through splats and shared photons and the Z values' heavy tails are in it.
  v.mean_z = counted ? sum_z / counted : 0.0;
  v.image_z = mean_z_sd > 0.0 ? v.mean_z / mean_z_sd : 0.0;
  return v;
}

void make_references(const Case& c) {
  std::vector<double> sum, sum2;
  std::vector<ImageRgb> renders;
  for (int k = 0; k < kReferenceRenders; ++k) {
    ImageRgb img = render_case(c, 5000u + static_cast<uint32_t>(k));
    renders.push_back(img);
    if (sum.empty()) sum.assign(img.pixels.size(), 0.0), sum2.assign(img.pixels.size(), 0.0);
    for (size_t i = 0; i < img.pixels.size(); ++i) sum[i] += img.pixels[i], sum2[i] += double(img.pixels[i]) * img.pixels[i];
  }
  ImageRgb mean{kWidth, kHeight, std::vector<float>(sum.size())}, var = mean;
  for (size_t i = 0; i < sum.size(); ++i) {
    double m = sum[i] / kReferenceRenders;
    mean.pixels[i] = static_cast<float>(m);
    var.pixels[i] = static_cast<float>(std::max(0.0, (sum2[i] - kReferenceRenders * m * m) / (kReferenceRenders - 1)));
  }
  // The spread of each reference render's mean Z (leave-one-out would be exact; with K = 64 the
  // difference is 1.6 %).
  double zs = 0.0, zs2 = 0.0;
  for (const ImageRgb& r : renders) {
    double z = compare(r, mean, var, 1.0).mean_z;
    zs += z, zs2 += z * z;
  }
  double zm = zs / kReferenceRenders;
  double sd = std::sqrt(std::max(0.0, (zs2 - kReferenceRenders * zm * zm) / (kReferenceRenders - 1)));
  std::filesystem::create_directories(kDataDir);
  write_image(kDataDir + "/" + c.name() + "-mean.exr", mean, {{"penumbra:mean_z_sd", fmt::format("{:.9g}", sd)}});
  write_image(kDataDir + "/" + c.name() + "-variance.exr", var);
}

struct Reference {
  ImageRgb mean, var;
  double mean_z_sd = 0.0;
};

Reference load_reference(const Case& c) {
  Reference r;
  std::string path = kDataDir + "/" + c.name() + "-mean.exr";
  r.mean = read_image(path);
  r.var = read_image(kDataDir + "/" + c.name() + "-variance.exr");
  r.mean_z_sd = std::stod(test::read_exr_channels(path).meta.at("penumbra:mean_z_sd"));
  return r;
}

void PrintTo(const Case& c, std::ostream* os) { *os << c.name(); }

class ImageRegression : public ::testing::TestWithParam<Case> {};

TEST_P(ImageRegression, RenderMatchesStoredMeanAndVariance) {
  const Case& c = GetParam();
  if (g_make_references) {
    make_references(c);
    return;
  }
  Reference ref = load_reference(c);
  ImageRgb img = render_case(c, 77);
  Verdict v = compare(img, ref.mean, ref.var, ref.mean_z_sd);
  std::printf("%-28s %d of %d pixels rejected, mean Z at %+.2f standard deviations\n", c.name().c_str(), v.rejected,
              v.pixels, v.image_z);
  if (!v.passes()) {
    std::string out = std::filesystem::temp_directory_path() / ("penumbra-regression-" + c.name());
    std::filesystem::create_directories(out);
    write_image(out + "/render.exr", img);
    write_image(out + "/p-values.exr", v.p_values);
    ADD_FAILURE() << c.name() << ": " << v.rejected << " pixels rejected, mean Z at " << v.image_z
                  << " standard deviations; p-value image in "
                  << out;
  }
}

INSTANTIATE_TEST_SUITE_P(Cases, ImageRegression, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           std::string n = info.param.name();
                           for (char& ch : n)
                             if (ch == '-') ch = '_';
                           return n;
                         });

TEST(ImageRegressionControl, TwoPercentBrighterFailsAndMissingLightFails) {
  if (g_make_references) GTEST_SKIP() << "making references";
  Case c{"cornell-box", "path"};
  Reference ref = load_reference(c);
  ImageRgb img = render_case(c, 77);
  ASSERT_TRUE(compare(img, ref.mean, ref.var, ref.mean_z_sd).passes());
  ImageRgb brighter = img;
  for (float& x : brighter.pixels) x *= 1.02f;
  Verdict b = compare(brighter, ref.mean, ref.var, ref.mean_z_sd);
  std::printf("2 %% brighter: %d pixels rejected, mean Z at %+.2f standard deviations\n", b.rejected, b.image_z);
  EXPECT_FALSE(b.passes());
  Verdict d = compare(render_case(c, 77, 1), ref.mean, ref.var, ref.mean_z_sd);
  std::printf("maxdepth 1: %d pixels rejected, mean Z at %+.2f standard deviations\n", d.rejected, d.image_z);
  EXPECT_FALSE(d.passes());
  EXPECT_GT(d.rejected, 0.005 * d.pixels);
}

}  // namespace


namespace {

// Stored means of two unbiased integrators: per-pixel Z values with both means' variances (each of
// kReferenceRenders renders); returns the number of pixels rejected at the Sidak-corrected 1 % level.
int rejected_between_means(const Reference& a, const Reference& b, float scale_a = 1.f) {
  const size_t n = a.mean.pixels.size();
  const double level = 1.0 - std::pow(1.0 - 0.01, 1.0 / static_cast<double>(n));
  int rejected = 0;
  for (size_t i = 0; i < n; ++i) {
    double s2 = (a.var.pixels[i] * scale_a * scale_a + b.var.pixels[i]) / kReferenceRenders;
    double d = a.mean.pixels[i] * scale_a - b.mean.pixels[i];
    if (s2 > 0.0 ? two_sided_p(d / std::sqrt(s2)) < level : std::abs(d) > 1e-6 * (1.0 + std::abs(b.mean.pixels[i])))
      ++rejected;
  }
  return rejected;
}

}  // namespace

// The stored references of bdpt and light tracing against the path tracer's, pixel by pixel: all
// three are unbiased, so they must agree within their noise everywhere, not only in the image mean.
// This would have caught splats that ignored the pixel filter (one pixel per splat under the
// Gaussian filter: light tracing's edges sharper than path's). Control: bdpt's mean 2 % brighter.
TEST(ImageRegressionCrossCheck, UnbiasedIntegratorsReferencesAgreePerPixel) {
  if (g_make_references) GTEST_SKIP() << "making references";
  for (const char* scene : {"cornell-box", "sphere-lights", "environment"}) {
    Reference path = load_reference({scene, "path"});
    const int n = static_cast<int>(path.mean.pixels.size());
    for (const char* integrator : {"bdpt", "lighttracing"}) {
      if (std::string(integrator) == "lighttracing" && std::string(scene) == "environment") continue;
      Reference other = load_reference({scene, integrator});
      int rejected = rejected_between_means(other, path);
      std::printf("%-14s %-13s vs path: %d of %d values rejected\n", scene, integrator, rejected, n);
      EXPECT_LE(rejected, 0.005 * n) << scene << " " << integrator;
      if (std::string(integrator) == "bdpt") {
        int brighter = rejected_between_means(other, path, 1.02f);
        std::printf("%-14s bdpt 2 %% brighter vs path: %d rejected\n", scene, brighter);
        EXPECT_GT(brighter, 0.005 * n) << scene;
      }
    }
  }
}
