// Chi-square goodness-of-fit tests for samplers: does a sampling routine draw from the density its pdf
// function reports? Reused for warps, BSDFs, lights and environment maps (docs/algorithms.md, "Chi-square tests of sampling routines").
//
// Recipe (pbrt-v4 / Mitsuba 3): histogram N samples over cells of the domain, integrate the pdf over
// each cell to get expected counts, pool cells expecting fewer than 5 samples, and compare with
// Pearson's statistic. Samples in a cell the pdf says is empty fail at once. A suite running m tests
// checks each p-value against the Šidák-corrected level sidak_alpha(0.01, m).
#pragma once

#include <penumbra/math.h>

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>

namespace penumbra::test {

struct ChiSquareResult {
  double statistic = 0.0;       // Pearson's chi^2 over the (pooled) cells
  int dof = 0;                  // cells used - 1
  double p_value = 0.0;         // P(chi^2_dof >= statistic) if the sampler matches the pdf
  std::string failure;          // set when the test failed outright (impossible samples, bad pdf)
  double pdf_integral = 0.0;    // integral of the pdf over the whole domain: should be ~1
  double invalid_fraction = 0.0;  // samples the sampler declined (std::nullopt)
  int pooled_cells = 0;         // low-expectation cells merged into one

  bool passes(double alpha) const { return failure.empty() && p_value >= alpha; }
  /// One line for test failure messages.
  std::string summary() const;
};

/// Per-test significance level that keeps the family-wise level at `alpha` over `num_tests` tests.
double sidak_alpha(double alpha, int num_tests);

/// Regularized incomplete gamma functions P(a, x) and Q(a, x) = 1 - P(a, x), for a > 0, x >= 0.
double regularized_gamma_p(double a, double x);
double regularized_gamma_q(double a, double x);
/// Upper tail of the chi-square distribution with `dof` degrees of freedom.
double chi_square_p_value(double statistic, int dof);

/// The statistic itself, from observed and expected counts per cell (same length). Cells with
/// expectation 0 are skipped unless they hold more than n_samples * 1e-5 samples, which fails the test
/// (a little leniency for round-off, as in pbrt).
ChiSquareResult chi_square_from_counts(std::span<const double> observed, std::span<const double> expected,
                                       double n_samples, double min_expected = 5.0);

/// A sampler under test: maps uniform numbers (u, uc) to a point, or std::nullopt for "no sample"
/// (e.g. an absorbed BSDF sample). Counted in invalid_fraction; the pdf should then integrate to
/// 1 - invalid_fraction.
using SphereSampler = std::function<std::optional<Vec3>(Vec2 u, float uc)>;
using SphereDensity = std::function<double(const Vec3&)>;  // per unit solid angle
using PlaneSampler = std::function<std::optional<Vec2>(Vec2 u, float uc)>;
using PlaneDensity = std::function<double(const Vec2&)>;   // per unit area

struct SphereChart {
  /// Histogram only the cap z >= z_min, for narrow lobes that would otherwise fit in one cell; the
  /// rest of the sphere counts as a single cell.
  double z_min = -1.0;
  /// Depth of adaptive 2x2 refinement when integrating the pdf over a cell (discontinuous pdfs).
  int max_refinements = 6;
};

/// Directions histogrammed over theta_bins x phi_bins cells of equal solid angle (bins uniform in
/// cos(theta) and phi, since d(omega) = d(cos theta) d(phi)). Directions must be unit length.
ChiSquareResult chi_square_sphere(const SphereSampler& sample, const SphereDensity& pdf, int n_samples,
                                  int theta_bins, int phi_bins, uint64_t seed,
                                  const SphereChart& chart = {});

struct PlaneRect {
  double x0 = 0.0, y0 = 0.0, x1 = 1.0, y1 = 1.0;
  int max_refinements = 6;
};

/// Points histogrammed over x_bins x y_bins cells of `rect` (the unit square by default). The pdf
/// must vanish outside the rectangle; samples falling outside it are impossible samples.
ChiSquareResult chi_square_plane(const PlaneSampler& sample, const PlaneDensity& pdf, int n_samples,
                                 int x_bins, int y_bins, uint64_t seed, const PlaneRect& rect = {});

/// A discrete sampler (light selection, Distribution1D::sample_discrete) against its pmf.
ChiSquareResult chi_square_discrete(const std::function<std::optional<size_t>(float u)>& sample,
                                    std::span<const double> pmf, int n_samples, uint64_t seed);

}  // namespace penumbra::test
