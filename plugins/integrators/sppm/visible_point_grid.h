// A hashed uniform grid over the visible points of one iteration, answering "which points have q
// within their radius?" for every photon hit.
//
// Cells are at least as wide as the largest radius, so a point's disk overlaps at most 3x3x3 cells;
// the point is listed in each of them. Only cells that hold points cost memory: cell coordinates are
// hashed into a table with about one bucket per point, and each bucket heads a singly linked list of
// nodes pushed lock-free with compare-exchange, so the build runs in parallel. Two cells of one point
// may share a bucket; the point is then listed once for both, which keeps a photon from being counted
// twice. Collisions with other cells cost time, never correctness: the query tests the distance.
//
// Memory: 4 bytes per bucket (1 to 2 per point), 8 bytes per node (1 to 27 per point) and 4 bytes per
// point for the node offsets. The table and node arrays are kept between builds.
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

  /// Rebuilds the grid over points p[i] with gather radii r[i]; r[i] <= 0 (or non-finite) leaves point
  /// i out. Both spans must stay alive and unchanged while the grid is queried.
  void build(std::span<const Vec3> p, std::span<const float> r) {
    p_ = p;
    r_ = r;
    node_count_ = 0;
    Extent e = extent(p, r);
    if (e.count == 0) {
      active_ = false;
      return;
    }
    active_ = true;
    Vec3 size = e.hi - e.lo;
    float widest = std::max(size.x, std::max(size.y, size.z));
    // A little wider than the largest radius, so that a disk's box (2r wide) spans at most 3 cells
    // per axis; coordinates are computed in double so that rounding cannot add a fourth.
    cell_ = std::max(1.001 * e.max_radius, static_cast<double>(widest) / (kMaxCellsPerAxis - 2));
    if (!(cell_ > 0.0)) cell_ = 1.0;  // every disk is a point at one place
    inv_cell_ = 1.0 / cell_;
    origin_ = glm::dvec3(e.lo);
    for (int k = 0; k < 3; ++k)
      res_[k] = std::clamp(static_cast<int>(size[k] * inv_cell_) + 1, 1, kMaxCellsPerAxis);

    size_t buckets = 1;
    while (buckets < e.count) buckets <<= 1;
    if (buckets > bucket_capacity_) {
      heads_ = std::make_unique<std::atomic<uint32_t>[]>(buckets);
      bucket_capacity_ = buckets;
    }
    bucket_mask_ = buckets - 1;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, buckets, 4096), [&](const tbb::blocked_range<size_t>& b) {
      for (size_t i = b.begin(); i < b.end(); ++i) heads_[i].store(kEnd, std::memory_order_relaxed);
    });

    // Count each point's distinct buckets, lay the nodes out by prefix sum, then link them.
    first_node_.resize(p.size() + 1);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, p.size(), 1024), [&](const tbb::blocked_range<size_t>& b) {
      uint32_t tmp[kMaxCellsPerPoint];
      for (size_t i = b.begin(); i < b.end(); ++i) first_node_[i + 1] = point_buckets(i, tmp);
    });
    first_node_[0] = 0;
    for (size_t i = 0; i < p.size(); ++i) first_node_[i + 1] += first_node_[i];
    node_count_ = first_node_[p.size()];
    if (nodes_.size() < node_count_) nodes_.resize(node_count_);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, p.size(), 1024), [&](const tbb::blocked_range<size_t>& b) {
      uint32_t tmp[kMaxCellsPerPoint];
      for (size_t i = b.begin(); i < b.end(); ++i) {
        uint32_t n = point_buckets(i, tmp), node = first_node_[i];
        for (uint32_t k = 0; k < n; ++k, ++node) {
          nodes_[node].point = static_cast<uint32_t>(i);
          std::atomic<uint32_t>& head = heads_[tmp[k]];
          uint32_t old = head.load(std::memory_order_relaxed);
          do {
            nodes_[node].next = old;
          } while (!head.compare_exchange_weak(old, node, std::memory_order_release, std::memory_order_relaxed));
        }
      }
    });
  }

  /// Calls f(i) for every point i with |q - p[i]| <= r[i], each once. The grid must not be rebuilt
  /// meanwhile; any number of threads may query at once (the build has finished, so relaxed loads do).
  template <class F>
  void for_each_within(const Vec3& q, F&& f) const {
    if (!active_) return;
    glm::ivec3 c;
    for (int k = 0; k < 3; ++k) {
      double x = (q[k] - origin_[k]) * inv_cell_;
      if (!(x >= 0.0) || x >= res_[k]) return;  // outside every point's disk
      c[k] = std::min(static_cast<int>(x), res_[k] - 1);
    }
    for (uint32_t n = heads_[bucket(c)].load(std::memory_order_relaxed); n != kEnd; n = nodes_[n].next) {
      uint32_t i = nodes_[n].point;
      Vec3 d = p_[i] - q;
      if (glm::dot(d, d) <= r_[i] * r_[i]) f(i);
    }
  }

  size_t node_count() const { return node_count_; }
  size_t bucket_count() const { return active_ ? bucket_mask_ + 1 : 0; }
  double cell_size() const { return cell_; }
  glm::ivec3 resolution() const { return res_; }
  /// Bytes held (kept between builds).
  size_t memory_bytes() const {
    return bucket_capacity_ * sizeof(uint32_t) + nodes_.capacity() * sizeof(Node) +
           first_node_.capacity() * sizeof(uint32_t);
  }

 private:
  static constexpr uint32_t kEnd = 0xffffffffu;
  static constexpr int kMaxCellsPerPoint = 27;
  struct Node {
    uint32_t point;
    uint32_t next;
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

  /// The distinct buckets of the cells point i's disk overlaps (its bounding box, clamped to the grid).
  uint32_t point_buckets(size_t i, uint32_t out[kMaxCellsPerPoint]) const {
    if (!active_point(p_[i], r_[i])) return 0;
    glm::ivec3 lo, hi;
    for (int k = 0; k < 3; ++k) {
      lo[k] = cell_coordinate(static_cast<double>(p_[i][k]) - r_[i], k);
      hi[k] = cell_coordinate(static_cast<double>(p_[i][k]) + r_[i], k);
    }
    uint32_t n = 0;
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
          uint32_t b = bucket({x, y, z});
          if (std::find(out, out + n, b) == out + n) out[n++] = b;
        }
    return n;
  }

  std::span<const Vec3> p_;
  std::span<const float> r_;
  bool active_ = false;
  glm::dvec3 origin_{0.0};
  double cell_ = 1.0, inv_cell_ = 1.0;
  glm::ivec3 res_{1};
  std::unique_ptr<std::atomic<uint32_t>[]> heads_;
  size_t bucket_capacity_ = 0, bucket_mask_ = 0;
  std::vector<Node> nodes_;
  std::vector<uint32_t> first_node_;
  size_t node_count_ = 0;
};

}  // namespace penumbra::sppm
