// Hierarchical Russian roulette (libs/bidirectional/hrr.*; docs/algorithms.md and docs/hrr.md):
//  1. every leaf's number is marginally U[0,1] (KS per leaf), and the seed's buggy pseudo-code fails;
//  2. culling is conservative: culled and unculled traversals accept exactly the same pairs;
//  3. the mean accepted count is sum_i P(y_i, z);
//  4. sum_accepted g/P is an unbiased estimate of sum_i g;
//  5. the SEL's acceptance region is exactly the ellipsoid of hrr.h, and the SEL matches GGX;
//  6. the stratified minimum keeps its strata for 2^40 leaves where a float b stalls;
//  7. the Embree-built BVH is well formed and identical at 1 and 2 TBB threads;
//  8. make_sel_lobe follows a real GGX conductor lobe around the mirror direction.
//
// The plugin's source is compiled in directly (tests only glob test files), so what is tested is
// what the plugin runs. All randomness is seeded.
#include "hrr.h"

#include <penumbra/microfacet.h>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <vector>

using namespace penumbra;
using namespace penumbra::bdpt;

namespace {

// ---------------------------------------------------------------------------------------------
// Helpers

/// Doubles with 53 random bits, normal deviates and directions from penumbra's PCG32.
class Rand {
 public:
  explicit Rand(uint64_t seed) : pcg_(seed, hash_ints(seed, 0x5eed)) {}
  double uniform() {
    const uint64_t hi = pcg_.next_u32() >> 5, lo = pcg_.next_u32() >> 6;
    return (static_cast<double>(hi) * 67108864.0 + static_cast<double>(lo)) * 0x1p-53;
  }
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  double log_uniform(double a, double b) { return a * std::pow(b / a, uniform()); }
  double normal() {
    const double u = 1.0 - uniform(), v = uniform();
    return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * M_PI * v);
  }
  Vec3d unit() {
    const double z = 1.0 - 2.0 * uniform(), phi = 2.0 * M_PI * uniform();
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
  }
  Vec3 point(double lo, double hi) {
    return Vec3(float(uniform(lo, hi)), float(uniform(lo, hi)), float(uniform(lo, hi)));
  }

 private:
  penumbra::Pcg32 pcg_;
};

Vec3 to_float(const Vec3d& v) { return Vec3(float(v.x), float(v.y), float(v.z)); }

/// A frame around a random axis with a random twist of its tangents.
Frame random_frame(Rand& rng) {
  Frame f(glm::normalize(to_float(rng.unit())));
  const float phi = float(2.0 * M_PI * rng.uniform());
  const Vec3 s = std::cos(phi) * f.s + std::sin(phi) * f.t;
  f.t = glm::cross(f.n, s);
  f.s = s;
  return f;
}

enum class LobeKind { Diffuse, Isotropic, Anisotropic, Narrow };

SelLobe random_lobe(Rand& rng, LobeKind kind) {
  SelLobe lobe;
  lobe.z = rng.point(-1.5, 1.5);
  lobe.frame = random_frame(rng);
  switch (kind) {
    case LobeKind::Diffuse: lobe.alpha_x = lobe.alpha_y = 1.0; break;
    case LobeKind::Isotropic: lobe.alpha_x = lobe.alpha_y = rng.log_uniform(1e-3, 1.0); break;
    case LobeKind::Anisotropic:
      lobe.alpha_x = rng.log_uniform(1e-3, 1.0);
      lobe.alpha_y = rng.log_uniform(1e-3, 1.0);
      break;
    case LobeKind::Narrow:
      lobe.alpha_x = 1e-3;
      lobe.alpha_y = rng.log_uniform(1e-3, 1e-2);
      break;
  }
  lobe.c = rng.log_uniform(1e-2, 1e2);
  const double h = rng.uniform();
  if (h < 0.3) lobe.half_space = lobe.frame.n;                  // reflection around the axis
  else if (h < 0.6) lobe.half_space = to_float(rng.unit());    // any tangent plane
  return lobe;
}

/// A direction inside the lobe: the axis tilted by ~spread alphas.
Vec3d direction_near_axis(Rand& rng, const SelLobe& lobe, double spread) {
  const Vec3d s(lobe.frame.s), t(lobe.frame.t), n(lobe.frame.n);
  return glm::normalize(n + s * (lobe.alpha_x * spread * rng.normal()) + t * (lobe.alpha_y * spread * rng.normal()));
}

/// Kolmogorov's limiting distribution Q(lambda) = P(sqrt(n) D > lambda), with both classical
/// series (the alternating one converges fast for large lambda, the theta-function one for small).
double kolmogorov_q(double lambda) {
  if (lambda <= 0.0) return 1.0;
  if (lambda < 1.18) {
    double sum = 0.0;
    for (int k = 1; k <= 20; ++k) sum += std::exp(-double((2 * k - 1) * (2 * k - 1)) * M_PI * M_PI / (8.0 * lambda * lambda));
    return std::clamp(1.0 - std::sqrt(2.0 * M_PI) / lambda * sum, 0.0, 1.0);
  }
  double sum = 0.0;
  for (int k = 1; k <= 100; ++k) sum += (k % 2 ? 2.0 : -2.0) * std::exp(-2.0 * k * k * lambda * lambda);
  return std::clamp(sum, 0.0, 1.0);
}

/// Sorts numbers in [0, 1) in linear expected time: a counting sort into n equal bins (about one
/// number each if they are near uniform), then a comparison sort inside each bin.
/// Scratch buffers are reused across calls: the marginal test sorts ~150 arrays of 1e5 numbers.
void sort_unit_interval(std::vector<double>& x) {
  static thread_local std::vector<uint32_t> start, next;
  static thread_local std::vector<double> sorted;
  const size_t n = x.size();
  auto bin = [n](double v) { return std::min(n - 1, size_t(std::max(0.0, v) * double(n))); };
  start.assign(n + 1, 0);
  for (double v : x) ++start[bin(v) + 1];
  for (size_t i = 0; i < n; ++i) start[i + 1] += start[i];
  next.assign(start.begin(), start.end() - 1);
  sorted.resize(n);
  for (double v : x) sorted[next[bin(v)]++] = v;
  for (size_t i = 0; i < n; ++i)
    if (start[i + 1] - start[i] > 1) std::sort(sorted.begin() + start[i], sorted.begin() + start[i + 1]);
  x.swap(sorted);
}

/// One-sample KS test against U[0,1] (Stephens' finite-n correction of the statistic). Sorts x.
double ks_uniform_p_value(std::vector<double>& x) {
  sort_unit_interval(x);
  const double n = double(x.size());
  double d = 0.0;
  for (size_t i = 0; i < x.size(); ++i) d = std::max({d, (double(i) + 1.0) / n - x[i], x[i] - double(i) / n});
  const double en = std::sqrt(n);
  return kolmogorov_q((en + 0.12 + 0.11 / en) * d);
}

double sidak(double alpha, size_t tests) { return 1.0 - std::pow(1.0 - alpha, 1.0 / double(tests)); }

std::vector<Vec3> random_points(Rand& rng, size_t n, double lo = -1.0, double hi = 1.0) {
  std::vector<Vec3> p(n);
  for (auto& v : p) v = rng.point(lo, hi);
  return p;
}

/// The seed's pseudo-code: BOTH children receive the new minimum (child l should keep the old one).
struct BuggyMinimum {
  double xi_min = 0.0, b = 1.0, one_minus_b = 0.0;
  static BuggyMinimum from(const StratifiedMinimum& m) { return {m.xi_min, m.b, m.one_minus_b}; }
  static BuggyMinimum root(double xi, uint64_t n) { return from(StratifiedMinimum::root(xi, n)); }
  struct Children;
  Children split(uint64_t n_other, double xi) const;
};

struct BuggyMinimum::Children {
  BuggyMinimum keeper, other;
};

BuggyMinimum::Children BuggyMinimum::split(uint64_t n_other, double xi) const {
  const auto fresh = from(StratifiedMinimum{xi_min, b, one_minus_b}.other_child(n_other, xi));
  return {fresh, fresh};
}

/// Every leaf's number over `traversals` walks with seeds 0, 1, ...: numbers[vertex][walk].
template <class Minimum>
std::vector<std::vector<double>> leaf_numbers(const LightVertexBvh& bvh, int traversals) {
  std::vector<std::vector<double>> numbers(bvh.vertex_count());
  for (auto& v : numbers) v.reserve(traversals);
  for (int i = 0; i < traversals; ++i) {
    double smallest = 1.0;
    hrr_walk<Minimum>(
        bvh, HrrRandom{hash_ints(uint64_t(i), 77)}, [](const auto&, double) { return false; },
        [&](uint32_t vertex, const auto&, double xi) {
          numbers[vertex].push_back(xi);
          smallest = std::min(smallest, xi);
        });
    // The walk's root minimum is the smallest number of all, by construction (the buggy variant
    // loses it).
    if constexpr (std::is_same_v<Minimum, StratifiedMinimum>) {
      EXPECT_LT(smallest, 1.0 / double(bvh.vertex_count()));
    }
  }
  return numbers;
}

struct KsSummary {
  double min_p = 1.0;
  size_t failures = 0;
};

KsSummary ks_per_leaf(std::vector<std::vector<double>> numbers, double alpha) {
  KsSummary s;
  for (auto& v : numbers) {
    const double p = ks_uniform_p_value(v);
    s.min_p = std::min(s.min_p, p);
    if (p < alpha) ++s.failures;
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
// 1. Marginal uniformity

TEST(HrrStatistics, KolmogorovDistributionMatchesTables) {
  // Critical values of the Kolmogorov distribution at 50 %, 5 % and 1 %.
  EXPECT_NEAR(kolmogorov_q(0.8276), 0.50, 1e-3);
  EXPECT_NEAR(kolmogorov_q(1.3581), 0.05, 1e-3);
  EXPECT_NEAR(kolmogorov_q(1.6276), 0.01, 1e-3);
  // Both series agree where they switch.
  EXPECT_NEAR(kolmogorov_q(1.1799), kolmogorov_q(1.1801), 1e-3);
}

TEST(HrrMarginal, EveryLeafNumberIsUniform) {
  constexpr int kTraversals = 100000;
  for (size_t n : {size_t(13), size_t(64)}) {
    Rand rng(1000 + n);
    const auto points = random_points(rng, n);
    LightVertexBvh bvh;
    bvh.build(points);
    const double alpha = sidak(0.01, n);
    const KsSummary good = ks_per_leaf(leaf_numbers<StratifiedMinimum>(bvh, kTraversals), alpha);
    const KsSummary bad = ks_per_leaf(leaf_numbers<BuggyMinimum>(bvh, kTraversals), alpha);
    std::printf("[hrr] marginal N=%zu: min KS p over leaves %.4f (Sidak alpha %.2e); buggy pseudo-code: min p %.3g, "
                "%zu/%zu leaves fail\n", n, good.min_p, alpha, bad.min_p, bad.failures, n);
    EXPECT_EQ(good.failures, 0u) << "N = " << n << ", min p = " << good.min_p;
    EXPECT_GT(bad.failures, 0u) << "the negative control passed: the KS test has no power";
  }
}

// ---------------------------------------------------------------------------------------------
// 2. Conservativeness

/// A cloud for one lobe: uniform points, points inside the lobe (narrow lobes would otherwise see
/// nothing), a cluster with exact duplicates, points on a plane, and sometimes z itself.
std::vector<Vec3> cloud_for(Rand& rng, const SelLobe& lobe, size_t n) {
  std::vector<Vec3> p;
  p.reserve(n);
  const Vec3d z(lobe.z);
  while (p.size() < n) {
    const double kind = rng.uniform();
    if (kind < 0.45) {
      p.push_back(rng.point(-2.0, 2.0));
    } else if (kind < 0.75) {
      const Vec3d w = direction_near_axis(rng, lobe, rng.log_uniform(0.1, 30.0));
      p.push_back(to_float(z + w * rng.log_uniform(1e-3, 10.0)));
    } else if (kind < 0.85 && !p.empty()) {
      p.push_back(p[size_t(rng.uniform() * double(p.size()))]);  // duplicate
    } else if (kind < 0.97) {
      p.push_back(Vec3(float(rng.uniform(-2, 2)), 0.25f, float(rng.uniform(-2, 2))));  // a flat surface
    } else {
      p.push_back(lobe.z);  // d == 0
    }
  }
  return p;
}

using Pairs = std::vector<std::pair<uint32_t, double>>;

TEST(HrrConservative, CulledAndUnculledTraversalsAcceptTheSamePairs) {
  constexpr int kConfigs = 2000;
  constexpr size_t kPoints = 300;
  LightVertexBvh bvh;
  uint64_t visited_culled = 0, visited_full = 0, accepted_total = 0;
  double ratio_sum = 0.0;
  int partial = 0;  // configurations where some but not all vertices were accepted
  for (int i = 0; i < kConfigs; ++i) {
    Rand rng(5000 + i);
    const SelLobe lobe = random_lobe(rng, LobeKind(i % 4));
    const auto points = cloud_for(rng, lobe, kPoints);
    bvh.build(points);
    double C = rng.log_uniform(1e-5, 1e2) / lobe.c;
    if (i % 50 == 0) C = 1e-30;
    if (i % 50 == 1) C = 1e30;
    const HrrRandom numbers{hash_ints(uint64_t(i), 2)};

    Pairs full, culled;
    HrrTraversalStats full_stats, culled_stats;
    hrr_traverse(bvh, lobe, C, numbers, [&](uint32_t v, double P, double) { full.emplace_back(v, P); }, false, &full_stats);
    hrr_traverse(bvh, lobe, C, numbers, [&](uint32_t v, double P, double) { culled.emplace_back(v, P); }, true, &culled_stats);
    ASSERT_EQ(full, culled) << "configuration " << i;  // same vertices, bit-identical P, same order
    for (const auto& [v, P] : full) ASSERT_EQ(P, hrr_acceptance(lobe, C, points[v]));

    EXPECT_EQ(full_stats.nodes_visited, 2 * kPoints - 1);
    EXPECT_LE(culled_stats.nodes_visited, full_stats.nodes_visited);
    visited_culled += culled_stats.nodes_visited;
    visited_full += full_stats.nodes_visited;
    ratio_sum += double(culled_stats.nodes_visited) / double(full_stats.nodes_visited);
    accepted_total += full.size();
    partial += !full.empty() && full.size() < kPoints;
  }
  const double ratio = double(visited_culled) / double(visited_full);
  std::printf("[hrr] conservative: %d configurations, %d partly accepted, %llu pairs accepted; culled/unculled "
              "node visits %.4f (mean per configuration %.4f)\n",
              kConfigs, partial, (unsigned long long)accepted_total, ratio, ratio_sum / kConfigs);
  EXPECT_GT(partial, kConfigs / 2);  // the comparison is not vacuous
  EXPECT_LT(ratio, 1.0);
}

TEST(HrrConservative, RangeTestKeepsEveryAcceptedPointAtTheBoundary) {
  // Points placed on the boundary of the acceptance region (to float precision), with their own
  // number xi: whenever the leaf test accepts, the box test must keep the point and any box around
  // it. Points 0.1 % outside must mostly be rejected, or the test would be vacuous.
  Rand rng(77);
  size_t accepted = 0, outside = 0, outside_rejected = 0;
  for (int i = 0; i < 400; ++i) {
    const SelLobe lobe = random_lobe(rng, LobeKind(i % 4));
    const double C = rng.log_uniform(1e-3, 1e3) / lobe.c;
    const HrrRange range(lobe, C);
    for (int j = 0; j < 500; ++j) {
      const double xi = j % 50 == 0 ? rng.log_uniform(1e-300, 1e-10) : rng.uniform();
      const Vec3d w = j % 2 ? rng.unit() : direction_near_axis(rng, lobe, rng.log_uniform(0.1, 10.0));
      if (lobe.q(w) == 0.0) continue;
      const double r = std::sqrt(C * lobe.c * lobe.K(w) / xi);  // boundary distance along w
      if (!(r < 1e30)) continue;
      for (double f : {1.0 - 1e-3, 1.0 - 1e-7, 1.0, 1.0 + 1e-7, 1.0 + 1e-3}) {
        const Vec3 y = to_float(Vec3d(lobe.z) + w * (r * f));
        const double P = range.acceptance(y);
        if (xi < P) {
          ++accepted;
          ASSERT_TRUE(range.may_accept(y, y, xi)) << "lobe " << i << " point " << j << " f " << f;
          const Vec3 pad(float(rng.log_uniform(1e-6, 1.0) * r));
          ASSERT_TRUE(range.may_accept(y - pad, y + pad * float(rng.uniform()), xi));
        } else if (f > 1.0 + 1e-4 && P < 1.0) {
          ++outside;
          outside_rejected += !range.may_accept(y, y, xi);
        }
      }
    }
  }
  std::printf("[hrr] boundary: %zu accepted points all kept; %zu/%zu points 0.1%% outside rejected\n", accepted,
              outside_rejected, outside);
  EXPECT_GT(accepted, 100000u);
  EXPECT_GT(double(outside_rejected), 0.99 * double(outside));
}

// ---------------------------------------------------------------------------------------------
// 3. Expected count and 4. unbiasedness

struct Scenario {
  const char* name;
  SelLobe lobe;
  std::vector<Vec3> points;
};

std::vector<Scenario> scenarios(size_t n) {
  std::vector<Scenario> out;
  const char* names[] = {"diffuse", "isotropic GGX 0.1", "anisotropic GGX 0.02 x 0.3", "narrow GGX 1e-3"};
  for (int k = 0; k < 4; ++k) {
    Rand rng(900 + k);
    Scenario s{names[k], random_lobe(rng, LobeKind(k)), {}};
    if (k == 1) s.lobe.alpha_x = s.lobe.alpha_y = 0.1;
    if (k == 2) s.lobe.alpha_x = 0.02, s.lobe.alpha_y = 0.3;
    s.lobe.half_space = s.lobe.frame.n;
    s.points = cloud_for(rng, s.lobe, n);
    out.push_back(std::move(s));
  }
  return out;
}

/// C giving about `target` expected connections.
double calibrate_C(const SelLobe& lobe, std::span<const Vec3> points, double target) {
  double lo = 1e-12, hi = 1e12;
  for (int it = 0; it < 200; ++it) {
    const double mid = std::sqrt(lo * hi);
    double sum = 0.0;
    for (const Vec3& y : points) sum += hrr_acceptance(lobe, mid, y);
    (sum < target ? lo : hi) = mid;
  }
  return lo;
}

TEST(HrrEstimator, MeanAcceptedCountIsTheSumOfP) {
  constexpr int kTraversals = 20000;
  LightVertexBvh bvh;
  for (const Scenario& s : scenarios(500)) {
    bvh.build(s.points);
    const double C = calibrate_C(s.lobe, s.points, 20.0);
    double expected = 0.0;
    for (const Vec3& y : s.points) expected += hrr_acceptance(s.lobe, C, y);
    double sum = 0.0, sum2 = 0.0;
    for (int i = 0; i < kTraversals; ++i) {
      double count = 0.0;
      hrr_traverse(bvh, s.lobe, C, HrrRandom{hash_ints(uint64_t(i), 3)}, [&](uint32_t, double, double) { count += 1.0; });
      sum += count;
      sum2 += count * count;
    }
    const double mean = sum / kTraversals, var = (sum2 - sum * mean) / (kTraversals - 1);
    const double se = std::sqrt(var / kTraversals);
    std::printf("[hrr] expected count %-26s: mean %.4f, sum P %.4f, SE %.4f (%.2f SE)\n", s.name, mean, expected, se,
                (mean - expected) / se);
    EXPECT_NEAR(mean, expected, 3.0 * se) << s.name;
  }
}

TEST(HrrEstimator, RussianRouletteEstimateIsUnbiased) {
  // g: a lobe * 1/d^2 weight with a different shape and width from the SEL (a GGX-like lobe twice as
  // wide, tilted, times a spatial texture), zero where P is zero (behind the half space, d == 0).
  constexpr int kTraversals = 20000;
  LightVertexBvh bvh;
  for (const Scenario& s : scenarios(1000)) {
    bvh.build(s.points);
    const double C = calibrate_C(s.lobe, s.points, 16.0);
    SelLobe shape = s.lobe;
    shape.alpha_x = std::min(1.0, 2.0 * s.lobe.alpha_x);
    shape.alpha_y = std::min(1.0, 1.5 * s.lobe.alpha_y);
    auto g = [&](const Vec3& y) {
      const Vec3d v = Vec3d(y) - Vec3d(s.lobe.z);
      const double d2 = glm::dot(v, v);
      if (d2 == 0.0 || s.lobe.q(v / std::sqrt(d2)) == 0.0) return 0.0;
      return (1.0 + 0.5 * std::sin(3.0 * y.x)) * shape.K(v / std::sqrt(d2)) / d2;
    };
    std::vector<double> gy(s.points.size());
    double exact = 0.0;
    for (size_t i = 0; i < s.points.size(); ++i) exact += gy[i] = g(s.points[i]);
    double sum = 0.0, sum2 = 0.0;
    for (int i = 0; i < kTraversals; ++i) {
      double estimate = 0.0;
      hrr_traverse(bvh, s.lobe, C, HrrRandom{hash_ints(uint64_t(i), 4)},
                   [&](uint32_t v, double P, double) { estimate += gy[v] / P; });
      sum += estimate;
      sum2 += estimate * estimate;
    }
    const double mean = sum / kTraversals, var = (sum2 - sum * mean) / (kTraversals - 1);
    const double se = std::sqrt(var / kTraversals);
    std::printf("[hrr] unbiased %-26s: mean %.6g, exact %.6g, rel. SE %.2e (%.2f SE)\n", s.name, mean, exact,
                se / exact, (mean - exact) / se);
    EXPECT_NEAR(mean, exact, 3.29 * se) << s.name;  // 99.9 % two-sided
  }
}

// ---------------------------------------------------------------------------------------------
// 5. SEL geometry

TEST(HrrSel, RangeBoundaryIsTheEllipsoid) {
  Rand rng(5);
  double worst = 0.0;
  for (int i = 0; i < 300; ++i) {
    const SelLobe lobe = random_lobe(rng, LobeKind(i % 4));
    const double s = rng.log_uniform(1e-3, 1e3);
    const auto e = lobe.range_ellipsoid(s);
    const Vec3d axes[3] = {e.axes.s, e.axes.t, e.axes.n};
    // The double axes are the float frame's to float precision.
    ASSERT_NEAR(glm::dot(e.axes.n, Vec3d(lobe.frame.n)), 1.0, 1e-6);
    ASSERT_NEAR(std::abs(glm::dot(e.axes.s, Vec3d(lobe.frame.s))), 1.0, 1e-6);
    for (int j = 0; j < 400; ++j) {
      const Vec3d w = j % 2 ? rng.unit() : direction_near_axis(rng, lobe, rng.log_uniform(0.01, 30.0));
      const Vec3d p = Vec3d(lobe.z) + w * (s * std::sqrt(lobe.K(w)));
      double sum = 0.0;
      for (int k = 0; k < 3; ++k) sum += std::pow(glm::dot(p - e.centre, axes[k]) / e.semi_axes[k], 2);
      worst = std::max(worst, std::abs(sum - 1.0));
      ASSERT_NEAR(sum, 1.0, 1e-5) << "lobe " << i << " direction " << j;
    }
  }
  std::printf("[hrr] SEL: z + s sqrt(K(w)) w is on the ellipsoid to %.2e\n", worst);
}

TEST(HrrSel, PeakIsOneAndIsotropicLobeIsTheSquaredSphericalLobe) {
  Rand rng(6);
  for (int i = 0; i < 1000; ++i) {
    SelLobe lobe = random_lobe(rng, LobeKind(i % 4));
    EXPECT_NEAR(lobe.K(lobe.frame.n), 1.0, 1e-6);  // float frame: orthonormal to ~1e-7
    // Canonical frame (exact axes): K(v) = 4 a^4 / ((1 - v_z) + a^2 (1 + v_z))^2.
    lobe.frame = Frame();
    EXPECT_DOUBLE_EQ(lobe.K(Vec3d(0, 0, 1)), 1.0);
    const double a = lobe.alpha_x;
    lobe.alpha_y = a;
    const Vec3d v = rng.unit();
    const double expected = 4.0 * std::pow(a, 4) / std::pow((1.0 - v.z) + a * a * (1.0 + v.z), 2);
    EXPECT_NEAR(lobe.K(v), expected, 1e-12 * expected);
  }
  // Diffuse: K == 1 everywhere (a sphere).
  SelLobe sphere;
  for (int i = 0; i < 100; ++i) EXPECT_DOUBLE_EQ(sphere.K(rng.unit()), 1.0);
}

TEST(HrrSel, ApproximatesGgxNearThePeak) {
  // pi ax ay D(m) ~ K(m; ax/2, ay/2): both are 1 / (1 + mx^2/ax^2 + my^2/ay^2)^2 to second order.
  Rand rng(8);
  double worst = 0.0;
  for (auto [ax, ay] : {std::pair{0.05, 0.05}, std::pair{0.05, 0.02}}) {
    const TrowbridgeReitz ggx{float(ax), float(ay)};
    SelLobe lobe;  // canonical frame: axis +z
    lobe.alpha_x = ax / 2;
    lobe.alpha_y = ay / 2;
    for (int i = 0; i < 10000; ++i) {
      const double theta = std::min(ax, ay) / 4 * rng.uniform(), phi = 2 * M_PI * rng.uniform();
      const Vec3d m(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      const double d = M_PI * ax * ay * ggx.D(to_float(m));
      const double rel = std::abs(lobe.K(m) / d - 1.0);
      worst = std::max(worst, rel);
      ASSERT_LT(rel, 0.05) << "alpha " << ax << " x " << ay << " theta " << theta;
    }
  }
  std::printf("[hrr] SEL vs pi a^2 D_GGX within theta < a/4: max relative difference %.2e\n", worst);
}

// ---------------------------------------------------------------------------------------------
// 6. The minimum for huge N

TEST(HrrMinimum, RootMinimumOfTwoToTheFortyIsUniformInItsStratum) {
  constexpr uint64_t kN = uint64_t(1) << 40;
  std::vector<double> scaled;
  for (uint64_t seed = 0; seed < 100000; ++seed) {
    const double xi_min = StratifiedMinimum::root(HrrRandom{seed}(0, kSlotRootMinimum), kN).xi_min;
    ASSERT_GE(xi_min, 0.0);
    ASSERT_LT(xi_min, 0x1p-40);
    scaled.push_back(xi_min * double(kN));
  }
  const double p = ks_uniform_p_value(scaled);
  std::printf("[hrr] root minimum, N = 2^40: KS p of xi_min * N = %.4f\n", p);
  EXPECT_GT(p, 0.01);
}

/// Follows the child that does NOT keep the minimum down a chain of splits of a tree with 2^40
/// leaves; `fraction` of each node's leaves go to that child.
void check_chain(double fraction, int splits) {
  uint64_t n = uint64_t(1) << 40;
  StratifiedMinimum m = StratifiedMinimum::root(0.5, n);
  long double exact = 1.0L - 1.0L / (long double)n;  // 1 - b at the root
  float naive_b = 1.0f / float(n), naive_previous = 1.0f - naive_b;
  int naive_stalls = 0;
  Rand rng(40);
  for (int k = 0; k < splits; ++k) {
    const uint64_t n_other = std::max<uint64_t>(1, uint64_t(std::llround(fraction * double(n))));
    const StratifiedMinimum child = m.other_child(n_other, rng.uniform());
    exact *= 1.0L - 1.0L / (long double)n_other;
    // The fresh minimum lies in its stratum [b, b + (1 - b)/|L_m|] and below the child's b.
    ASSERT_GE(child.xi_min, m.b);
    ASSERT_LE(child.xi_min, m.b + m.one_minus_b / double(n_other));
    ASSERT_LE(child.xi_min, child.b);
    EXPECT_NEAR(child.b + child.one_minus_b, 1.0, 1e-15);
    if (n_other > 1) {
      ASSERT_GT(child.one_minus_b, 0.0) << "split " << k;
      ASSERT_LT(child.one_minus_b, m.one_minus_b) << "split " << k;
      ASSERT_NEAR(child.one_minus_b, double(exact), 1e-12 * double(exact)) << "split " << k;
    } else {
      EXPECT_EQ(child.one_minus_b, 0.0);  // a single leaf has no other numbers
    }
    // The naive float form: b' = b + (1 - b)/|L_m|, and 1 - b taken from it.
    naive_b = naive_b + (1.0f - naive_b) / float(n_other);
    const float naive_one_minus_b = 1.0f - naive_b;
    naive_stalls += n_other > 1 && !(naive_one_minus_b < naive_previous);
    naive_previous = naive_one_minus_b;
    m = child;
    n = n_other;
  }
  std::printf("[hrr] chain of %d splits (fraction %.2f): 1 - b = %.17g; naive float 1 - b stalled on %d splits\n",
              splits, fraction, m.one_minus_b, naive_stalls);
  EXPECT_GT(naive_stalls, 0);
}

TEST(HrrMinimum, FortySplitsKeepTheirStrata) {
  check_chain(0.5, 40);  // balanced: the 40th split reaches a leaf
  check_chain(0.6, 40);  // the other child is the larger one: never a leaf in 40 splits
}

TEST(HrrMinimum, NaiveFloatBoundStallsInADeepChainWhileOursDoesNot) {
  // A caterpillar over 2^40 leaves: each node splits into one leaf (which keeps the minimum) and
  // the rest. Along the rest, b_k = (k + 1)/N and 1 - b_k = (N - k - 1)/N exactly, and the step
  // (1 - b)/|L_m| is 2^-40. A float b in [2^-16, 2^-15) sees that step as half an ulp (ties: every
  // other step is lost, the average survives); from 2^-15 on it is a quarter ulp and b stops.
  constexpr uint64_t kN = uint64_t(1) << 40;
  constexpr uint64_t kSteps = uint64_t(1) << 26;
  StratifiedMinimum m = StratifiedMinimum::root(0.5, kN);
  float naive_b = 1.0f / float(kN);
  uint64_t naive_stalls = 0;
  for (uint64_t k = 0; k < kSteps; ++k) {
    const uint64_t n_other = kN - k - 1;
    const StratifiedMinimum child = m.other_child(n_other, 0.5);
    if (!(child.b > m.b) || !(child.one_minus_b < m.one_minus_b)) FAIL() << "our b stalled at step " << k;
    m = child;
    const float next = naive_b + (1.0f - naive_b) / float(n_other);
    naive_stalls += next == naive_b;
    naive_b = next;
  }
  const double exact_b = double(kSteps + 1) / double(kN), exact_one_minus_b = double(kN - kSteps - 1) / double(kN);
  std::printf("[hrr] caterpillar, 2^26 splits: exact b %.10g, ours %.10g (rel. err %.1e), naive float %.10g "
              "(rel. err %.2f, %llu stalled steps)\n",
              exact_b, m.b, std::abs(m.b / exact_b - 1), double(naive_b), std::abs(naive_b / exact_b - 1),
              (unsigned long long)naive_stalls);
  // Worst-case accumulated rounding over 2^26 steps is 2^26 * 2^-53 ~ 8e-9 relative.
  EXPECT_NEAR(m.b, exact_b, 1e-8 * exact_b);
  EXPECT_NEAR(m.one_minus_b, exact_one_minus_b, 1e-8);
  EXPECT_GT(naive_stalls, kSteps / 4);
  EXPECT_GT(std::abs(naive_b / exact_b - 1), 0.4);
}

// ---------------------------------------------------------------------------------------------
// 7. BVH

void check_structure(const LightVertexBvh& bvh, std::span<const Vec3> points) {
  const size_t n = points.size();
  ASSERT_EQ(bvh.vertex_count(), n);
  ASSERT_EQ(bvh.node_count(), n ? 2 * n - 1 : 0);
  EXPECT_EQ(bvh.memory_bytes(), bvh.node_count() * 32);
  EXPECT_LE(bvh.depth(), LightVertexBvh::kMaxDepth);
  if (n == 0) return;
  EXPECT_EQ(bvh.node(0).count, n);
  std::vector<int> seen(n, 0);
  const auto nodes = bvh.nodes();
  for (size_t i = 0; i < nodes.size(); ++i) {
    const auto& node = nodes[i];
    if (node.is_leaf()) {
      ASSERT_LT(node.vertex(), n);
      ++seen[node.vertex()];
      ASSERT_EQ(std::memcmp(&node.lo, &points[node.vertex()], sizeof(Vec3)), 0);
      ASSERT_EQ(std::memcmp(&node.hi, &points[node.vertex()], sizeof(Vec3)), 0);
      continue;
    }
    ASSERT_GT(node.second_child(), i + 1);
    ASSERT_LT(node.second_child(), nodes.size());
    const auto& a = nodes[i + 1];
    const auto& b = nodes[node.second_child()];
    ASSERT_EQ(node.count, a.count + b.count);
    // The first child's subtree fills exactly the slots before the second child.
    ASSERT_EQ(node.second_child(), i + 2 * a.count);
    for (const auto* child : {&a, &b})
      for (int k = 0; k < 3; ++k) {
        ASSERT_LE(node.lo[k], child->lo[k]);
        ASSERT_GE(node.hi[k], child->hi[k]);
      }
  }
  for (size_t v = 0; v < n; ++v) ASSERT_EQ(seen[v], 1) << "vertex " << v;
}

/// Uniform points, clusters at several scales, a flat layer and 10 % exact duplicates.
std::vector<Vec3> awkward_cloud(Rand& rng, size_t n) {
  std::vector<Vec3> p;
  p.reserve(n);
  while (p.size() < n) {
    const double kind = rng.uniform();
    if (kind < 0.5) p.push_back(rng.point(-10, 10));
    else if (kind < 0.7) p.push_back(Vec3(3.f) + rng.point(-1e-3, 1e-3));
    else if (kind < 0.8) p.push_back(Vec3(float(rng.uniform(-10, 10)), -1.f, float(rng.uniform(-10, 10))));
    else if (kind < 0.9 && !p.empty()) p.push_back(p[size_t(rng.uniform() * double(p.size()))]);
    else p.push_back(Vec3(0.5f, 0.25f, 0.125f));  // a point light's worth of identical vertices
  }
  return p;
}

TEST(HrrBvh, WellFormed) {
  LightVertexBvh bvh;
  Rand rng(11);
  for (size_t n : {size_t(0), size_t(1), size_t(2), size_t(3), size_t(1000), size_t(20000)}) {
    const auto points = awkward_cloud(rng, n);
    bvh.build(points);
    check_structure(bvh, points);
  }
  // All points identical: Embree's fallback split (ordered by id) must still give one vertex a leaf.
  const std::vector<Vec3> same(5000, Vec3(1.f, 2.f, 3.f));
  bvh.build(same);
  check_structure(bvh, same);
  EXPECT_LE(bvh.depth(), 14u);  // object-median splits: balanced
  // Empty again, then a traversal is a no-op.
  bvh.build({});
  check_structure(bvh, {});
  int calls = 0;
  hrr_traverse(bvh, SelLobe{}, 1.0, HrrRandom{1}, [&](uint32_t, double, double) { ++calls; });
  EXPECT_EQ(calls, 0);
  EXPECT_THROW(bvh.build(std::vector<Vec3>{Vec3(0.f), Vec3(std::nanf(""), 0.f, 0.f)}), std::invalid_argument);
}

std::vector<LightVertexBvh::Node> build_with_threads(LightVertexBvh& bvh, std::span<const Vec3> points, size_t threads) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  bvh.build(points);
  return {bvh.nodes().begin(), bvh.nodes().end()};
}

bool same_tree(const std::vector<LightVertexBvh::Node>& a, const std::vector<LightVertexBvh::Node>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0;
}

TEST(HrrBvh, IdenticalAtOneAndTwoThreads) {
  Rand rng(12);
  const auto uniform = random_points(rng, 100000, -10, 10);
  const auto awkward = awkward_cloud(rng, 100000);
  LightVertexBvh bvh, other;
  for (const auto* points : {&uniform, &awkward}) {
    const auto one = build_with_threads(bvh, *points, 1);
    const double seconds_one = bvh.last_build_seconds();
    const auto two = build_with_threads(bvh, *points, 2);
    const double seconds_two = bvh.last_build_seconds();
    const auto again = build_with_threads(other, *points, 2);  // another device, another run
    check_structure(bvh, *points);
    EXPECT_TRUE(same_tree(one, two)) << (points == &uniform ? "uniform" : "awkward");
    EXPECT_TRUE(same_tree(two, again)) << (points == &uniform ? "uniform" : "awkward");
    std::printf("[hrr] BVH %s 1e5 points: %.1f ms at 1 thread, %.1f ms at 2, %.1f bytes/vertex, depth %u, "
                "identical trees: %s\n", points == &uniform ? "uniform" : "awkward", 1e3 * seconds_one,
                1e3 * seconds_two, double(bvh.memory_bytes()) / 1e5, bvh.depth(),
                same_tree(one, two) && same_tree(two, again) ? "yes" : "NO");
  }
}

TEST(HrrBvh, BuildsAMillionPoints) {
  Rand rng(13);
  const auto points = awkward_cloud(rng, 1000000);
  LightVertexBvh bvh;
  bvh.build(points);
  ASSERT_EQ(bvh.node_count(), 2 * points.size() - 1);
  EXPECT_EQ(bvh.node(0).count, points.size());
  std::printf("[hrr] BVH 1e6 points: built in %.1f ms, %.1f bytes/vertex, depth %u\n", 1e3 * bvh.last_build_seconds(),
              double(bvh.memory_bytes()) / double(points.size()), bvh.depth());
}

// ---------------------------------------------------------------------------------------------
// 8. make_sel_lobe against a GGX conductor

/// f(wo, wi) cos(wi) of a GGX conductor up to its (constant) Fresnel factor, local frame.
double ggx_reflection_cos(const TrowbridgeReitz& ggx, const Vec3& wo, const Vec3& wi) {
  if (wi.z <= 0.f) return 0.0;
  const Vec3 h = glm::normalize(wo + wi);
  return double(ggx.D(h)) * double(ggx.G(wo, wi)) / (4.0 * wo.z);
}

TEST(HrrSelLobe, MirrorLobeFollowsTheGgxBsdf) {
  Rand rng(21);
  double worst = 0.0;
  struct Case {
    float ax, ay, theta_o_deg, phi_o;
  };
  const Case cases[] = {{0.05f, 0.05f, 0.f, 0.f},  {0.05f, 0.05f, 20.f, 1.f}, {0.05f, 0.05f, 40.f, 2.5f},
                        {0.05f, 0.10f, 0.f, 0.f},  {0.05f, 0.10f, 30.f, 0.f}, {0.10f, 0.05f, 30.f, 0.5f * Pi}};
  for (const Case& cs : cases) {
    const TrowbridgeReitz ggx(cs.ax, cs.ay);
    const Frame shading = random_frame(rng);  // the surface sits at a random orientation
    const float th = radians(cs.theta_o_deg);
    const Vec3 wo_local(std::sin(th) * std::cos(cs.phi_o), std::sin(th) * std::sin(cs.phi_o), std::cos(th));
    LobeSummary summary;
    summary.peak = Vec3(-wo_local.x, -wo_local.y, wo_local.z);  // the conductor's lobe()
    summary.alpha_x = cs.ax;
    summary.alpha_y = cs.ay;
    const Vec3 z(0.3f, -0.2f, 1.f);
    const double peak_value = ggx_reflection_cos(ggx, wo_local, summary.peak);
    const SelLobe lobe = make_sel_lobe(z, shading, summary, peak_value, shading.n);
    EXPECT_NEAR(lobe.K(shading.to_world(summary.peak)), 1.0, 1e-6);
    EXPECT_NEAR(glm::dot(lobe.frame.n, shading.to_world(summary.peak)), 1.f, 1e-6f);
    for (int i = 0; i < 2000; ++i) {
      // Directions within alpha/2 of the peak (alpha of the narrower axis).
      const double theta = 0.5 * std::min(cs.ax, cs.ay) * std::sqrt(rng.uniform()), phi = 2 * M_PI * rng.uniform();
      const Vec3d w = Vec3d(lobe.frame.n) * std::cos(theta) +
                      (Vec3d(lobe.frame.s) * std::cos(phi) + Vec3d(lobe.frame.t) * std::sin(phi)) * std::sin(theta);
      const Vec3 wi_local = shading.to_local(glm::normalize(to_float(w)));
      const double ratio = ggx_reflection_cos(ggx, wo_local, wi_local) / peak_value;
      const double rel = std::abs(lobe.K(w) / ratio - 1.0);
      worst = std::max(worst, rel);
      ASSERT_LT(rel, 0.2) << "alpha " << cs.ax << " x " << cs.ay << " theta_o " << cs.theta_o_deg;
      // q is the BSDF * cos at the peak times K.
      EXPECT_DOUBLE_EQ(lobe.q(w), peak_value * lobe.K(w));
    }
  }
  // A cosine lobe is the sphere around the shading normal.
  LobeSummary diffuse;
  diffuse.cosine = true;
  const Frame shading = random_frame(rng);
  const SelLobe sphere = make_sel_lobe(Vec3(0.f), shading, diffuse, InvPi, shading.n);
  EXPECT_EQ(sphere.alpha_x, 1.0);
  EXPECT_NEAR(sphere.K(rng.unit()), 1.0, 1e-6);
  std::printf("[hrr] make_sel_lobe vs GGX conductor f cos ratio within alpha/2 of the mirror direction: max relative "
              "difference %.3f\n", worst);
}

}  // namespace
