// Spectral transport's building blocks (penumbra/spectrum.h, core/src/spectra/sigmoid_fit.*,
// rgb_to_spectrum_table.*): colours become smooth spectra with the same colour, wavelengths are
// drawn with the density they claim, and the film's conversion averages an emitter's spectrum back
// to its colour. The colour of a spectrum is checked by the runtime's exact integration
// (spectra::reflectance_to_rgb), not by the fitter's own quadrature.
#include <gtest/gtest.h>

#include <penumbra/spectrum.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "spectra/rgb_to_spectrum_table.h"
#include "spectra/sigmoid_fit.h"
#include "spectra/spectrum.h"
#include "support/chi_square.h"
#include "support/pcg32.h"

namespace penumbra {
namespace {

// The colour of a sigmoid spectrum lit by D65, integrated exactly as the scene loader integrates a
// measured spectrum (its samples every 0.5 nm, linear in between).
Rgb colour_of(const spectra::SigmoidCoefficients& c) {
  std::vector<double> lambda, value;
  for (double l = spectra::kLambdaMin; l <= spectra::kLambdaMax; l += 0.5) {
    lambda.push_back(l);
    value.push_back(spectra::sigmoid_spectrum(c, static_cast<float>(l)));
  }
  return spectra::reflectance_to_rgb(spectra::Spectrum(lambda, value));
}

float max_abs_diff(const Rgb& a, const Rgb& b) { return max_component(glm::abs(a - b)); }

TEST(SpectralUpsampling, TableColoursComeBackAsTheirColour) {
  const auto& table = spectra::RgbToSpectrumTable::built_in();
  test::Pcg32 rng(11);
  float worst = 0.f;
  for (int i = 0; i < 400; ++i) {
    Rgb rgb(rng.next_float(), rng.next_float(), rng.next_float());
    if (i % 4 == 0) rgb[i % 3] = 0.f;        // on the gamut's faces too
    if (i % 7 == 0) rgb = rgb / max_component(rgb);  // and at full brightness
    worst = std::max(worst, max_abs_diff(colour_of(table(rgb.r, rgb.g, rgb.b)), rgb));
  }
  // Interpolating the coefficients between grid colours costs a little; 64^3 nodes keep it small.
  std::printf("largest colour difference over 400 colours: %.2e\n", worst);
  EXPECT_LT(worst, 4e-3f);
  // Saturated primaries, the hardest colours (their spectra are steps).
  for (Rgb rgb : {Rgb(1, 0, 0), Rgb(0, 1, 0), Rgb(0, 0, 1), Rgb(1, 0.379f, 0.013f), Rgb(0.63f, 0.065f, 0.05f)})
    EXPECT_LT(max_abs_diff(colour_of(table(rgb.r, rgb.g, rgb.b)), rgb), 4e-3f)
        << rgb.r << " " << rgb.g << " " << rgb.b;
}

TEST(SpectralUpsampling, FitReachesTheColourAtGridPoints) {
  for (Rgb rgb : {Rgb(0.8f, 0.3f, 0.01f), Rgb(0.1f, 0.9f, 0.4f), Rgb(0.05f, 0.02f, 0.7f)}) {
    spectra::SigmoidCoefficients c{0.f, 0.f, 0.f};
    double lab_error = spectra::fit_sigmoid(glm::dvec3(rgb), c);
    EXPECT_LT(lab_error, 1e-3);
    EXPECT_LT(max_abs_diff(colour_of(c), rgb), 5e-4f);
  }
}

TEST(SpectralUpsampling, GreysAreConstantsToFloatPrecision) {
  const auto& table = spectra::RgbToSpectrumTable::built_in();
  for (float v : {0.f, 0.02f, 0.5f, 0.73f, 1.f}) {
    spectra::SigmoidCoefficients c = table(v, v, v);
    for (float l : {360.f, 455.5f, 600.f, 830.f}) EXPECT_NEAR(spectra::sigmoid_spectrum(c, l), v, 2e-6f * v);
  }
  SampledWavelengths w = SampledWavelengths::sample(0.3f);
  Rgb eta = w.unbounded(Rgb(1.5f));
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(eta[i], 1.5f, 1e-6f);
  // Reflectances stay in [0, 1] wherever they are evaluated.
  Rgb a = w.albedo(Rgb(1.f, 0.f, 0.f));
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(a[i] >= 0.f && a[i] <= 1.f);
}

TEST(SpectralUpsampling, WavelengthsAreDrawnWithTheirDensity) {
  // 94 cells of 5 nm; each of the three stratified wavelengths is counted.
  const int cells = 94, n = 300'000;
  std::vector<double> observed(cells, 0.0), expected(cells, 0.0);
  test::Pcg32 rng(5);
  for (int s = 0; s < n; ++s) {
    SampledWavelengths w = SampledWavelengths::sample(rng.next_float());
    for (int i = 0; i < 3; ++i) {
      float l = w.lambda(i);
      ASSERT_TRUE(l >= 360.f && l <= 830.f);
      observed[std::min(cells - 1, static_cast<int>((l - 360.f) / 5.f))] += 1.0;
    }
  }
  for (int c = 0; c < cells; ++c) {
    double sum = 0.0;  // integral of pdf over the cell, 0.05 nm midpoint rule
    for (int k = 0; k < 100; ++k) sum += SampledWavelengths::pdf(360.f + 5.f * c + 0.05f * (k + 0.5f)) * 0.05;
    expected[c] = sum * 3.0 * n;
  }
  test::ChiSquareResult r = test::chi_square_from_counts(observed, expected, 3.0 * n);
  EXPECT_GT(r.p_value, 1e-3) << "chi^2 " << r.statistic << " dof " << r.dof;
  double total = 0.0;
  for (double e : expected) total += e;
  EXPECT_NEAR(total / (3.0 * n), 1.0, 1e-4);  // the density integrates to 1
}

// Mean over wavelengths of to_rgb(f(w)) and its standard error, per channel.
template <class F>
void mean_colour(F f, int n, Rgb* mean, Rgb* stderr_out) {
  glm::dvec3 sum(0.0), sum2(0.0);
  test::Pcg32 rng(3);
  for (int s = 0; s < n; ++s) {
    SampledWavelengths w = SampledWavelengths::sample(rng.next_float());
    glm::dvec3 c(w.to_rgb(f(w)));
    sum += c, sum2 += c * c;
  }
  glm::dvec3 m = sum / double(n);
  *mean = Rgb(m);
  *stderr_out = Rgb(glm::sqrt(glm::max(sum2 / double(n) - m * m, glm::dvec3(0.0)) / double(n)));
}

TEST(SpectralUpsampling, FilmTurnsAnEmittersSpectrumBackIntoItsColour) {
  const int n = 200'000;
  for (Rgb c : {Rgb(1.f), Rgb(17.f, 12.f, 4.f), Rgb(0.2f, 0.9f, 0.1f)}) {
    Rgb mean, se;
    mean_colour([&](const SampledWavelengths& w) { return w.illuminant(c); }, n, &mean, &se);
    for (int i = 0; i < 3; ++i) {
      float tol = 4.f * se[i] + 2e-3f * c[i];  // 4 standard errors, plus the table's interpolation
      EXPECT_NEAR(mean[i], c[i], tol) << "channel " << i;
      // Negative control: an emitter 2 % brighter is told apart.
      EXPECT_GT(std::abs(1.02f * mean[i] - c[i]), tol) << "channel " << i;
    }
  }
}

TEST(SpectralUpsampling, ReflectanceUnderWhiteLightKeepsItsColour) {
  const int n = 200'000;
  const Rgb r(1.f, 0.379f, 0.013f);  // the coffee scene's orange plastic
  Rgb mean, se;
  mean_colour([&](const SampledWavelengths& w) { return w.illuminant(Rgb(1.f)) * w.albedo(r); }, n, &mean, &se);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(mean[i], r[i], 4.f * se[i] + 4e-3f) << "channel " << i;
  // The spectral effect the transport exists for: the square of the spectrum is not the square of
  // the colour (red below 1 over part of the red matching function), so two bounces off it are
  // darker in red than RGB products say.
  Rgb mean2, se2;
  mean_colour([&](const SampledWavelengths& w) { Rgb a = w.albedo(r); return w.illuminant(Rgb(1.f)) * a * a; }, n,
              &mean2, &se2);
  EXPECT_LT(mean2.r, r.r * r.r - 10.f * se2.r);
}

}  // namespace
}  // namespace penumbra
