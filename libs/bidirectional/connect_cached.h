// The cached connection techniques of "bdpt" (issue 6): per iteration a light-vertex cache of M light
// subpaths (light_cache.h) with a BVH over its vertices; each non-specular camera vertex then
//  - connects by hierarchical Russian roulette (Tokuyoshi & Harada 2019, hrr.h) to every cached
//    vertex y it accepts with probability P(y, z) = min(C q_z(w) / d^2, 1): density c = M P;
//  - draws n_c cached vertices by probabilistic connections (Popov et al. 2015, prob_connect.h) from
//    the records of its cache point: density c = n_c M P_j.
// Both are ordinary strategies (s, t) of the path space with a density factor c per edge, so they
// enter the MIS of every other strategy through CachedTechniques::factor() (subpath.h, mis.h).
//
// Exactness: the factors used in the MIS weights are functions of the path's vertices and of
// quantities fixed before the render (C, the cache points and the probabilistic connections' pilot
// statistics), never of the iteration's samples, so the weights of every technique for one path sum
// to 1 exactly and the image is unbiased whatever subset of techniques is on.
#pragma once

#include "hrr.h"
#include "light_cache.h"
#include "prob_connect.h"
#include "subpath.h"

#include <tbb/enumerable_thread_specific.h>

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace penumbra::bdpt {

struct CachedOptions {
  bool hrr = false;
  double hrr_c = 0.0;          // C; 0: calibrate to hrr_target connections per eye vertex
  double hrr_target = 32.0;
  bool hrr_cull = true;
  double hrr_max_alpha = 0.3;  // HRR only at eye vertices whose lobe has max(alpha) <= this
  bool probconnect = false;
  int pc_connections = 4;      // n_c
  int pc_records = 100;        // R
  size_t light_paths = 0;      // M; 0: the pixel count
  uint64_t seed = 0;
};

/// Reads and checks bdpt's parameters of the cached techniques (hrr*, probconnect, probconnections,
/// pcrecords, lightpaths); throws located errors. The seed is set at render time.
CachedOptions read_cached_options(const ParamSet& p);

class CachedConnector final : public CachedTechniques {
 public:
  CachedConnector(const CachedOptions& options, int max_depth);
  ~CachedConnector() override;

  /// Before the render: a pilot cache and pilot camera paths fix C (calibration), the cache points
  /// of probabilistic connections and their frozen statistics.
  /// `stop` (the render's time budget is spent) cuts the work short; the render then takes no
  /// sample with what is left. Returns false when it was cut.
  bool prepare(const Context& ctx, const Sampler& proto, Point2i resolution, const std::function<bool()>& stop = {});
  /// Before iteration `index`: traces the cache, rebuilds the BVH and the records (cut short by
  /// `stop` as prepare() is).
  void begin_iteration(const Context& ctx, const Sampler& proto, Point2i resolution, uint32_t index,
                       const std::function<bool()>& stop = {});

  const LightCache& cache() const { return cache_; }
  const ConnectionCache& connection_cache() const { return pc_; }
  size_t light_paths() const { return M_; }
  double hrr_c() const { return C_; }
  /// Whether the pilot found an eye vertex where HRR may connect (a lobe within hrr_max_alpha).
  bool hrr_eligible() const { return hrr_eligible_; }

  /// Every cached connection of camera vertex camera[t-1] (t >= 2); `emit` receives each one.
  void connect_eye_vertex(const Context& ctx, const Vertex* camera, int t, Point2i pixel, uint32_t index,
                          const std::function<void(const Connection&, int s)>& emit) const;

  // CachedTechniques
  double factor(Technique tau, const Vertex& y_prev, const Vertex& y, const Vertex& z,
                const Vertex& z_next) const override;
  bool enabled(Technique tau) const override;

  /// The lobe of eye vertex z towards its eye-side neighbour (c = 0: HRR does not apply at z).
  SelLobe eye_lobe(const Vertex& z, const Vertex& z_next) const;
  /// HRR's acceptance range at eye vertex z (empty: HRR does not apply there) and z's cache point
  /// (-1: none), from a small per-thread memo: the MIS weights of a sample's connections ask for the
  /// same eye vertices again and again. The reference is valid until the next call on this thread.
  const std::optional<HrrRange>& eye_range(const Vertex& z, const Vertex& z_next) const;
  int eye_cache_point(const Vertex& z, const Vertex& z_next) const;
  /// Probabilistic connections' weight of light vertex y (reached from y_prev) for cache point cp.
  double pc_weight(const Vertex& y_prev, const Vertex& y, int cp) const;

  /// Figures for the render's stats.
  std::vector<std::pair<std::string, double>> statistics() const;

 private:
  void calibrate(const std::vector<Vertex>& eye_vertices, const std::vector<Vertex>& eye_next,
                 const std::function<bool()>& stop);
  void build_records(uint32_t index, const std::function<bool()>& stop);

  CachedOptions opt_;
  int max_depth_;
  uint64_t id_;  // unique per connector (keys per-thread memos)
  size_t M_ = 0;
  double C_ = 0.0;
  bool hrr_eligible_ = false;
  LightCache cache_;
  LightVertexBvh bvh_;
  ConnectionCache pc_;
  float pc_radius_ = 0.f;
  // Statistics, counted per thread (a shared atomic per eye vertex would bounce one cache line
  // between all threads) and summed by statistics().
  struct alignas(64) Counters {
    uint64_t eye_vertices = 0, hrr_eye_vertices = 0, hrr_accepted = 0, hrr_nodes = 0, pc_draws = 0;
  };
  mutable tbb::enumerable_thread_specific<Counters> counters_;
  double build_seconds_ = 0.0, trace_seconds_ = 0.0, calibration_seconds_ = 0.0;
  uint64_t iterations_ = 0, cached_vertices_ = 0;
  size_t bvh_bytes_ = 0, bvh_vertices_ = 0;
};

}  // namespace penumbra::bdpt
