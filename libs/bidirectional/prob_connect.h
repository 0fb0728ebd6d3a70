// Probabilistic connections (Popov, Ramamoorthi, Durand, Drettakis, EGSR 2015; docs/algorithms.md, docs/hrr.md):
// a cache that lets an eye vertex importance-sample WHICH stored light vertex to connect to.
//
// The module only knows what it is handed: cache-point positions and normals, a vertex count and a
// caller-supplied weight w(cache point, vertex index) >= 0. It knows nothing of BSDFs, paths or the
// integrator, so it can be tested on plain numbers.
//
// Design, and why it keeps the bidirectional estimator exactly unbiased:
//
//  * Cache points. A fixed set per render (e.g. first diffuse camera hits of a subset of pixels).
//    An eye vertex is mapped to a cache point by lookup(p, n): the nearest point within `radius`
//    whose normal satisfies dot(n, n_c) >= 0.7, found in a hashed uniform grid of cell size
//    `radius` (27 neighbouring cells; ties go to the lower index; -1 if none). The lookup is a
//    deterministic function of (p, n) only, so the sampling code and the MIS code, which both call
//    it, always agree on the cache point of a vertex.
//
//  * Records. Each iteration the integrator stores V light vertices (indices 0..V-1). Every cache
//    point draws R = Options::records vertex indices uniformly WITH replacement from [0, V), from a
//    counter-based stream seeded by (seed, iteration, cache point index): the records do not depend
//    on thread count or scheduling. The weight of each record is evaluated and the slots get the
//    defensive PMF
//        P_r = (1 - eps) w_r / sum_w + eps / R        (P_r = 1/R when sum_w == 0),
//    eps = Options::defensive. Every slot keeps P_r >= eps / R > 0, so a record whose weight
//    estimate is wrongly 0 can still be chosen.
//
//  * Estimator. An eye vertex at cache point c takes n_c draws; a draw picks slot r with P_r. The
//    term g(y_r) V / (R n_c P_r) is unbiased for sum over ALL V vertices of g(y): conditioned on the
//    records it is unbiased for (V / R) sum_r g(y_r) (importance sampling over the slots, all P_r > 0),
//    and that is unbiased for sum_y g(y) because each record is uniform over [0, V). sample() returns
//    the slot's vertex and the "effective selection probability" p = R P_r / V, so the caller simply
//    divides by n_c * p.
//
//  * MIS density. Balance-heuristic weights must not depend on the random records of the current
//    iteration (otherwise the weight would be a function of the sample that chose it, and the
//    weights of a path would no longer sum to one over the strategies in expectation). So the MIS
//    uses an approximation that is independent of the current records:
//        P~(y | c) = (1 - eps) w_y / (V_f wbar_f(c)) + eps / V_f,
//    which is the expected per-draw probability of y (expected R / V copies of y among the records,
//    each with P_r ~ (1 - eps) w_y / (R wbar) + eps / R). V_f and wbar_f(c) (the mean record weight at
//    c) are statistics FROZEN from a pilot build: call freeze_statistics() once, after the first
//    build_records(); later builds never change them. When wbar_f(c) == 0 the formula falls back to
//    the uniform 1 / V_f. P~ is only a density for MIS ratios: it is not clamped to 1.
//
// Storage is flat (point-major, stride R): O(points x records) memory, as in the paper.
#pragma once

#include <penumbra/math.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

namespace penumbra::bdpt {

/// An eye-side location with a unit normal.
struct CachePoint {
  Vec3 p;
  Vec3 n;
};

class ConnectionCache {
 public:
  struct Options {
    int records = 100;        // R: candidate vertices drawn per cache point and iteration (>= 1)
    double defensive = 0.2;   // eps in (0, 1]: probability mass spread uniformly over the slots
  };

  /// Minimum dot(n, n_c) for an eye vertex to use cache point c.
  static constexpr double kNormalAgreement = 0.7;

  /// Starts a render: stores the points (unit normals expected), builds the lookup grid and clears
  /// the records and the frozen statistics. Points with non-finite positions are never found.
  /// Throws std::invalid_argument for records < 1, defensive outside (0, 1] or more than INT_MAX
  /// points. A radius that is not positive and finite gives a cache where lookup() always fails.
  void build_points(std::vector<CachePoint> points, float radius, Options opt);

  /// Index of the cache point for an eye vertex at p with unit normal n, or -1 (see header comment).
  int lookup(const Vec3& p, const Vec3& n) const;

  size_t point_count() const { return points_.size(); }
  const CachePoint& point(int i) const { return points_[size_t(i)]; }
  float radius() const { return radius_; }
  const Options& options() const { return options_; }

  /// Draws each point's records among `vertex_count` vertices and builds its PMF; weight(cp, vertex) >= 0
  /// is called R times per point; runs in parallel over points with TBB, deterministic.
  /// `weight` is called as weight(int cp, uint32_t vertex), concurrently for different points, and
  /// must be thread-safe. Negative or non-finite weights count as 0. Throws std::length_error if
  /// vertex_count does not fit in 32 bits.
  template <class Weight>
  void build_records(size_t vertex_count, uint64_t seed, uint64_t iteration, Weight&& weight,
                     const std::function<bool()>& stop = {});

  /// Freezes V_f and wbar_f(c) from the most recent build_records() for approx_probability(). Only
  /// the first call after build_points() has an effect; throws std::logic_error before any build.
  void freeze_statistics();
  bool frozen() const { return frozen_; }
  size_t frozen_vertex_count() const { return frozen_vertex_count_; }
  double frozen_mean_weight(int cp) const { return frozen_mean_weight_[size_t(cp)]; }

  /// One draw's result. probability = R P_r / V, the effective selection probability of `vertex`.
  struct Pick {
    uint32_t vertex;
    double probability;
    uint32_t slot;  // the record slot r that was drawn
  };

  /// One draw at cache point cp with a uniform u in [0,1); empty when the point has no records or V == 0.
  std::optional<Pick> sample(int cp, double u) const;

  /// Slot PMF of point cp (for tests): the R values P_r and the record vertex indices. Both are
  /// empty before the first build or when the last build had V == 0.
  std::span<const double> slot_pmf(int cp) const;
  std::span<const uint32_t> record_vertices(int cp) const;
  /// Vertex count V of the most recent build_records().
  size_t vertex_count() const { return vertex_count_; }

  /// P~(y|c) above, for a vertex with weight w_y at cache point cp. Depends only on the frozen
  /// statistics. Returns 0 for cp < 0 (no cache point) and when V_f == 0; throws std::logic_error
  /// before freeze_statistics().
  double approx_probability(int cp, double w_y) const;

  /// Heap memory held by the cache (points, grid, records, PMFs, statistics).
  size_t memory_bytes() const;

 private:
  // Build steps called by the build_records() template; each touches only point cp's data.
  void begin_records(size_t vertex_count);
  std::span<uint32_t> draw_records(size_t cp, uint64_t seed, uint64_t iteration);
  std::span<double> slot_storage(size_t cp);
  void finish_point(size_t cp);
  static double sanitize_weight(double w) { return (w >= 0.0 && std::isfinite(w)) ? w : 0.0; }

  // Hashed uniform grid: the points of bucket b are grid_points_[grid_start_[b] .. grid_start_[b+1]).
  void build_grid();
  size_t bucket_of(int64_t ix, int64_t iy, int64_t iz) const;
  int64_t cell_coordinate(float x) const;

  std::vector<CachePoint> points_;
  float radius_ = 0.f;
  Options options_;
  std::vector<uint32_t> grid_start_, grid_points_;

  size_t vertex_count_ = 0;
  size_t slots_per_point_ = 0;             // R after a build with V > 0, else 0
  bool built_ = false;                     // build_records() ran since build_points()
  std::vector<uint32_t> record_vertex_;    // point-major, stride R
  std::vector<double> slot_pmf_;           // P_r (holds the raw weights during a build)
  std::vector<double> slot_cdf_;           // running sums of P_r, last one exactly 1
  std::vector<double> weight_sum_;         // sum_w per point, latest build

  bool frozen_ = false;
  size_t frozen_vertex_count_ = 0;
  std::vector<double> frozen_mean_weight_;
};

template <class Weight>
void ConnectionCache::build_records(size_t vertex_count, uint64_t seed, uint64_t iteration, Weight&& weight,
                                    const std::function<bool()>& stop) {
  begin_records(vertex_count);
  if (slots_per_point_ == 0) return;
  // `stop` (the time budget is spent) leaves the records incomplete: not to be rendered with.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, points_.size(), 16), [&](const tbb::blocked_range<size_t>& range) {
    if (stop && stop()) return;
    for (size_t cp = range.begin(); cp != range.end(); ++cp) {
      std::span<const uint32_t> vertices = draw_records(cp, seed, iteration);
      std::span<double> w = slot_storage(cp);
      for (size_t r = 0; r < vertices.size(); ++r) w[r] = sanitize_weight(double(weight(int(cp), vertices[r])));
      finish_point(cp);
    }
  });
}

}  // namespace penumbra::bdpt
