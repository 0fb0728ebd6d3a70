// Every warp in penumbra/sampling.h must draw from exactly the density it reports: chi-square tests
// against the pdf, moment checks against closed forms, and negative controls proving the harness can
// tell a wrong pdf from a right one.
#include <penumbra/sampling.h>

#include "support/chi_square.h"
#include "support/pcg32.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

namespace penumbra {
namespace {

using test::ChiSquareResult;

// Chi-square tests in this file that are expected to pass; Šidák keeps the file's family-wise false
// alarm rate at 1% (the seeds are fixed, so in practice the outcome is deterministic).
constexpr int kChiSquareTests = 14;
const double kAlpha = test::sidak_alpha(0.01, kChiSquareTests);
constexpr int kSamples = 1'000'000;

std::string current_test_name() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  return std::string(info->test_suite_name()) + "." + info->name();
}

void expect_fits(const ChiSquareResult& r, double integral_tolerance = 1e-4) {
  std::printf("[ chi2     ] %s: %s\n", current_test_name().c_str(), r.summary().c_str());
  EXPECT_TRUE(r.passes(kAlpha)) << r.summary() << " (alpha = " << kAlpha << ")";
  EXPECT_NEAR(r.pdf_integral, 1.0, integral_tolerance) << r.summary();
  EXPECT_EQ(r.invalid_fraction, 0.0) << r.summary();
}

// Mean of f over kSamples samples of the warp, with fixed seeds.
template <typename F>
double mean_of(F f, uint64_t seed = 7) {
  test::Pcg32 rng(seed);
  double sum = 0.0;
  for (int i = 0; i < kSamples; ++i) sum += f(Vec2(rng.next_float(), rng.next_float()));
  return sum / kSamples;
}

// Five standard errors of a mean of kSamples values with variance `variance`.
double five_sigma(double variance) { return 5.0 * std::sqrt(variance / kSamples); }

// ---- Harness self-checks -------------------------------------------------------------------------

TEST(ChiSquareHarness, IncompleteGammaMatchesClosedForms) {
  for (double x : {0.01, 0.5, 1.0, 3.0, 20.0}) {
    EXPECT_NEAR(test::regularized_gamma_q(1.0, x), std::exp(-x), 1e-12) << x;  // exponential tail
    EXPECT_NEAR(test::regularized_gamma_q(0.5, x), std::erfc(std::sqrt(x)), 1e-12) << x;
    EXPECT_NEAR(test::regularized_gamma_p(2.5, x) + test::regularized_gamma_q(2.5, x), 1.0, 1e-12);
  }
  EXPECT_EQ(test::regularized_gamma_q(3.0, 0.0), 1.0);
}

TEST(ChiSquareHarness, PValuesMatchTabulatedCriticalValues) {
  // 5% critical values of the chi-square distribution from standard tables.
  EXPECT_NEAR(test::chi_square_p_value(3.841, 1), 0.05, 1e-4);
  EXPECT_NEAR(test::chi_square_p_value(9.488, 4), 0.05, 1e-4);
  EXPECT_NEAR(test::chi_square_p_value(18.307, 10), 0.05, 1e-4);
  EXPECT_NEAR(test::chi_square_p_value(124.342, 100), 0.05, 1e-4);
  EXPECT_NEAR(test::sidak_alpha(0.01, 1), 0.01, 1e-15);
  EXPECT_NEAR(test::sidak_alpha(0.01, 5), 0.0020082, 1e-6);
}

TEST(ChiSquareHarness, RejectsCosineSamplesAgainstUniformHemispherePdf) {
  auto r = test::chi_square_sphere([](Vec2 u, float) { return sample_cosine_hemisphere(u); },
                                   [](const Vec3& w) { return w.z > 0.f ? double(Inv2Pi) : 0.0; },
                                   kSamples, 30, 61, 11);
  std::printf("[ chi2     ] %s: %s\n", current_test_name().c_str(), r.summary().c_str());
  EXPECT_TRUE(r.failure.empty()) << r.summary();
  EXPECT_LT(r.p_value, 1e-12) << r.summary();
  EXPECT_FALSE(r.passes(kAlpha));
}

TEST(ChiSquareHarness, RejectsTriangleSamplesAgainstSkewedPdf) {
  // 6*b0 integrates to 1 over the triangle but is not the uniform density the warp produces.
  auto r = test::chi_square_plane([](Vec2 u, float) { return sample_uniform_triangle(u); },
                                  [](const Vec2& b) { return b.x + b.y <= 1.f ? 6.0 * b.x : 0.0; },
                                  kSamples, 40, 40, 12);
  std::printf("[ chi2     ] %s: %s\n", current_test_name().c_str(), r.summary().c_str());
  EXPECT_LT(r.p_value, 1e-12) << r.summary();
  EXPECT_FALSE(r.passes(kAlpha));
}

TEST(ChiSquareHarness, RejectsSamplesWhereThePdfIsZero) {
  auto r = test::chi_square_sphere([](Vec2 u, float) { return sample_uniform_sphere(u); },
                                   [](const Vec3& w) { return double(cosine_hemisphere_pdf(w.z)); },
                                   100'000, 20, 41, 13);
  EXPECT_FALSE(r.failure.empty()) << r.summary();
  EXPECT_FALSE(r.passes(kAlpha));
}

TEST(ChiSquareHarness, ReportsDeclinedSamplesAsInvalid) {
  // Sampling the sphere but dropping the lower half: the pdf of what remains integrates to 1/2.
  auto r = test::chi_square_sphere(
      [](Vec2 u, float) -> std::optional<Vec3> {
        Vec3 w = sample_uniform_sphere(u);
        if (w.z < 0.f) return std::nullopt;
        return w;
      },
      [](const Vec3& w) { return w.z >= 0.f ? double(Inv4Pi) : 0.0; }, 200'000, 20, 41, 14);
  EXPECT_NEAR(r.invalid_fraction, 0.5, 0.01);
  EXPECT_NEAR(r.pdf_integral, 0.5, 1e-4);
  EXPECT_TRUE(r.failure.empty()) << r.summary();
}

// ---- Directions ----------------------------------------------------------------------------------

TEST(CosineHemisphere, SamplingMatchesPdfChiSquare) {
  expect_fits(test::chi_square_sphere([](Vec2 u, float) { return sample_cosine_hemisphere(u); },
                                      [](const Vec3& w) { return double(cosine_hemisphere_pdf(w.z)); },
                                      kSamples, 30, 61, 1));
}

TEST(CosineHemisphere, MeanCosineIsTwoThirds) {
  // E[cos] = 2/3 and E[cos^2] = 1/2 for p = cos/pi, so Var = 1/18.
  EXPECT_NEAR(mean_of([](Vec2 u) { return sample_cosine_hemisphere(u).z; }), 2.0 / 3.0, five_sigma(1.0 / 18));
  EXPECT_NEAR(mean_of([](Vec2 u) { return sqr(sample_cosine_hemisphere(u).z); }), 0.5, five_sigma(1.0 / 12));
}

TEST(CosineHemisphere, DirectionsAreUnitAndAboveTheHorizon) {
  test::Pcg32 rng(2);
  for (int i = 0; i < 100'000; ++i) {
    Vec3 w = sample_cosine_hemisphere(Vec2(rng.next_float(), rng.next_float()));
    ASSERT_GE(w.z, 0.f);
    ASSERT_NEAR(glm::length(w), 1.f, 1e-6f);
  }
}

TEST(UniformSphere, SamplingMatchesPdfChiSquare) {
  expect_fits(test::chi_square_sphere([](Vec2 u, float) { return sample_uniform_sphere(u); },
                                      [](const Vec3&) { return double(uniform_sphere_pdf()); }, kSamples,
                                      30, 61, 2));
}

TEST(UniformSphere, MomentsMatchIsotropy) {
  // Each coordinate has mean 0 and second moment 1/3 on the uniform sphere.
  EXPECT_NEAR(mean_of([](Vec2 u) { return sample_uniform_sphere(u).x; }), 0.0, five_sigma(1.0 / 3));
  EXPECT_NEAR(mean_of([](Vec2 u) { return sample_uniform_sphere(u).y; }), 0.0, five_sigma(1.0 / 3));
  EXPECT_NEAR(mean_of([](Vec2 u) { return sample_uniform_sphere(u).z; }), 0.0, five_sigma(1.0 / 3));
  EXPECT_NEAR(mean_of([](Vec2 u) { return sqr(sample_uniform_sphere(u).z); }), 1.0 / 3, five_sigma(4.0 / 45));
}

// A cone chi-square test. Narrow cones are histogrammed over a cap 25% taller than the cone so that
// cells just outside it check that no sample leaks out.
ChiSquareResult cone_test(float cos_max, bool zoom, uint64_t seed) {
  test::SphereChart chart;
  if (zoom) chart.z_min = 1.0 - 1.25 * (1.0 - double(cos_max));
  return test::chi_square_sphere([cos_max](Vec2 u, float) { return sample_uniform_cone(u, cos_max); },
                                 [cos_max](const Vec3& w) {
                                   return w.z >= cos_max ? double(uniform_cone_pdf(cos_max)) : 0.0;
                                 },
                                 kSamples, 20, 31, seed, chart);
}

TEST(UniformCone, WideConeSamplingMatchesPdfChiSquare) { expect_fits(cone_test(-0.5f, false, 3)); }
TEST(UniformCone, HalfAngle60SamplingMatchesPdfChiSquare) { expect_fits(cone_test(0.5f, false, 4)); }
TEST(UniformCone, HalfAngle10SamplingMatchesPdfChiSquare) {
  expect_fits(cone_test(std::cos(radians(10.f)), true, 5));
}
TEST(UniformCone, VeryNarrowConeSamplingMatchesPdfChiSquare) { expect_fits(cone_test(0.9999f, true, 6)); }

TEST(UniformCone, MeanCosineIsMidpointOfRange) {
  for (float cos_max : {-0.5f, 0.5f, 0.9999f}) {
    double mean = (1.0 + cos_max) / 2.0, variance = sqr(1.f - cos_max) / 12.0;
    EXPECT_NEAR(mean_of([cos_max](Vec2 u) { return sample_uniform_cone(u, cos_max).z; }), mean,
                five_sigma(variance) + 1e-7)
        << cos_max;
  }
}

TEST(UniformCone, NarrowConeSamplesStayInsideAndUnit) {
  const float cos_max = 0.9999f;
  test::Pcg32 rng(8);
  for (int i = 0; i < 100'000; ++i) {
    Vec3 w = sample_uniform_cone(Vec2(rng.next_float(), rng.next_float()), cos_max);
    ASSERT_GE(w.z, cos_max);
    ASSERT_NEAR(glm::length(w), 1.f, 1e-6f);
    ASSERT_GT(std::hypot(w.x, w.y), 0.f) << "sin(theta) lost to cancellation";
  }
}

// ---- Planar warps --------------------------------------------------------------------------------

TEST(UniformTriangle, BarycentricsAreUniformChiSquare) {
  // Uniform over the triangle b0, b1 >= 0, b0 + b1 <= 1, whose area in barycentric space is 1/2.
  expect_fits(test::chi_square_plane([](Vec2 u, float) { return sample_uniform_triangle(u); },
                                     [](const Vec2& b) { return b.x + b.y <= 1.f ? 2.0 : 0.0; }, kSamples,
                                     40, 40, 7),
              1e-3);
}

TEST(UniformTriangle, MeanBarycentricsAreOneThird) {
  // Each barycentric coordinate is Beta(1, 2): mean 1/3, variance 1/18.
  EXPECT_NEAR(mean_of([](Vec2 u) { return sample_uniform_triangle(u).x; }), 1.0 / 3, five_sigma(1.0 / 18));
  EXPECT_NEAR(mean_of([](Vec2 u) { return sample_uniform_triangle(u).y; }), 1.0 / 3, five_sigma(1.0 / 18));
}

TEST(UniformTriangle, CornersOfTheSquareMapToTheTriangle) {
  EXPECT_EQ(sample_uniform_triangle(Vec2(0.f, 0.f)), Vec2(0.f, 0.f));
  Vec2 b = sample_uniform_triangle(Vec2(OneMinusEpsilon, OneMinusEpsilon));
  EXPECT_LE(b.x + b.y, 1.f);
  test::Pcg32 rng(9);
  for (int i = 0; i < 100'000; ++i) {
    Vec2 s = sample_uniform_triangle(Vec2(rng.next_float(), rng.next_float()));
    ASSERT_GE(s.x, 0.f);
    ASSERT_GE(s.y, 0.f);
    ASSERT_LE(s.x + s.y, 1.f);
  }
}

TEST(ConcentricDisk, SamplingIsUniformChiSquare) {
  // Histogrammed on [-1,1]^2 directly, so a point outside the disk would fail the test.
  test::PlaneRect square{-1.0, -1.0, 1.0, 1.0};
  expect_fits(test::chi_square_plane([](Vec2 u, float) { return sample_uniform_disk_concentric(u); },
                                     [](const Vec2& p) { return glm::dot(p, p) <= 1.f ? double(InvPi) : 0.0; },
                                     kSamples, 41, 41, 8, square),
              1e-3);
}

TEST(ConcentricDisk, MeanSquaredRadiusIsOneHalf) {
  // r^2 is uniform on [0, 1] for a uniform disk.
  EXPECT_NEAR(mean_of([](Vec2 u) {
                Vec2 p = sample_uniform_disk_concentric(u);
                return glm::dot(p, p);
              }),
              0.5, five_sigma(1.0 / 12));
  EXPECT_EQ(sample_uniform_disk_concentric(Vec2(0.5f, 0.5f)), Vec2(0.f, 0.f));
}

TEST(ConcentricDisk, MatchesTheMapWithLibmSinCos) {
  // The map computes sin and cos of its quarter-circle angle by a polynomial: against the textbook
  // form with std::cos / std::sin on a 1025 x 1025 grid (corners and diagonals included), every point
  // within 2.5e-7 and still inside the disk. Negative control: a polynomial one term shorter (Taylor to
  // a^7 for sin) is off by 3.0e-7 at the corners, which the bound rejects.
  auto textbook = [](Vec2 u) {
    Vec2 o = 2.f * u - Vec2(1.f);
    if (o.x == 0.f && o.y == 0.f) return Vec2(0.f);
    bool x_major = std::abs(o.x) > std::abs(o.y);
    float r = x_major ? o.x : o.y;
    float phi = x_major ? (Pi / 4.f) * (o.y / o.x) : Pi / 2.f - (Pi / 4.f) * (o.x / o.y);
    return r * Vec2(std::cos(phi), std::sin(phi));
  };
  float worst = 0.f, worst_radius = 0.f;
  for (int i = 0; i <= 1024; ++i)
    for (int j = 0; j <= 1024; ++j) {
      Vec2 u(i / 1024.f, j / 1024.f);
      Vec2 p = sample_uniform_disk_concentric(u);
      Vec2 d = p - textbook(u);
      worst = std::max({worst, std::abs(d.x), std::abs(d.y)});
      worst_radius = std::max(worst_radius, glm::length(p));
    }
  EXPECT_LT(worst, 2.5e-7f) << worst;  // measured 1.8e-7: float rounding of both forms
  EXPECT_LE(worst_radius, 1.f + 2e-7f);
  float a = Pi / 4.f, a2 = a * a;
  float short_sin = a * (1.f + a2 * (-1.f / 6.f + a2 * (1.f / 120.f + a2 * (-1.f / 5040.f))));
  EXPECT_GT(std::abs(short_sin - std::sin(a)), 2.5e-7f);
}

// ---- Distribution1D ------------------------------------------------------------------------------

const std::vector<float> kSteps = {1.f, 3.f, 0.f, 0.5f, 7.f, 2.f, 0.f, 4.f};  // sum 17.5

// Density of the continuous distribution built from f, computed independently of Distribution1D.
double step_pdf(const std::vector<float>& f, double x) {
  double sum = 0.0;
  for (float v : f) sum += std::abs(v);
  size_t n = f.size();
  size_t i = std::min(size_t(x * n), n - 1);
  return sum > 0.0 ? std::abs(f[i]) * n / sum : 1.0;
}

ChiSquareResult continuous_test(const std::vector<float>& f, uint64_t seed) {
  Distribution1D d(f);
  // A 1D test on the plane harness: y is a dummy coordinate with one bin.
  return test::chi_square_plane(
      [&d](Vec2 u, float) {
        float pdf;
        return Vec2(d.sample_continuous(u.x, &pdf), 0.5f);
      },
      [&f](const Vec2& p) { return step_pdf(f, p.x); }, kSamples, int(f.size()) * 5, 1, seed);
}

TEST(Distribution1D, ContinuousSamplingMatchesPdfChiSquare) { expect_fits(continuous_test(kSteps, 21)); }

TEST(Distribution1D, DiscreteSamplingMatchesPmfChiSquare) {
  Distribution1D d(kSteps);
  std::vector<double> pmf;
  for (float v : kSteps) pmf.push_back(v / 17.5);
  expect_fits(test::chi_square_discrete([&d](float u) { return d.sample_discrete(u); }, pmf, kSamples, 22));
}

// Negative control of the discrete test: the same sampler against a pmf with 1 % of the largest
// bin's probability (7/17.5) moved to another bin must fail (4000 of 10^6 samples, 8 standard
// deviations), and so must a pmf that misses a bin the sampler can draw.
TEST(ChiSquareHarness, RejectsDiscreteSamplesAgainstAShiftedPmf) {
  Distribution1D d(kSteps);
  std::vector<double> pmf;
  for (float v : kSteps) pmf.push_back(v / 17.5);
  std::vector<double> shifted = pmf;
  shifted[7] += 0.01 * shifted[4];
  shifted[4] *= 0.99;
  auto sample = [&d](float u) { return d.sample_discrete(u); };
  EXPECT_FALSE(test::chi_square_discrete(sample, shifted, kSamples, 22).passes(kAlpha));
  std::vector<double> missing = pmf;
  missing[5] += missing[1];
  missing[1] = 0.0;
  EXPECT_FALSE(test::chi_square_discrete(sample, missing, kSamples, 22).passes(kAlpha));
}

TEST(Distribution1D, RemappedUIsUniformWithinTheChosenBin) {
  // (u_remapped, bin) must have density pmf(bin) * n on the strip of that bin: uniform in x and
  // independent of the bin, so callers can reuse the number.
  Distribution1D d(kSteps);
  const int n = int(kSteps.size());
  expect_fits(test::chi_square_plane(
      [&d, n](Vec2 u, float) {
        float remapped;
        size_t bin = d.sample_discrete(u.x, nullptr, &remapped);
        return Vec2(remapped, (float(bin) + 0.5f) / float(n));
      },
      [n](const Vec2& p) { return kSteps[std::min(int(p.y * n), n - 1)] / 17.5 * n; }, kSamples, 10, n, 23));
}

// The bin a u falls in, for few bins (counted) and many (binary search): as u grows the bin never
// goes back, a bin of zero weight is never returned, and the bin's CDF interval holds u (the remapped
// u is in [0, 1)). Zero bins at the start, inside and at the end, for 1 to 12 bins.
TEST(Distribution1D, DiscreteBinsAreMonotoneInUAndNeverEmpty) {
  for (size_t n = 1; n <= 12; ++n) {
    std::vector<float> f(n);
    for (size_t i = 0; i < n; ++i) f[i] = (i % 3 == 1 || i + 1 == n) && n > 1 ? 0.f : 1.f + float(i % 4);
    Distribution1D d(f);
    size_t previous = 0;
    const int steps = 20000;
    for (int k = 0; k < steps; ++k) {
      float u = std::min(float(k) / steps, OneMinusEpsilon);
      float remapped = -1.f;
      size_t bin = d.sample_discrete(u, nullptr, &remapped);
      ASSERT_LT(bin, n) << "n " << n << " u " << u;
      EXPECT_GT(f[bin], 0.f) << "n " << n << " u " << u;
      EXPECT_GE(bin, previous) << "n " << n << " u " << u;
      EXPECT_GE(remapped, 0.f);
      EXPECT_LT(remapped, 1.f);
      previous = bin;
    }
  }
}

TEST(Distribution1D, AllZeroFunctionSamplesUniformlyChiSquare) {
  std::vector<float> zeros(5, 0.f);
  expect_fits(continuous_test(zeros, 24));
  Distribution1D d(zeros);
  std::vector<double> pmf(5, 0.2);
  expect_fits(test::chi_square_discrete([&d](float u) { return d.sample_discrete(u); }, pmf, kSamples, 25));
}

TEST(Distribution1D, AllZeroFunctionReportsUniformDensity) {
  Distribution1D d(std::vector<float>(5, 0.f));
  EXPECT_EQ(d.integral(), 0.f);
  float pdf = -1.f;
  size_t offset = 99;
  float x = d.sample_continuous(0.5f, &pdf, &offset);
  EXPECT_FLOAT_EQ(x, 0.5f);
  EXPECT_EQ(offset, 2u);
  EXPECT_EQ(pdf, 1.f);
  for (size_t i = 0; i < 5; ++i) EXPECT_FLOAT_EQ(d.discrete_pmf(i), 0.2f);
}

TEST(Distribution1D, SingleNonzeroBinSamplesOnlyThatBinChiSquare) {
  std::vector<float> one_hot = {0.f, 0.f, 0.f, 2.5f, 0.f, 0.f};
  expect_fits(continuous_test(one_hot, 26));
  Distribution1D d(one_hot);
  test::Pcg32 rng(27);
  for (int i = 0; i < 10'000; ++i) {
    float u = rng.next_float(), pmf = 0.f, remapped = -1.f;
    ASSERT_EQ(d.sample_discrete(u, &pmf, &remapped), 3u) << u;
    ASSERT_EQ(pmf, 1.f);
    ASSERT_NEAR(remapped, u, 1e-6f);
  }
}

TEST(Distribution1D, ReportedPdfAndOffsetMatchTheSample) {
  Distribution1D d(kSteps);
  test::Pcg32 rng(28);
  for (int i = 0; i < 100'000; ++i) {
    float pdf = 0.f;
    size_t offset = 0;
    float x = d.sample_continuous(rng.next_float(), &pdf, &offset);
    ASSERT_GE(x, 0.f);
    ASSERT_LT(x, 1.f);
    ASSERT_EQ(offset, size_t(x * kSteps.size()));
    ASSERT_NE(kSteps[offset], 0.f) << "sampled a bin of zero density";
    ASSERT_FLOAT_EQ(pdf, float(step_pdf(kSteps, x)));
  }
}

TEST(Distribution1D, IntegralCdfAndPmfFollowPbrtSemantics) {
  std::vector<float> f = {2.f, -2.f, 0.f, 4.f};  // negative values count by magnitude
  Distribution1D d(f);
  EXPECT_EQ(d.size(), 4u);
  EXPECT_FLOAT_EQ(d.integral(), 2.f);  // (2 + 2 + 0 + 4) / 4
  EXPECT_FLOAT_EQ(d.discrete_pmf(0), 0.25f);
  EXPECT_FLOAT_EQ(d.discrete_pmf(1), 0.25f);
  EXPECT_FLOAT_EQ(d.discrete_pmf(2), 0.f);
  EXPECT_FLOAT_EQ(d.discrete_pmf(3), 0.5f);
  EXPECT_EQ(d.discrete_pmf(4), 0.f);
  // cdf = {0, .25, .5, .5, 1}: u = 0.5 lands past the empty bin 2, at the start of bin 3.
  float pmf = 0.f, remapped = -1.f;
  EXPECT_EQ(d.sample_discrete(0.5f, &pmf, &remapped), 3u);
  EXPECT_FLOAT_EQ(pmf, 0.5f);
  EXPECT_FLOAT_EQ(remapped, 0.f);
  float pdf = 0.f;
  EXPECT_FLOAT_EQ(d.sample_continuous(0.125f, &pdf), 0.125f);  // halfway through bin 0
  EXPECT_FLOAT_EQ(pdf, 1.f);
  EXPECT_LT(d.sample_continuous(OneMinusEpsilon, &pdf), 1.f);
}

TEST(Distribution1D, EmptyDistributionReturnsZeroDensity) {
  Distribution1D d(std::vector<float>{});
  float pdf = -1.f, pmf = -1.f;
  d.sample_continuous(0.3f, &pdf);
  d.sample_discrete(0.3f, &pmf);
  EXPECT_EQ(pdf, 0.f);
  EXPECT_EQ(pmf, 0.f);
  EXPECT_EQ(Distribution1D().size(), 0u);
}

}  // namespace
}  // namespace penumbra
