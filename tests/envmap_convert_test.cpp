// Converting environment images between the equal-area and the equirectangular mapping
// (envmap::resample, `penumbra envmap`, exact area weighting): constants stay constant, the sphere mean
// is kept even with a sun a few texels wide (where point sampling 8 x 8 points per texel is off by a
// percent: the negative control), a smooth sky lands where it belongs, and the command line checks
// its options.
#include "environment_map.h"

#include <penumbra/image.h>

#include "support/command.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <functional>

using namespace penumbra;
using namespace penumbra::test;
using envmap::Mapping;

namespace {

ImageRgb make_map(Mapping m, int w, int h, const std::function<Rgb(const Vec3&)>& radiance) {
  ImageRgb img;
  img.width = w;
  img.height = h;
  img.pixels.resize(3 * static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Rgb L = radiance(envmap::uv_to_direction(m, Vec2((x + 0.5f) / w, (y + 0.5f) / h)));
      for (int c = 0; c < 3; ++c) img.pixels[3 * (static_cast<size_t>(y) * w + x) + c] = L[c];
    }
  return img;
}

double worst_mean_change(const envmap::RgbD& a, const envmap::RgbD& b) {
  return std::max({std::abs(b.r / a.r - 1.0), std::abs(b.g / a.g - 1.0), std::abs(b.b / a.b - 1.0)});
}

const std::string kSky = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/environment/sky.exr";

}  // namespace

// Sizes that do not divide each other, odd sizes (the square's axes inside texels), and resizing
// within one mapping.
TEST(EnvmapConvert, ConstantMapStaysConstantEveryWay) {
  ImageRgb latlong = make_map(Mapping::Equirectangular, 64, 32, [](const Vec3&) { return Rgb(0.25f, 1.5f, 3.f); });
  for (auto [from, to, w, h] : {std::tuple{Mapping::Equirectangular, Mapping::EqualArea, 45, 45},
                                std::tuple{Mapping::EqualArea, Mapping::Equirectangular, 90, 45},
                                std::tuple{Mapping::Equirectangular, Mapping::Equirectangular, 50, 25},
                                std::tuple{Mapping::EqualArea, Mapping::EqualArea, 27, 27}}) {
    ImageRgb in = from == Mapping::Equirectangular ? latlong : envmap::resample(latlong, Mapping::Equirectangular, from, 40, 40);
    ImageRgb out = envmap::resample(in, from, to, w, h);
    ASSERT_EQ(out.width, w);
    ASSERT_EQ(out.height, h);
    for (size_t i = 0; i < out.pixels.size(); i += 3) {
      ASSERT_NEAR(out.pixels[i], 0.25f, 1e-5f) << i;
      ASSERT_NEAR(out.pixels[i + 1], 1.5f, 1e-5f) << i;
      ASSERT_NEAR(out.pixels[i + 2], 3.f, 1e-5f) << i;
    }
  }
}

// The shipped sky has a sun of radiance 1500 over a few texels that carries half of its flux. Exact
// overlaps hand every input texel's flux on, so the sphere mean changes only by rounding (measured
// below 1e-7 each way). Point sampling instead, even at 8 x 8 points per output texel, is off by
// about 1 % (measured 1.1 % red), which the 1e-5 tolerance fails.
TEST(EnvmapConvert, SphereMeanIsKeptWithASunAFewTexelsWide) {
  ImageRgb latlong = read_image(kSky);
  envmap::RgbD mean = envmap::sphere_mean(latlong, Mapping::Equirectangular);
  ImageRgb square = envmap::resample(latlong, Mapping::Equirectangular, Mapping::EqualArea, 256, 256);
  double to_square = worst_mean_change(mean, envmap::sphere_mean(square, Mapping::EqualArea));
  ImageRgb back = envmap::resample(square, Mapping::EqualArea, Mapping::Equirectangular, 512, 256);
  double and_back = worst_mean_change(mean, envmap::sphere_mean(back, Mapping::Equirectangular));
  // Coarse output, many input texels per output texel.
  ImageRgb coarse = envmap::resample(latlong, Mapping::Equirectangular, Mapping::EqualArea, 16, 16);
  double coarse_change = worst_mean_change(mean, envmap::sphere_mean(coarse, Mapping::EqualArea));
  std::printf("[ measured ] sphere mean change: to equal area %.2g, and back %.2g, to 16 x 16 %.2g\n",
              to_square, and_back, coarse_change);
  EXPECT_LT(to_square, 1e-5);
  EXPECT_LT(and_back, 1e-5);
  EXPECT_LT(coarse_change, 1e-5);

  // Negative control: 8 x 8 points per output texel, averaged.
  ImageRgb plain = square;
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) {
      Rgb sum(0.f);
      for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i) {
          Vec3 w = envmap::uv_to_direction(Mapping::EqualArea, Vec2((x + (i + 0.5f) / 8) / 256, (y + (j + 0.5f) / 8) / 256));
          sum += envmap::lookup_nearest(latlong, envmap::direction_to_uv(Mapping::Equirectangular, w));
        }
      for (int c = 0; c < 3; ++c) plain.pixels[3 * (y * 256 + x) + c] = sum[c] / 64.f;
    }
  double plain_change = worst_mean_change(mean, envmap::sphere_mean(plain, Mapping::EqualArea));
  std::printf("[ measured ] point sampling (must exceed 1e-3): %.3g\n", plain_change);
  EXPECT_GT(plain_change, 1e-3);
}

// A sky linear in the direction, L = (2 + x, 2 + y, 2 + z), converted from a fine equirectangular map
// to a 64 x 64 equal-area one: each texel holds the mean of L over the texel, which for a linear L is
// L at the texel's centroid direction; the texel's centre is within a fraction of the texel's
// 3-degree width (0.05 in L) of it. Measured worst 0.008, tolerance 0.02; a map mirrored in x (L off
// by 2|x|) fails.
TEST(EnvmapConvert, SmoothSkyLandsInTheRightTexels) {
  auto L = [](const Vec3& w) { return Rgb(2.f + w.x, 2.f + w.y, 2.f + w.z); };
  ImageRgb latlong = make_map(Mapping::Equirectangular, 512, 256, L);
  ImageRgb square = envmap::resample(latlong, Mapping::Equirectangular, Mapping::EqualArea, 64, 64);
  auto worst_error = [&](const std::function<Rgb(const Vec3&)>& expected) {
    double worst = 0.0;
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x) {
        Rgb e = expected(envmap::uv_to_direction(Mapping::EqualArea, Vec2((x + 0.5f) / 64, (y + 0.5f) / 64)));
        for (int c = 0; c < 3; ++c) worst = std::max(worst, double(std::abs(square.pixels[3 * (y * 64 + x) + c] - e[c])));
      }
    return worst;
  };
  double error = worst_error(L);
  double mirrored = worst_error([&](const Vec3& w) { return L(Vec3(-w.x, w.y, w.z)); });
  std::printf("[ measured ] worst texel error %.4f; against the mirrored sky %.3f\n", error, mirrored);
  EXPECT_LT(error, 0.02);
  EXPECT_GT(mirrored, 1.0);
}

TEST(EnvmapConvert, CommandConvertsAndChecksItsOptions) {
  std::string dir = temp_dir("envmap-cli");
  auto r = run_penumbra({"envmap", kSky, dir + "/square.exr", "--to", "equalarea"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ImageRgb square = read_image(dir + "/square.exr");
  EXPECT_EQ(square.width, 181);  // round(sqrt(256 x 128)): about as many texels as the input
  EXPECT_EQ(square.height, 181);
  EXPECT_NE(r.err.find("181x181 equalarea from"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("mean radiance over the sphere"), std::string::npos) << r.err;
  r = run_penumbra({"envmap", dir + "/square.exr", dir + "/back.exr", "--to", "equirectangular", "--size", "64"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ImageRgb back = read_image(dir + "/back.exr");
  EXPECT_EQ(back.width, 64);
  EXPECT_EQ(back.height, 32);

  r = run_penumbra({"envmap", kSky, dir + "/x.exr", "--to", "cubemap"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--to: expected equalarea or equirectangular, got 'cubemap'"), std::string::npos) << r.err;
  r = run_penumbra({"envmap", kSky, dir + "/x.exr", "--to", "equirectangular", "--size", "63"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--size 63"), std::string::npos) << r.err;
  r = run_penumbra({"envmap", kSky, dir + "/x.exr", "--to", "equalarea", "--from", "equalarea"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--from equalarea"), std::string::npos) << r.err;
  ImageRgb wide;
  wide.width = 48;
  wide.height = 16;
  wide.pixels.assign(3 * 48 * 16, 1.f);
  write_image(dir + "/wide.exr", wide);
  r = run_penumbra({"envmap", dir + "/wide.exr", dir + "/x.exr", "--to", "equalarea"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("neither square (equal area) nor 2:1 (equirectangular); say which with --from"), std::string::npos)
      << r.err;
  r = run_penumbra({"envmap", dir + "/wide.exr", dir + "/x.exr", "--to", "equalarea", "--from", "equirectangular"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
}
