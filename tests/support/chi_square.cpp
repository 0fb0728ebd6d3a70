#include "support/chi_square.h"

#include "support/pcg32.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

namespace penumbra::test {

std::string ChiSquareResult::summary() const {
  return fmt::format("chi2 = {:.2f}, dof = {}, p = {:.4g}, pdf integral = {:.6f}, invalid = {:.3g}, "
                     "pooled cells = {}{}{}",
                     statistic, dof, p_value, pdf_integral, invalid_fraction, pooled_cells,
                     failure.empty() ? "" : ", FAILED: ", failure);
}

double sidak_alpha(double alpha, int num_tests) {
  return 1.0 - std::pow(1.0 - alpha, 1.0 / double(num_tests));
}

// ---- Incomplete gamma ------------------------------------------------------------------------------
// P(a, x) by its power series converges fast for x < a + 1; Q(a, x) by its continued fraction
// (evaluated with the modified Lentz method) converges fast beyond. Computing each tail directly
// keeps tiny p-values accurate instead of losing them to 1 - P.

namespace {

constexpr double kEpsilon = 1e-15;
constexpr double kTiny = 1e-300;  // keeps Lentz's denominators away from zero
constexpr int kMaxIterations = 100000;

// x^a e^-x / Gamma(a), the common prefactor, computed in logs to survive large a and x.
double gamma_prefactor(double a, double x) { return std::exp(a * std::log(x) - x - std::lgamma(a)); }

double gamma_p_series(double a, double x) {
  double term = 1.0 / a, sum = term;
  for (int n = 1; n < kMaxIterations; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::abs(term) < std::abs(sum) * kEpsilon) break;
  }
  return sum * gamma_prefactor(a, x);
}

double gamma_q_continued_fraction(double a, double x) {
  // Q = prefactor * 1/(x+1-a- 1(1-a)/(x+3-a- 2(2-a)/(x+5-a- ...)))
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < kMaxIterations; ++i) {
    double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < kEpsilon) break;
  }
  return h * gamma_prefactor(a, x);
}

}  // namespace

double regularized_gamma_p(double a, double x) {
  if (x <= 0.0) return 0.0;
  return x < a + 1.0 ? gamma_p_series(a, x) : 1.0 - gamma_q_continued_fraction(a, x);
}

double regularized_gamma_q(double a, double x) {
  if (x <= 0.0) return 1.0;
  return x < a + 1.0 ? 1.0 - gamma_p_series(a, x) : gamma_q_continued_fraction(a, x);
}

double chi_square_p_value(double statistic, int dof) {
  return regularized_gamma_q(0.5 * dof, 0.5 * statistic);
}

// ---- The statistic -------------------------------------------------------------------------------

ChiSquareResult chi_square_from_counts(std::span<const double> observed, std::span<const double> expected,
                                       double n_samples, double min_expected) {
  ChiSquareResult r;
  std::vector<size_t> order(expected.size());
  std::iota(order.begin(), order.end(), size_t(0));
  // Visiting cells by increasing expectation lets the low ones be pooled together first.
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return expected[a] < expected[b]; });

  double pool_observed = 0.0, pool_expected = 0.0;
  int cells = 0;
  for (size_t i : order) {
    double o = observed[i], e = expected[i];
    if (!(e >= 0.0)) {
      r.failure = fmt::format("cell {} has an invalid expected count {}", i, e);
      return r;
    }
    if (e == 0.0) {
      if (o > n_samples * 1e-5) {
        r.failure = fmt::format("{} samples in cell {} where the pdf is zero", o, i);
        return r;
      }
      continue;
    }
    if (e < min_expected || (pool_expected > 0.0 && pool_expected < min_expected)) {
      pool_observed += o;
      pool_expected += e;
      ++r.pooled_cells;
      continue;
    }
    r.statistic += (o - e) * (o - e) / e;
    ++cells;
  }
  if (r.pooled_cells > 0) {
    r.statistic += (pool_observed - pool_expected) * (pool_observed - pool_expected) / pool_expected;
    ++cells;
  }
  // The expected counts are fully specified (no fitted parameters), so only the total is constrained.
  r.dof = cells - 1;
  if (r.dof < 1) {
    r.failure = fmt::format("only {} usable cell(s): refine the histogram", cells);
    return r;
  }
  r.p_value = chi_square_p_value(r.statistic, r.dof);
  return r;
}

// ---- Integrating the pdf over cells ---------------------------------------------------------------

namespace {

// 4-point Gauss-Legendre per axis: exact for polynomials up to degree 7 in each variable, and it never
// evaluates on a cell's edges, where pdfs are often discontinuous (cone and triangle boundaries, hemispheres).
constexpr double kNodes[4] = {-0.86113631159405257522, -0.33998104358485626480, 0.33998104358485626480,
                              0.86113631159405257522};
constexpr double kWeights[4] = {0.34785484513745385737, 0.65214515486254614263, 0.65214515486254614263,
                                0.34785484513745385737};

struct Box {
  double x0, x1, y0, y1;
};

class CellIntegrator {
 public:
  CellIntegrator(std::function<double(double, double)> f, int max_refinements)
      : f_(std::move(f)), max_refinements_(max_refinements) {}

  double integrate(const Box& b) { return refine(b, gauss_legendre(b), max_refinements_); }
  const std::string& error() const { return error_; }

 private:
  double eval(double x, double y) {
    double v = f_(x, y);
    if (!(v >= 0.0) || std::isinf(v)) {
      if (error_.empty()) error_ = fmt::format("pdf is {} at ({}, {})", v, x, y);
      return 0.0;
    }
    return v;
  }

  double gauss_legendre(const Box& b) {
    double cx = 0.5 * (b.x0 + b.x1), hx = 0.5 * (b.x1 - b.x0);
    double cy = 0.5 * (b.y0 + b.y1), hy = 0.5 * (b.y1 - b.y0);
    double sum = 0.0;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) sum += kWeights[i] * kWeights[j] * eval(cx + hx * kNodes[i], cy + hy * kNodes[j]);
    return sum * hx * hy;
  }

  // Adaptive: accept the 2x2 refinement when it agrees with the whole-cell estimate, else recurse.
  // Only cells crossed by a discontinuity go deep, so the cost stays near one rule per cell.
  double refine(const Box& b, double whole, int depth) {
    double xm = 0.5 * (b.x0 + b.x1), ym = 0.5 * (b.y0 + b.y1);
    Box q[4] = {{b.x0, xm, b.y0, ym}, {xm, b.x1, b.y0, ym}, {b.x0, xm, ym, b.y1}, {xm, b.x1, ym, b.y1}};
    double parts[4], sum = 0.0;
    for (int k = 0; k < 4; ++k) sum += parts[k] = gauss_legendre(q[k]);
    if (depth <= 0 || std::abs(sum - whole) <= 1e-7 * std::abs(sum) + 1e-13) return sum;
    sum = 0.0;
    for (int k = 0; k < 4; ++k) sum += refine(q[k], parts[k], depth - 1);
    return sum;
  }

  std::function<double(double, double)> f_;
  int max_refinements_;
  std::string error_;
};

constexpr double kTwoPi = 6.28318530717958647692;

Vec3 direction(double z, double phi) {
  double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return Vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z));
}

// Draws the samples; `bin` maps one valid sample to a cell index or returns a failure message.
template <typename Sample, typename Bin>
std::string draw(const Sample& sample, const Bin& bin, int n_samples, uint64_t seed,
                 std::vector<double>& counts, int& invalid) {
  Pcg32 rng(seed);
  invalid = 0;
  for (int n = 0; n < n_samples; ++n) {
    Vec2 u(rng.next_float(), rng.next_float());
    float uc = rng.next_float();
    auto s = sample(u, uc);
    if (!s) {
      ++invalid;
      continue;
    }
    std::string problem;
    long cell = bin(*s, problem);
    if (!problem.empty()) return problem;
    counts[size_t(cell)] += 1.0;
  }
  return "";
}

ChiSquareResult finish(std::vector<double>& observed, std::vector<double>& probability, int n_samples,
                       int invalid, const std::string& sample_problem, const std::string& pdf_problem) {
  ChiSquareResult r;
  if (sample_problem.empty() && pdf_problem.empty()) {
    std::vector<double> expected(probability.size());
    for (size_t i = 0; i < probability.size(); ++i) expected[i] = probability[i] * n_samples;
    r = chi_square_from_counts(observed, expected, n_samples);
  } else {
    r.failure = !sample_problem.empty() ? sample_problem : pdf_problem;
  }
  r.pdf_integral = std::accumulate(probability.begin(), probability.end(), 0.0);
  r.invalid_fraction = double(invalid) / n_samples;
  return r;
}

}  // namespace

ChiSquareResult chi_square_sphere(const SphereSampler& sample, const SphereDensity& pdf, int n_samples,
                                  int theta_bins, int phi_bins, uint64_t seed, const SphereChart& chart) {
  const double z_min = chart.z_min;
  const bool has_rest = z_min > -1.0;  // the part of the sphere below the cap, as one cell
  const size_t grid = size_t(theta_bins) * size_t(phi_bins);
  std::vector<double> observed(grid + (has_rest ? 1 : 0), 0.0);

  auto bin = [&](const Vec3& w, std::string& problem) -> long {
    if (!is_finite(w)) {
      problem = fmt::format("non-finite direction ({}, {}, {})", w.x, w.y, w.z);
      return 0;
    }
    double len = std::sqrt(double(w.x) * w.x + double(w.y) * w.y + double(w.z) * w.z);
    if (std::abs(len - 1.0) > 1e-3) {
      problem = fmt::format("direction ({}, {}, {}) is not unit length ({})", w.x, w.y, w.z, len);
      return 0;
    }
    double z = std::clamp(w.z / len, -1.0, 1.0);
    if (z < z_min) return long(grid);
    double phi = std::atan2(double(w.y), double(w.x));
    if (phi < 0.0) phi += kTwoPi;
    int i = std::min(int((z - z_min) / (1.0 - z_min) * theta_bins), theta_bins - 1);
    int j = std::min(int(phi / kTwoPi * phi_bins), phi_bins - 1);
    return long(i) * phi_bins + j;
  };
  int invalid = 0;
  std::string sample_problem = draw(sample, bin, n_samples, seed, observed, invalid);

  // dω = d(cos θ) dφ, so integrating over (z, φ) needs no Jacobian.
  CellIntegrator integrator([&](double z, double phi) { return pdf(direction(z, phi)); },
                            chart.max_refinements);
  std::vector<double> probability(observed.size(), 0.0);
  double dz = (1.0 - z_min) / theta_bins, dphi = kTwoPi / phi_bins;
  for (int i = 0; i < theta_bins; ++i)
    for (int j = 0; j < phi_bins; ++j)
      probability[size_t(i) * phi_bins + j] =
          integrator.integrate({z_min + i * dz, z_min + (i + 1) * dz, j * dphi, (j + 1) * dphi});
  if (has_rest) {
    constexpr int kRestStrips = 16;
    double rz = (z_min + 1.0) / kRestStrips;
    for (int i = 0; i < kRestStrips; ++i)
      for (int j = 0; j < phi_bins; ++j)
        probability[grid] += integrator.integrate({-1.0 + i * rz, -1.0 + (i + 1) * rz, j * dphi, (j + 1) * dphi});
  }
  return finish(observed, probability, n_samples, invalid, sample_problem, integrator.error());
}

ChiSquareResult chi_square_plane(const PlaneSampler& sample, const PlaneDensity& pdf, int n_samples,
                                 int x_bins, int y_bins, uint64_t seed, const PlaneRect& rect) {
  const size_t grid = size_t(x_bins) * size_t(y_bins);
  // One extra cell for samples outside the rectangle, where the pdf is zero by contract.
  std::vector<double> observed(grid + 1, 0.0);
  const double w = rect.x1 - rect.x0, h = rect.y1 - rect.y0;

  auto bin = [&](const Vec2& p, std::string& problem) -> long {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      problem = fmt::format("non-finite point ({}, {})", p.x, p.y);
      return 0;
    }
    double x = (p.x - rect.x0) / w, y = (p.y - rect.y0) / h;
    if (x < 0.0 || x > 1.0 || y < 0.0 || y > 1.0) return long(grid);
    int i = std::min(int(x * x_bins), x_bins - 1);
    int j = std::min(int(y * y_bins), y_bins - 1);
    return long(j) * x_bins + i;
  };
  int invalid = 0;
  std::string sample_problem = draw(sample, bin, n_samples, seed, observed, invalid);

  CellIntegrator integrator([&](double x, double y) { return pdf(Vec2(float(x), float(y))); },
                            rect.max_refinements);
  std::vector<double> probability(observed.size(), 0.0);
  double dx = w / x_bins, dy = h / y_bins;
  for (int j = 0; j < y_bins; ++j)
    for (int i = 0; i < x_bins; ++i)
      probability[size_t(j) * x_bins + i] = integrator.integrate(
          {rect.x0 + i * dx, rect.x0 + (i + 1) * dx, rect.y0 + j * dy, rect.y0 + (j + 1) * dy});
  return finish(observed, probability, n_samples, invalid, sample_problem, integrator.error());
}

ChiSquareResult chi_square_discrete(const std::function<std::optional<size_t>(float u)>& sample,
                                    std::span<const double> pmf, int n_samples, uint64_t seed) {
  // One extra cell for out-of-range indices, which have probability zero.
  std::vector<double> observed(pmf.size() + 1, 0.0);
  std::vector<double> probability(pmf.begin(), pmf.end());
  probability.push_back(0.0);
  Pcg32 rng(seed);
  int invalid = 0;
  for (int n = 0; n < n_samples; ++n) {
    auto s = sample(rng.next_float());
    if (!s) {
      ++invalid;
      continue;
    }
    observed[std::min(*s, pmf.size())] += 1.0;
  }
  std::string pdf_problem;
  for (size_t i = 0; i < pmf.size(); ++i)
    if (!(pmf[i] >= 0.0) && pdf_problem.empty()) pdf_problem = fmt::format("pmf[{}] = {}", i, pmf[i]);
  return finish(observed, probability, n_samples, invalid, "", pdf_problem);
}

}  // namespace penumbra::test
