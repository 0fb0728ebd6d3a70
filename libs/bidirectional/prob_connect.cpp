// Probabilistic-connection cache: lookup grid, record drawing, slot PMFs and frozen MIS statistics.
// The design and why it is unbiased are explained in prob_connect.h.
#include "prob_connect.h"

#include <penumbra/rng.h>

#include <algorithm>
#include <climits>
#include <stdexcept>

namespace penumbra::bdpt {

namespace {

double distance_squared(const Vec3& a, const Vec3& b) {
  double dx = double(a.x) - double(b.x), dy = double(a.y) - double(b.y), dz = double(a.z) - double(b.z);
  return dx * dx + dy * dy + dz * dz;
}

bool normals_agree(const Vec3& a, const Vec3& b) {
  double d = double(a.x) * double(b.x) + double(a.y) * double(b.y) + double(a.z) * double(b.z);
  return d >= ConnectionCache::kNormalAgreement;
}

/// Exactly uniform integer in [0, bound), bound >= 1 (Lemire 2019, multiply and reject).
uint32_t uniform_index(Pcg32& rng, uint32_t bound) {
  uint64_t m = uint64_t(rng.next_u32()) * bound;
  if (uint32_t(m) < bound) {
    uint32_t threshold = (0u - bound) % bound;
    while (uint32_t(m) < threshold) m = uint64_t(rng.next_u32()) * bound;
  }
  return uint32_t(m >> 32);
}

/// The record stream of one cache point in one iteration: a pure function of its three indices.
Pcg32 record_stream(uint64_t seed, uint64_t iteration, size_t cp) {
  uint64_t sequence = hash_ints(seed, iteration, cp, 0x70635f7265636fdull);
  return Pcg32(sequence, mix_bits(sequence ^ 0x9e3779b97f4a7c15ull));
}

template <class T>
size_t heap_bytes(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Cache points and lookup

void ConnectionCache::build_points(std::vector<CachePoint> points, float radius, Options opt) {
  if (opt.records < 1) throw std::invalid_argument("ConnectionCache: records must be >= 1");
  if (!(opt.defensive > 0.0 && opt.defensive <= 1.0))
    throw std::invalid_argument("ConnectionCache: defensive fraction must be in (0, 1]");
  if (points.size() > size_t(INT_MAX)) throw std::invalid_argument("ConnectionCache: too many cache points");

  points_ = std::move(points);
  radius_ = radius;
  options_ = opt;
  build_grid();

  vertex_count_ = 0;
  slots_per_point_ = 0;
  built_ = false;
  record_vertex_.clear();
  slot_pmf_.clear();
  slot_cdf_.clear();
  weight_sum_.assign(points_.size(), 0.0);
  frozen_ = false;
  frozen_vertex_count_ = 0;
  frozen_mean_weight_.clear();
}

int64_t ConnectionCache::cell_coordinate(float x) const {
  // Clamped so that far-away or huge coordinates cannot overflow; the +-1 neighbours stay in range.
  constexpr double kLimit = 0x1p60;
  double c = std::floor(double(x) / double(radius_));
  return int64_t(std::clamp(c, -kLimit, kLimit));
}

size_t ConnectionCache::bucket_of(int64_t ix, int64_t iy, int64_t iz) const {
  size_t mask = grid_start_.size() - 2;  // bucket count is a power of two; grid_start_ has one more entry
  return size_t(hash_ints(uint64_t(ix), uint64_t(iy), uint64_t(iz))) & mask;
}

void ConnectionCache::build_grid() {
  grid_start_.clear();
  grid_points_.clear();
  if (!(radius_ > 0.f && std::isfinite(radius_))) return;

  size_t buckets = 1;
  while (buckets < 2 * points_.size()) buckets *= 2;
  std::vector<size_t> bucket(points_.size(), SIZE_MAX);
  grid_start_.assign(buckets + 1, 0);
  for (size_t i = 0; i < points_.size(); ++i) {
    const Vec3& p = points_[i].p;
    if (!is_finite(p)) continue;
    bucket[i] = bucket_of(cell_coordinate(p.x), cell_coordinate(p.y), cell_coordinate(p.z));
    ++grid_start_[bucket[i] + 1];
  }
  // Counting sort: prefix sums give each bucket's range, then points are placed in index order.
  for (size_t b = 0; b < buckets; ++b) grid_start_[b + 1] += grid_start_[b];
  grid_points_.resize(grid_start_[buckets]);
  std::vector<uint32_t> fill(grid_start_.begin(), grid_start_.end() - 1);
  for (size_t i = 0; i < points_.size(); ++i)
    if (bucket[i] != SIZE_MAX) grid_points_[fill[bucket[i]]++] = uint32_t(i);
}

int ConnectionCache::lookup(const Vec3& p, const Vec3& n) const {
  if (grid_start_.empty() || !is_finite(p)) return -1;
  const double r2 = double(radius_) * double(radius_);
  int64_t cx = cell_coordinate(p.x), cy = cell_coordinate(p.y), cz = cell_coordinate(p.z);
  int best = -1;
  double best_d2 = 0.0;
  // Cells have the size of the radius, so every point within it lies in one of the 27 neighbours.
  // Two neighbours may share a bucket; visiting it twice does not change the minimum.
  for (int64_t dz = -1; dz <= 1; ++dz)
    for (int64_t dy = -1; dy <= 1; ++dy)
      for (int64_t dx = -1; dx <= 1; ++dx) {
        size_t b = bucket_of(cx + dx, cy + dy, cz + dz);
        for (uint32_t k = grid_start_[b]; k < grid_start_[b + 1]; ++k) {
          int i = int(grid_points_[k]);
          double d2 = distance_squared(p, points_[size_t(i)].p);
          if (d2 > r2 || !normals_agree(n, points_[size_t(i)].n)) continue;
          if (best < 0 || d2 < best_d2 || (d2 == best_d2 && i < best)) {
            best = i;
            best_d2 = d2;
          }
        }
      }
  return best;
}

// ---------------------------------------------------------------------------------------------
// Records and slot PMFs

void ConnectionCache::begin_records(size_t vertex_count) {
  if (vertex_count > size_t(UINT32_MAX)) throw std::length_error("ConnectionCache: too many light vertices");
  vertex_count_ = vertex_count;
  slots_per_point_ = vertex_count == 0 ? 0 : size_t(options_.records);
  size_t slots = points_.size() * slots_per_point_;
  record_vertex_.resize(slots);
  slot_pmf_.resize(slots);
  slot_cdf_.resize(slots);
  std::fill(weight_sum_.begin(), weight_sum_.end(), 0.0);
  built_ = true;
}

std::span<uint32_t> ConnectionCache::draw_records(size_t cp, uint64_t seed, uint64_t iteration) {
  std::span<uint32_t> vertices(record_vertex_.data() + cp * slots_per_point_, slots_per_point_);
  Pcg32 rng = record_stream(seed, iteration, cp);
  for (uint32_t& v : vertices) v = uniform_index(rng, uint32_t(vertex_count_));
  return vertices;
}

std::span<double> ConnectionCache::slot_storage(size_t cp) {
  return {slot_pmf_.data() + cp * slots_per_point_, slots_per_point_};
}

void ConnectionCache::finish_point(size_t cp) {
  // On entry the slot storage holds the sanitized record weights; on exit the defensive PMF.
  std::span<double> p = slot_storage(cp);
  double* cdf = slot_cdf_.data() + cp * slots_per_point_;
  double sum = 0.0;
  for (double w : p) sum += w;
  weight_sum_[cp] = sum;

  const double R = double(p.size()), eps = options_.defensive;
  double running = 0.0;
  for (size_t r = 0; r < p.size(); ++r) {
    p[r] = sum > 0.0 ? (1.0 - eps) * (p[r] / sum) + eps / R : 1.0 / R;
    running += p[r];
    cdf[r] = running;
  }
  cdf[p.size() - 1] = 1.0;  // u < 1 must always land in a slot
}

std::optional<ConnectionCache::Pick> ConnectionCache::sample(int cp, double u) const {
  if (cp < 0 || size_t(cp) >= points_.size() || slots_per_point_ == 0) return std::nullopt;
  size_t base = size_t(cp) * slots_per_point_;
  const double* cdf = slot_cdf_.data() + base;
  u = std::clamp(u, 0.0, 1.0);
  size_t r = size_t(std::upper_bound(cdf, cdf + slots_per_point_, u) - cdf);
  r = std::min(r, slots_per_point_ - 1);
  double probability = double(slots_per_point_) * slot_pmf_[base + r] / double(vertex_count_);
  return Pick{record_vertex_[base + r], probability, uint32_t(r)};
}

std::span<const double> ConnectionCache::slot_pmf(int cp) const {
  return {slot_pmf_.data() + size_t(cp) * slots_per_point_, slots_per_point_};
}

std::span<const uint32_t> ConnectionCache::record_vertices(int cp) const {
  return {record_vertex_.data() + size_t(cp) * slots_per_point_, slots_per_point_};
}

// ---------------------------------------------------------------------------------------------
// Frozen statistics for MIS

void ConnectionCache::freeze_statistics() {
  if (!built_) throw std::logic_error("ConnectionCache: freeze_statistics() needs a build_records() first");
  if (frozen_) return;
  frozen_ = true;
  frozen_vertex_count_ = vertex_count_;
  frozen_mean_weight_.assign(points_.size(), 0.0);
  if (slots_per_point_ == 0) return;
  for (size_t cp = 0; cp < points_.size(); ++cp) frozen_mean_weight_[cp] = weight_sum_[cp] / double(slots_per_point_);
}

double ConnectionCache::approx_probability(int cp, double w_y) const {
  if (!frozen_) throw std::logic_error("ConnectionCache: approx_probability() before freeze_statistics()");
  if (cp < 0 || size_t(cp) >= points_.size() || frozen_vertex_count_ == 0) return 0.0;
  const double V = double(frozen_vertex_count_), eps = options_.defensive;
  const double mean = frozen_mean_weight_[size_t(cp)];
  if (!(mean > 0.0)) return 1.0 / V;  // eps / V_f + (1 - eps) / V_f
  return (1.0 - eps) * sanitize_weight(w_y) / (V * mean) + eps / V;
}

size_t ConnectionCache::memory_bytes() const {
  return heap_bytes(points_) + heap_bytes(grid_start_) + heap_bytes(grid_points_) + heap_bytes(record_vertex_) +
         heap_bytes(slot_pmf_) + heap_bytes(slot_cdf_) + heap_bytes(weight_sum_) + heap_bytes(frozen_mean_weight_);
}

}  // namespace penumbra::bdpt
