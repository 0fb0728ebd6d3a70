// A hashed uniform grid over the visible points of one iteration, answering "which points have q
// within their radius?" for every photon hit.
//
// Each point is stored once, in the cell that holds its position; cells are a little over two largest
// radii wide, so the points that can reach q lie in the cells that [q - R, q + R] overlaps: at most
// 2 per axis, 8 in all (R is the largest radius, times 1.001 against rounding). Only cells that hold
// points cost memory: cell coordinates are hashed into a table with one to two buckets per point, and
// the points are counting-sorted by bucket, so a bucket's points lie next to each other. Each entry
// keeps the point's position and radius inline (16 bytes), so a query scans contiguous memory and
// follows no pointer until a point is within its radius (the earlier layout, a linked list of point
// indices per bucket, took one dependent cache miss per candidate and half the photon pass).
// Two of a query's cells may share a bucket; the bucket is then scanned once, so no point is reported
// twice. Collisions with other cells cost time, never correctness: the query tests the distance.
//
// Memory: 4 bytes per bucket (1 to 2 per point) plus 24 bytes per point (16 for the entry, 4 for its
// index, 4 for its bucket during the build). The arrays are kept between builds.
#pragma once

#include <penumbra/math.h>
#include <penumbra/rng.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace penumbra::sppm {

class VisiblePointGrid {
 public:
  /// Cells per axis are capped so that coordinates pack into 21 bits; with a tiny radius in a large
  /// scene the cells then grow beyond the radius, which stays correct.
  static constexpr int kMaxCellsPerAxis = 1 << 20;
  static constexpr double kCellReach = 2.0;

  /// Rebuilds the grid over points p[i] with gather radii r[i]; r[i] <= 0 (or non-finite) leaves point
  /// i out. The grid copies what it needs: the spans may change after the build.
  void build(std::span<const Vec3> p, std::span<const float> r) {
    node_count_ = 0;
    Extent e = extent(p, r);
    if (e.count == 0) {
      active_ = false;
      return;
    }
    active_ = true;
    Vec3 size = e.hi - e.lo;
    float widest = std::max(size.x, std::max(size.y, size.z));
    // A query looks h = 1.001 R either side of q; cells 2h wide make that at most 2 cells per axis.
    // Coordinates are computed in double; the margin covers the rounding of the float distance test.
    reach_ = 1.001 * e.max_radius;
    cell_ = std::max(kCellReach * reach_, static_cast<double>(widest) / (kMaxCellsPerAxis - 2));
    if (!(cell_ > 0.0)) cell_ = 1.0;  // every disk is a point at one place
    inv_cell_ = 1.0 / cell_;
    origin_ = glm::dvec3(e.lo);
    for (int k = 0; k < 3; ++k)
      res_[k] = std::clamp(static_cast<int>(size[k] * inv_cell_) + 1, 1, kMaxCellsPerAxis);

    size_t buckets = 1;
    while (buckets < e.count) buckets <<= 1;
    bucket_mask_ = buckets - 1;
    if (buckets + 1 > start_.size()) start_ = std::vector<std::atomic<uint32_t>>(buckets + 1);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, buckets + 1, 4096), [&](const tbb::blocked_range<size_t>& b) {
      for (size_t i = b.begin(); i < b.end(); ++i) start_[i].store(0, std::memory_order_relaxed);
    });

    // Counting sort by bucket: each point's bucket and the buckets' sizes, an exclusive prefix sum,
    // then every point goes to its bucket's next free slot (the order within a bucket does not matter:
    // deposits are order-independent integer sums).
    point_bucket_.resize(p.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, p.size(), 4096), [&](const tbb::blocked_range<size_t>& b) {
      for (size_t i = b.begin(); i < b.end(); ++i) {
        if (!active_point(p[i], r[i])) {
          point_bucket_[i] = kNone;
          continue;
        }
        glm::ivec3 c;
        for (int k = 0; k < 3; ++k) c[k] = cell_coordinate(static_cast<double>(p[i][k]), k);
        uint32_t bk = bucket(c);
        point_bucket_[i] = bk;
        start_[bk + 1].fetch_add(1, std::memory_order_relaxed);
      }
    });
    uint32_t sum = 0;
    for (size_t i = 1; i <= buckets; ++i) {
      sum += start_[i].load(std::memory_order_relaxed);
      start_[i].store(sum, std::memory_order_relaxed);
    }
    node_count_ = sum;
    if (entries_.size() < node_count_) {
      entries_.resize(node_count_);
      index_.resize(node_count_);
    }
    // start_[b] serves as bucket b's cursor and ends at its end, which is bucket b + 1's start:
    // afterwards the range of bucket b is [start_[b - 1], start_[b]) with start_[-1] = 0, so the
    // table is read shifted by one (begin_of).
    tbb::parallel_for(tbb::blocked_range<size_t>(0, p.size(), 4096), [&](const tbb::blocked_range<size_t>& b) {
      for (size_t i = b.begin(); i < b.end(); ++i) {
        uint32_t bk = point_bucket_[i];
        if (bk == kNone) continue;
        uint32_t slot = start_[bk].fetch_add(1, std::memory_order_relaxed);
        entries_[slot] = Entry{p[i].x, p[i].y, p[i].z, r[i]};
        index_[slot] = static_cast<uint32_t>(i);
      }
    });
  }

  /// Calls f(i) for every point i with |q - p[i]| <= r[i], each once. The grid must not be rebuilt
  /// meanwhile; any number of threads may query at once (the build has finished, so relaxed loads do).
  template <class F>
  void for_each_within(const Vec3& q, F&& f) const {
    for_each_entry_within(q, [&](uint32_t slot) { f(index_[slot]); });
  }

  /// As for_each_within, but calls f(slot) with the point's slot in the grid's order (point_of(slot)
  /// is its index): data kept per slot lies together for points of one cell, which a photon's
  /// neighbours share.
  template <class F>
  void for_each_entry_within(const Vec3& q, F&& f) const {
    if (!active_) return;
    glm::ivec3 lo, hi;
    for (int k = 0; k < 3; ++k) {
      double a = (static_cast<double>(q[k]) - reach_ - origin_[k]) * inv_cell_;
      double b = (static_cast<double>(q[k]) + reach_ - origin_[k]) * inv_cell_;
      if (!(b >= 0.0) || !(a < res_[k])) return;  // outside every point's disk (or q is not finite)
      lo[k] = a <= 0.0 ? 0 : static_cast<int>(a);
      hi[k] = std::min(static_cast<int>(b), res_[k] - 1);
    }
    // Three steps, so that the cache misses of the (up to 8) cells overlap instead of following
    // one another: the distinct buckets (prefetching their bounds), their ranges (prefetching the
    // first entries), then the scan.
    uint32_t bks[27];
    int n = 0;
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
          uint32_t bk = bucket({x, y, z});
          if (std::find(bks, bks + n, bk) != bks + n) continue;
          bks[n++] = bk;
          __builtin_prefetch(&start_[bk == 0 ? 0 : bk - 1]);
        }
    uint32_t begin[27], end[27];
    for (int j = 0; j < n; ++j) {
      begin[j] = bks[j] == 0 ? 0 : start_[bks[j] - 1].load(std::memory_order_relaxed);
      end[j] = start_[bks[j]].load(std::memory_order_relaxed);
      if (begin[j] < end[j]) __builtin_prefetch(&entries_[begin[j]]);
    }
    for (int j = 0; j < n; ++j)
      for (uint32_t s = begin[j]; s < end[j]; ++s) {
        const Entry& en = entries_[s];
        Vec3 d = Vec3(en.x, en.y, en.z) - q;
        if (glm::dot(d, d) <= en.r * en.r) f(s);
      }
  }

  /// The point held in a slot (slots run from 0 to node_count() - 1).
  uint32_t point_of(uint32_t slot) const { return index_[slot]; }

  /// Entries held by the grid (one per point with a positive radius).
  size_t node_count() const { return node_count_; }
  size_t bucket_count() const { return active_ ? bucket_mask_ + 1 : 0; }
  double cell_size() const { return cell_; }
  glm::ivec3 resolution() const { return res_; }
  /// Bytes held (kept between builds).
  size_t memory_bytes() const {
    return start_.capacity() * sizeof(uint32_t) + entries_.capacity() * sizeof(Entry) +
           index_.capacity() * sizeof(uint32_t) + point_bucket_.capacity() * sizeof(uint32_t);
  }

 private:
  static constexpr uint32_t kNone = 0xffffffffu;
  struct Entry {
    float x, y, z, r;
  };
  struct Extent {
    Vec3 lo{Infinity}, hi{-Infinity};
    float max_radius = 0.f;
    size_t count = 0;
  };

  static bool active_point(const Vec3& p, float r) { return r > 0.f && std::isfinite(r) && is_finite(p); }

  static Extent extent(std::span<const Vec3> p, std::span<const float> r) {
    return tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, p.size(), 4096), Extent{},
        [&](const tbb::blocked_range<size_t>& b, Extent e) {
          for (size_t i = b.begin(); i < b.end(); ++i) {
            if (!active_point(p[i], r[i])) continue;
            e.lo = glm::min(e.lo, p[i] - Vec3(r[i]));
            e.hi = glm::max(e.hi, p[i] + Vec3(r[i]));
            e.max_radius = std::max(e.max_radius, r[i]);
            ++e.count;
          }
          return e;
        },
        [](Extent a, const Extent& b) {
          a.lo = glm::min(a.lo, b.lo);
          a.hi = glm::max(a.hi, b.hi);
          a.max_radius = std::max(a.max_radius, b.max_radius);
          a.count += b.count;
          return a;
        });
  }

  int cell_coordinate(double x, int axis) const {
    double c = (x - origin_[axis]) * inv_cell_;
    return std::clamp(static_cast<int>(c), 0, res_[axis] - 1);
  }

  uint32_t bucket(glm::ivec3 c) const {
    uint64_t key = static_cast<uint64_t>(c.x) | static_cast<uint64_t>(c.y) << 21 | static_cast<uint64_t>(c.z) << 42;
    return static_cast<uint32_t>(mix_bits(key) & bucket_mask_);
  }

  bool active_ = false;
  glm::dvec3 origin_{0.0};
  double cell_ = 1.0, inv_cell_ = 1.0, reach_ = 0.0;
  glm::ivec3 res_{1};
  std::vector<std::atomic<uint32_t>> start_;  // during the build: counts, then cursors; see build()
  size_t bucket_mask_ = 0;
  std::vector<Entry> entries_;
  std::vector<uint32_t> index_;
  std::vector<uint32_t> point_bucket_;
  size_t node_count_ = 0;
};

}  // namespace penumbra::sppm
