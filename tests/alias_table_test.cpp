// The alias table (core/src/util/alias_table.h) that picks the scene's lights by power: chi-square tests
// against the pmf it reports, with a negative control; an exact count of every u of a float grid;
// zero weights never drawn; and the scene's sample_light() against its light_pmf().
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "scene/scene_builder.h"
#include "support/chi_square.h"
#include "support/pcg32.h"
#include "util/alias_table.h"

#include <penumbra/light.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace penumbra {
namespace {

// Chi-square tests in this file that are expected to pass; Šidák keeps the file's family-wise false
// alarm rate at 1 % (the seeds are fixed, so the outcome is deterministic).
constexpr int kChiSquareTests = 4;
const double kAlpha = test::sidak_alpha(0.01, kChiSquareTests);
constexpr int kSamples = 1'000'000;

const std::vector<float> kSteps = {1.f, 3.f, 0.f, 0.5f, 7.f, 2.f, 0.f, 4.f};  // sum 17.5

std::vector<double> pmf_of(const std::vector<float>& w) {
  double sum = 0.0;
  for (float v : w) sum += v;
  std::vector<double> pmf;
  for (float v : w) pmf.push_back(v / sum);
  return pmf;
}

void expect_fits(const test::ChiSquareResult& r, const char* what) {
  std::printf("[ chi2     ] %s: %s\n", what, r.summary().c_str());
  EXPECT_TRUE(r.passes(kAlpha)) << what << ": " << r.summary() << " (alpha = " << kAlpha << ")";
}

TEST(AliasTable, SamplesMatchTheWeightsChiSquare) {
  AliasTable t(kSteps);
  expect_fits(test::chi_square_discrete([&t](float u) { return t.sample(u); }, pmf_of(kSteps), kSamples, 31),
              "eight weights with two zeros");
}

// A thousand weights spread over eight decades: most bins are topped up by an alias.
TEST(AliasTable, ManyWeightsOverEightDecadesChiSquare) {
  test::Pcg32 rng(32);
  std::vector<float> w(1000);
  for (float& v : w) v = std::pow(10.f, -8.f * rng.next_float());
  AliasTable t(w);
  expect_fits(test::chi_square_discrete([&t](float u) { return t.sample(u); }, pmf_of(w), kSamples, 33),
              "1000 weights over eight decades");
}

// Negative control: the same samples against a pmf with 1 % of the largest item's probability moved
// to another item must fail (8 standard deviations at 10^6 samples), as must a pmf that misses an
// item the table draws.
TEST(AliasTable, ChiSquareRejectsAOnePercentShift) {
  AliasTable t(kSteps);
  auto sample = [&t](float u) { return t.sample(u); };
  std::vector<double> shifted = pmf_of(kSteps);
  shifted[7] += 0.01 * shifted[4];
  shifted[4] *= 0.99;
  EXPECT_FALSE(test::chi_square_discrete(sample, shifted, kSamples, 31).passes(kAlpha));
  std::vector<double> missing = pmf_of(kSteps);
  missing[5] += missing[1];
  missing[1] = 0.0;
  EXPECT_FALSE(test::chi_square_discrete(sample, missing, kSamples, 31).passes(kAlpha));
}

// Every u = k / 2^24 of [0, 1) once: each item's count is its probability times 2^24, up to the
// rounding of the bins' edges (a couple of grid steps per edge, and an item has at most n + 1 edges).
TEST(AliasTable, EveryGridPointCountsExactly) {
  for (const std::vector<float>& w : {kSteps, std::vector<float>{1.f, 1e-3f, 5.f}, std::vector<float>{2.f}}) {
    AliasTable t(w);
    const uint32_t steps = 1u << 24;
    std::vector<double> count(w.size(), 0.0);
    for (uint32_t k = 0; k < steps; ++k) count[t.sample(float(k) * 0x1p-24f)] += 1.0;
    std::vector<double> pmf = pmf_of(w);
    const double tolerance = 2.0 * double(w.size() + 1);
    for (size_t i = 0; i < w.size(); ++i) {
      EXPECT_NEAR(count[i], pmf[i] * steps, tolerance) << "item " << i << " of " << w.size();
      EXPECT_FLOAT_EQ(t.pmf(i), float(pmf[i]));
    }
  }
}

// Zero weights at the start, inside and at the end, for 1 to 12 items: a fine sweep of u never
// draws one, every index is in range, and the pmfs sum to 1.
TEST(AliasTable, ZeroWeightsAreNeverDrawn) {
  for (size_t n = 2; n <= 12; ++n) {
    std::vector<float> w(n);
    for (size_t i = 0; i < n; ++i) w[i] = ((i == 0 && n > 3) || i % 3 == 1 || i + 1 == n) ? 0.f : 1.f + float(i % 4);
    AliasTable t(w);
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i) sum += t.pmf(i);
    EXPECT_NEAR(sum, 1.0, 1e-6) << n;
    for (int k = 0; k < 200000; ++k) {
      float u = std::min(float(k) / 200000.f, OneMinusEpsilon);
      size_t i = t.sample(u);
      ASSERT_LT(i, n) << "n " << n << " u " << u;
      ASSERT_GT(w[i], 0.f) << "n " << n << " u " << u;
    }
    ASSERT_LT(t.sample(OneMinusEpsilon), n);
  }
}

// No usable weight (all zero, negative, NaN, or a sum that overflows): every item equally likely.
TEST(AliasTable, WithoutUsableWeightsEveryItemIsEquallyLikelyChiSquare) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  AliasTable zeros(std::vector<float>{0.f, -1.f, nan, 0.f, 0.f});
  for (size_t i = 0; i < 5; ++i) EXPECT_FLOAT_EQ(zeros.pmf(i), 0.2f);
  EXPECT_EQ(zeros.pmf(5), 0.f);
  expect_fits(test::chi_square_discrete([&zeros](float u) { return zeros.sample(u); },
                                        std::vector<double>(5, 0.2), kSamples, 34),
              "no positive weight");
  AliasTable huge(std::vector<float>{3e38f, 3e38f, 3e38f});
  for (size_t i = 0; i < 3; ++i) EXPECT_FLOAT_EQ(huge.pmf(i), 1.f / 3.f);
  // A negative or NaN weight beside positive ones counts as zero.
  AliasTable mixed(std::vector<float>{-2.f, 1.f, nan, 3.f});
  EXPECT_EQ(mixed.pmf(0), 0.f);
  EXPECT_EQ(mixed.pmf(2), 0.f);
  EXPECT_FLOAT_EQ(mixed.pmf(3), 0.75f);
  EXPECT_EQ(AliasTable().pmf(0), 0.f);
}

// The scene's light choice: three area lights of power 1, 2 and 5 (two triangles each, powers spread
// by area) and a point light of power 2. sample_light() must pick each light with the probability
// light_pmf() reports, and that must be its share of the total power.
TEST(AliasTable, SceneSamplesLightsByPowerChiSquare) {
  static Registry registry(Registry::default_search_dirs());
  std::string world = "WorldBegin\n";
  const char* powers[] = {"1", "2", "5"};
  for (int k = 0; k < 3; ++k)
    world += std::string("AttributeBegin\nAreaLightSource \"diffuse\" \"float power\" [ ") + powers[k] +
             " ]\nTranslate " + std::to_string(3 * k) +
             " 0 0\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0  2 0 0  2 1 0  0 1 0 ] \"integer indices\" [ 0 1 2  0 2 3 ]\n"
             "AttributeEnd\n";
  world += "LightSource \"point\" \"float power\" [ 2 ]\n";
  SceneDescription description = parse_scene_string(world, "lights.pbrt");
  BuiltScene b = build_scene(description, registry);
  const EmbreeScene& scene = *b.scene;
  std::span<const Light* const> lights = scene.lights();
  ASSERT_EQ(lights.size(), 7u);
  std::vector<double> pmf;
  double total = 0.0;
  for (const Light* l : lights) total += luminance(l->power());
  EXPECT_NEAR(total, 10.0, 1e-3);
  for (const Light* l : lights) {
    pmf.push_back(scene.light_pmf(l));
    EXPECT_NEAR(pmf.back(), luminance(l->power()) / total, 1e-6);
  }
  auto sample = [&](float u) -> std::optional<size_t> {
    std::optional<SampledLight> s = scene.sample_light(u);
    if (!s) return std::nullopt;
    EXPECT_EQ(s->pmf, scene.light_pmf(s->light));
    return size_t(s->light->index());
  };
  expect_fits(test::chi_square_discrete(sample, pmf, kSamples, 35), "a scene's seven lights");
}

}  // namespace
}  // namespace penumbra
