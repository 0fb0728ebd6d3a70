#include "connect_cached.h"

#include <penumbra/memory.h>

#include <penumbra/error.h>
#include <penumbra/rng.h>

#include <fmt/core.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>

namespace penumbra::bdpt {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

uint64_t pixel_key(Point2i p) { return (static_cast<uint64_t>(static_cast<uint32_t>(p.y)) << 32) | static_cast<uint32_t>(p.x); }

std::atomic<uint64_t> next_connector_id{1};

constexpr double kPcWeightBound = 8.0;  // record weights are capped at this multiple of the pilot mean

bool is_connectible_surface(const Vertex& v) { return v.kind == VertexKind::Surface && v.bsdf && v.connectible(); }

// Pilot camera paths: one through the centre of every `stride`-th pixel in x and y, traced with an
// independent stream. Returns their non-specular surface vertices and each one's eye-side neighbour.
void pilot_eye_vertices(const Context& ctx, Point2i res, int stride, uint64_t seed, std::vector<Vertex>* eye,
                        std::vector<Vertex>* eye_next) {
  StreamSampler sampler(hash_ints(seed, 0x50494c4fu /* "PILO" */));
  std::vector<Vertex> path(ctx.config.max_depth + 2);
  for (int y = stride / 2; y < res.y; y += stride)
    for (int x = stride / 2; x < res.x; x += stride) {
      CameraSample cs{Vec2(x + 0.5f, y + 0.5f), Vec2(0.5f)};
      std::optional<Ray> ray = ctx.scene.camera().generate_ray(cs);
      if (!ray) continue;
      PathSampler ps(sampler, Point2i(x, y), 0);
      int n = camera_subpath(ctx, *ray, ps, path.data());
      for (int t = 2; t <= n; ++t)
        if (is_connectible_surface(path[t - 1])) {
          eye->push_back(path[t - 1]);
          eye_next->push_back(path[t - 2]);
        }
    }
}

}  // namespace

CachedConnector::CachedConnector(const CachedOptions& options, int max_depth)
    : opt_(options), max_depth_(max_depth), id_(next_connector_id.fetch_add(1)), cache_(max_depth) {}

CachedConnector::~CachedConnector() = default;

bool CachedConnector::enabled(Technique tau) const {
  switch (tau) {
    case Technique::Hrr: return opt_.hrr;
    case Technique::ProbConnect: return opt_.probconnect;
    case Technique::Regular: return false;
  }
  return false;
}

SelLobe CachedConnector::eye_lobe(const Vertex& z, const Vertex& z_next) const {
  SelLobe lobe;
  lobe.z = z.p;
  lobe.c = 0.0;
  if (!is_connectible_surface(z)) return lobe;
  Vec3 wo_world = direction_to(z, z_next);
  Vec3 wo = z.shading.to_local(wo_world);
  if (wo.z == 0.f) return lobe;
  const ShadingContext& sc = z.sc;  // a camera vertex: radiance
  LobeSummary summary = z.bsdf->lobe(wo, sc);
  float len = glm::length(summary.peak);
  if (!(len > 0.f)) return lobe;
  summary.peak /= len;
  // Optionally only glossy eye vertices (a diffuse one's sphere of a range is costly to traverse and
  // regular connections already serve it well); the MIS sees the same rule.
  if (std::max(summary.alpha_x, summary.alpha_y) > opt_.hrr_max_alpha) return lobe;
  // The lobe's height is the BSDF times the cosine at its peak (only the peak's neighbourhood needs to
  // be accurate: the other techniques cover the tails through MIS).
  double c = luminance(z.bsdf->f(wo, summary.peak, sc)) * std::abs(summary.peak.z);
  if (!(c > 0.0) || !std::isfinite(c)) return lobe;
  // A BSDF without transmission is 0 on the far side of the surface: no connections there.
  Vec3 half_space(0.f);
  if (!(z.bsdf->flags() & BsdfTransmission)) half_space = glm::dot(z.ng, wo_world) >= 0.f ? z.ng : -z.ng;
  return make_sel_lobe(z.p, z.shading, summary, c, half_space);
}

double CachedConnector::pc_weight(const Vertex& y_prev, const Vertex& y, int cp) const {
  if (!is_connectible_surface(y)) return 0.0;
  const CachePoint& point = pc_.point(cp);
  Vec3 d = point.p - y.p;
  float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.f)) return 0.0;
  Vec3 wi = d / std::sqrt(dist2);
  Vec3 wo = direction_to(y, y_prev);
  Rgb f = y.bsdf->f(y.shading.to_local(wo), y.shading.to_local(wi), y.sc);  // a light vertex: importance
  double w = luminance(f) * std::abs(glm::dot(y.ns, wi)) * std::abs(glm::dot(point.n, wi)) /
             std::max(dist2, pc_radius_ * pc_radius_);
  if (!std::isfinite(w) || !(w > 0.0)) return 0.0;
  // Bounded weights: the MIS approximates the selection probability with the pilot's mean record
  // weight; a record far above it (a glossy light vertex aimed at the cache point) would make one
  // iteration's PMF much more peaked than that approximation, and samples drawn with a true
  // probability far below the approximate one become fireflies. With w <= kappa * mean, the true
  // probability is never below 1/kappa of the approximation. The same bound holds in the MIS.
  if (pc_.frozen()) w = std::min(w, kPcWeightBound * pc_.frozen_mean_weight(cp));
  return w;
}

namespace {

// The MIS weight of every connection evaluates the factors of all the path's edges, and a pixel
// sample's connections share most of their eye vertices: a small per-thread memo of the last eye
// vertices' acceptance ranges and cache points saves recomputing them. Keyed by everything they
// depend on (the connector, the vertex's position and BSDF, the eye-side neighbour's position).
struct EyeMemo {
  uint64_t owner = 0;
  Vec3 z{0.f}, z_next{0.f}, n{0.f};
  const Bsdf* bsdf = nullptr;
  std::optional<HrrRange> range;  // empty: HRR does not apply at z
  bool has_range = false;
};

EyeMemo& eye_memo(uint64_t owner, const Vertex& z, const Vertex& z_next) {
  thread_local std::array<EyeMemo, 64> memo;
  auto bits = [](float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
  };
  uint64_t h = hash_ints(owner, bits(z.p.x) ^ (uint64_t(bits(z.p.y)) << 32), bits(z.p.z) ^ (uint64_t(bits(z_next.p.x)) << 32),
                         bits(z_next.p.y) ^ (uint64_t(bits(z_next.p.z)) << 32));
  EyeMemo& m = memo[h & 63];
  if (m.owner != owner || m.z != z.p || m.z_next != z_next.p || m.bsdf != z.bsdf || m.n != z.ng) {
    m = EyeMemo{};
    m.owner = owner;
    m.z = z.p;
    m.z_next = z_next.p;
    m.n = z.ng;
    m.bsdf = z.bsdf;
  }
  return m;
}

}  // namespace

const std::optional<HrrRange>& CachedConnector::eye_range(const Vertex& z, const Vertex& z_next) const {
  EyeMemo& memo = eye_memo(id_, z, z_next);
  if (!memo.has_range) {
    SelLobe lobe = eye_lobe(z, z_next);
    if (lobe.c > 0.0) memo.range.emplace(lobe, C_);
    memo.has_range = true;
  }
  return memo.range;
}

// The cache point depends on z alone (not on its neighbour, as HRR's range does), so it has a memo
// of its own: the MIS weights ask for the same vertex with many neighbours.
int CachedConnector::eye_cache_point(const Vertex& z, const Vertex&) const {
  struct PointMemo {
    uint64_t owner = 0;
    Vec3 p{0.f}, n{0.f};
    int cache_point = -1;
  };
  thread_local std::array<PointMemo, 64> memo;
  auto bits = [](float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
  };
  uint64_t h = hash_ints(id_, bits(z.p.x) ^ (uint64_t(bits(z.p.y)) << 32), bits(z.p.z) ^ (uint64_t(bits(z.ng.x)) << 32));
  PointMemo& m = memo[h & 63];
  if (m.owner != id_ || m.p != z.p || m.n != z.ng) {
    m.owner = id_;
    m.p = z.p;
    m.n = z.ng;
    m.cache_point = pc_.lookup(z.p, z.ng);
  }
  return m.cache_point;
}

double CachedConnector::factor(Technique tau, const Vertex& y_prev, const Vertex& y, const Vertex& z,
                               const Vertex& z_next) const {
  if (!is_connectible_surface(y) || !is_connectible_surface(z)) return 0.0;
  if (tau == Technique::Hrr && opt_.hrr) {
    const std::optional<HrrRange>& range = eye_range(z, z_next);
    return range ? static_cast<double>(M_) * range->acceptance(y.p) : 0.0;
  }
  if (tau == Technique::ProbConnect && opt_.probconnect) {
    int cp = eye_cache_point(z, z_next);
    if (cp < 0) return 0.0;
    return opt_.pc_connections * static_cast<double>(M_) * pc_.approx_probability(cp, pc_weight(y_prev, y, cp));
  }
  return 0.0;
}

bool CachedConnector::prepare(const Context& ctx, const Sampler& proto, Point2i resolution,
                              const std::function<bool()>& stop) {
  auto cut = [&] { return stop && stop(); };
  auto t0 = std::chrono::steady_clock::now();
  M_ = opt_.light_paths ? opt_.light_paths : static_cast<size_t>(resolution.x) * resolution.y;
  // The cache is the largest structure of a cached render: announced before it is allocated.
  require_memory(cache_.estimated_bytes(M_), "bdpt's light-vertex cache",
                 fmt::format("{} light paths of up to {} vertices, {} bytes each", M_, cache_.stride(),
                             sizeof(Vertex)));
  // A pilot cache, independent of the render's samples.
  StreamSampler pilot(hash_ints(opt_.seed, 0x50434143u /* "PCAC" */));
  cache_.trace(ctx, pilot, resolution, 0xfffffffeu, M_, opt_.seed ^ 0x9e3779b97f4a7c15ull, stop);
  if (cut()) return false;
  std::vector<Vertex> eye, eye_next;
  pilot_eye_vertices(ctx, resolution, 4, opt_.seed, &eye, &eye_next);
  if (opt_.hrr) calibrate(eye, eye_next, stop);
  if (cut()) return false;
  if (opt_.probconnect) {
    std::vector<CachePoint> points;
    for (const Vertex& v : eye) points.push_back(CachePoint{v.p, v.ng});
    // Cache points spread over the visible surfaces: about their spacing on a scene-sized area.
    Bounds3 b = ctx.scene.bounds();
    float diagonal = glm::length(b.max - b.min);
    pc_radius_ = points.empty() ? 1.f : 2.f * diagonal / std::sqrt(static_cast<float>(points.size()));
    if (!(pc_radius_ > 0.f) || !std::isfinite(pc_radius_)) pc_radius_ = 1.f;
    pc_.build_points(std::move(points), pc_radius_, ConnectionCache::Options{opt_.pc_records, 0.2});
    build_records(0xfffffffeu, stop);
    if (cut()) return false;
    pc_.freeze_statistics();
  }
  calibration_seconds_ = seconds_since(t0);
  return true;
}

void CachedConnector::calibrate(const std::vector<Vertex>& eye, const std::vector<Vertex>& eye_next,
                                const std::function<bool()>& stop) {
  if (opt_.hrr_c > 0.0) {
    C_ = opt_.hrr_c;
    return;
  }
  // Mean accepted count per eye vertex S(C) = mean_z sum_y min(C q_z / d^2, 1), estimated on at most
  // 128 pilot eye vertices and 2048 cache vertices, solved for S(C) = target by bisection on log C
  // (S grows with C). Per-eye sums are added in a fixed order, so C does not depend on threads.
  std::vector<SelLobe> lobes;
  size_t step = std::max<size_t>(1, eye.size() / 128);
  for (size_t i = 0; i < eye.size(); i += step) {
    SelLobe l = eye_lobe(eye[i], eye_next[i]);
    if (l.c > 0.0) lobes.push_back(l);
  }
  size_t V = cache_.vertex_count();
  C_ = 1.0;
  hrr_eligible_ = !lobes.empty();
  if (lobes.empty() || V == 0) return;
  std::vector<Vec3> ys;
  size_t vstep = std::max<size_t>(1, V / 2048);
  for (size_t i = 0; i < V; i += vstep) ys.push_back(cache_.positions()[i]);
  double scale = static_cast<double>(V) / ys.size();
  std::vector<double> per_lobe(lobes.size());
  auto mean_count = [&](double C) {
    tbb::parallel_for(size_t(0), lobes.size(), [&](size_t i) {
      HrrRange range(lobes[i], C);
      double sum = 0.0;
      for (const Vec3& y : ys) sum += range.acceptance(y);
      per_lobe[i] = sum;
    });
    double total = 0.0;
    for (double s : per_lobe) total += s;
    return total * scale / lobes.size();
  };
  double target = std::min(opt_.hrr_target, static_cast<double>(V));
  double lo = 1.0, hi = 1.0;
  auto cut = [&] { return stop && stop(); };
  for (int i = 0; i < 200 && !cut() && mean_count(lo) >= target; ++i) lo *= 0.01;
  for (int i = 0; i < 200 && !cut() && mean_count(hi) < target; ++i) hi *= 100.0;
  for (int i = 0; i < 40 && !cut(); ++i) {
    double mid = std::sqrt(lo * hi);
    (mean_count(mid) < target ? lo : hi) = mid;
  }
  C_ = hi;
}

void CachedConnector::build_records(uint32_t index, const std::function<bool()>& stop) {
  pc_.build_records(
      cache_.vertex_count(), opt_.seed, index,
      [&](int cp, uint32_t v) {
        LightCache::Ref r = cache_.ref(v);
        const Vertex* path = cache_.path(r.path);
        return pc_weight(path[r.vertex - 1], path[r.vertex], cp);
      },
      stop);
}

void CachedConnector::begin_iteration(const Context& ctx, const Sampler& proto, Point2i resolution, uint32_t index,
                                      const std::function<bool()>& stop) {
  auto t0 = std::chrono::steady_clock::now();
  cache_.trace(ctx, proto, resolution, index, M_, opt_.seed, stop);
  if (stop && stop()) return;
  trace_seconds_ += seconds_since(t0);
  ++iterations_;
  cached_vertices_ += cache_.vertex_count();
  if (opt_.hrr) {
    auto t1 = std::chrono::steady_clock::now();
    bvh_.build(cache_.positions());
    build_seconds_ += seconds_since(t1);
    bvh_bytes_ = bvh_.memory_bytes();
    bvh_vertices_ = bvh_.vertex_count();
  }
  if (opt_.probconnect) build_records(index, stop);
}

void CachedConnector::connect_eye_vertex(const Context& ctx, const Vertex* camera, int t, Point2i pixel,
                                         uint32_t index,
                                         const std::function<void(const Connection&, int s)>& emit) const {
  const Vertex& z = camera[t - 1];
  if (t < 2 || !is_connectible_surface(z)) return;
  Counters& counters = counters_.local();
  ++counters.eye_vertices;
  if (opt_.hrr && bvh_.vertex_count() > 0) {
    // A copy: the connections' MIS weights reuse the per-thread memo while the traversal runs.
    const std::optional<HrrRange> range = eye_range(z, camera[t - 2]);
    if (range) {
      ++counters.hrr_eye_vertices;
      HrrRandom rng{hash_ints(opt_.seed, pixel_key(pixel), index, static_cast<uint64_t>(t))};
      HrrTraversalStats stats;
      hrr_traverse(
          bvh_, *range, rng,
          [&](uint32_t v, double P, double) {
            LightCache::Ref r = cache_.ref(v);
            int s = static_cast<int>(r.vertex) + 1;
            if (s + t - 2 > max_depth_) return;
            Connection c = connect_cached(ctx, cache_.path(r.path), s, camera, t, Technique::Hrr,
                                          static_cast<double>(M_) * P);
            if (!is_black(c.L)) emit(c, s);
          },
          opt_.hrr_cull, &stats);
      counters.hrr_accepted += stats.accepted;
      counters.hrr_nodes += stats.nodes_visited;
    }
  }
  if (opt_.probconnect && cache_.vertex_count() > 0) {
    int cp = eye_cache_point(z, camera[t - 2]);
    if (cp < 0) return;
    Pcg32 rng(hash_ints(opt_.seed, pixel_key(pixel), index, static_cast<uint64_t>(t)), 0x50434f4eu /* "PCON" */);
    for (int d = 0; d < opt_.pc_connections; ++d) {
      std::optional<ConnectionCache::Pick> pick = pc_.sample(cp, rng.next_u32() * 0x1p-32);
      if (!pick) break;
      ++counters.pc_draws;
      LightCache::Ref r = cache_.ref(pick->vertex);
      int s = static_cast<int>(r.vertex) + 1;
      if (s + t - 2 > max_depth_) continue;
      double factor = opt_.pc_connections * static_cast<double>(M_) * pick->probability;
      Connection c = connect_cached(ctx, cache_.path(r.path), s, camera, t, Technique::ProbConnect, factor);
      if (!is_black(c.L)) emit(c, s);
    }
  }
}

std::vector<std::pair<std::string, double>> CachedConnector::statistics() const {
  Counters total;
  for (const Counters& c : counters_) {
    total.eye_vertices += c.eye_vertices;
    total.hrr_eye_vertices += c.hrr_eye_vertices;
    total.hrr_accepted += c.hrr_accepted;
    total.hrr_nodes += c.hrr_nodes;
    total.pc_draws += c.pc_draws;
  }
  double eyes = std::max<double>(1.0, static_cast<double>(total.eye_vertices));
  double iters = std::max<double>(1.0, static_cast<double>(iterations_));
  std::vector<std::pair<std::string, double>> s = {
      {"light_paths_per_iteration", static_cast<double>(M_)},
      {"light_vertices_per_iteration", cached_vertices_ / iters},
      {"light_cache_trace_seconds_per_iteration", trace_seconds_ / iters},
      {"light_cache_bytes", static_cast<double>(cache_.memory_bytes())},
      {"cached_eye_vertices", static_cast<double>(total.eye_vertices)},
      {"pilot_seconds", calibration_seconds_},
  };
  if (opt_.hrr) {
    s.push_back({"hrr_c", C_});
    s.push_back({"hrr_connections_per_eye_vertex", total.hrr_accepted / eyes});
    s.push_back({"hrr_eye_vertex_fraction", total.hrr_eye_vertices / eyes});
    s.push_back({"hrr_connections_per_hrr_eye_vertex",
                 total.hrr_accepted / std::max<double>(1.0, static_cast<double>(total.hrr_eye_vertices))});
    s.push_back({"hrr_nodes_visited_per_eye_vertex", total.hrr_nodes / eyes});
    s.push_back({"light_vertex_bvh_build_seconds", build_seconds_ / iters});
    s.push_back({"light_vertex_bvh_bytes_per_vertex",
                 bvh_vertices_ ? static_cast<double>(bvh_bytes_) / bvh_vertices_ : 0.0});
  }
  if (opt_.probconnect) {
    s.push_back({"pc_cache_points", static_cast<double>(pc_.point_count())});
    s.push_back({"pc_connections_per_eye_vertex", total.pc_draws / eyes});
    s.push_back({"pc_bytes", static_cast<double>(pc_.memory_bytes())});
  }
  return s;
}

CachedOptions read_cached_options(const ParamSet& p) {
  CachedOptions o;
  o.hrr = p.get_bool("hrr");
  o.hrr_c = p.get_float("hrrc");
  if (!(o.hrr_c >= 0.0) || !std::isfinite(o.hrr_c))
    throw Error(p.loc_of("hrrc"), "hrrc must be a finite number >= 0 (0: calibrate to hrrconnections)");
  int target = p.get_int("hrrconnections");
  if (target < 1) throw Error(p.loc_of("hrrconnections"), "hrrconnections must be >= 1");
  o.hrr_target = target;
  o.hrr_cull = p.get_bool("hrrcull");
  o.hrr_max_alpha = p.get_float("hrrmaxalpha");
  if (!(o.hrr_max_alpha > 0.0)) throw Error(p.loc_of("hrrmaxalpha"), "hrrmaxalpha must be > 0");
  o.probconnect = p.get_bool("probconnect");
  o.pc_connections = p.get_int("probconnections");
  if (o.pc_connections < 1) throw Error(p.loc_of("probconnections"), "probconnections must be >= 1");
  o.pc_records = p.get_int("pcrecords");
  if (o.pc_records < 1) throw Error(p.loc_of("pcrecords"), "pcrecords must be >= 1");
  int paths = p.get_int("lightpaths");
  if (paths < 0) throw Error(p.loc_of("lightpaths"), "lightpaths must be >= 0 (0: the pixel count)");
  o.light_paths = static_cast<size_t>(paths);
  return o;
}

}  // namespace penumbra::bdpt
