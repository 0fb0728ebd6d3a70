// Camera and light subpaths and their connections: the code that the "bdpt" and "lighttracing"
// integrators share (and that tests/bdpt_test.cpp compiles directly to check the MIS weights).
//
// MIS formulation: pbrt-v3's explicit per-vertex densities. Every vertex stores the area density of
// being generated from its own subpath's side (pdf_fwd) and from the other side (pdf_rev); a
// connection patches the few densities it changes and hands the whole path to mis.h, which chains
// the ratios p_i / p_s. Chosen over VCM's running partial sums because the next strategies to add
// (probabilistic connections and hierarchical Russian roulette, issue 6) have densities that depend
// on which eye vertex meets which light vertex (a cache lookup, a lobe-dependent acceptance
// probability): with explicit densities the weight can evaluate such a factor for every edge of the
// path at connection time, while partial sums would have to fold it in while the subpath is traced,
// before its partner is known. The cost is O(path length) per connection, which is small next to
// the shadow ray it comes with.
//
// Where every technique is a per-sample one (no cache: plain bdpt and light tracing), the weights do
// not walk the path. Once a subpath is traced, each vertex stores the sum over the strategies that
// move it and the vertices before it to the other side (Vertex::mis_sum, the ratio recurrence of
// mis.h folded from the subpath's start, the partial sums of VCM); a connection then changes only its
// two vertices on each side and reads the stored sum beyond them, in O(1). tests/bdpt_test.cpp checks
// both forms against brute force on real paths.
//
// Russian roulette is kept out of the MIS densities: the reverse density would need the roulette
// probability the *other* subpath would have used, which depends on a throughput that does not
// exist. Weights computed without it are still a partition of unity over the strategies that can
// produce a path, and every such strategy still produces it with non-zero probability, so the
// estimator stays unbiased; only the weights are slightly less than optimal for long paths.
#pragma once

#include <penumbra/params.h>

#include "mis.h"

#include <penumbra/bsdf.h>
#include <penumbra/camera.h>
#include <penumbra/light.h>
#include <penumbra/sampler.h>
#include <penumbra/scene.h>

#include <cstdint>
#include <limits>
#include <optional>
#include <type_traits>
#include <vector>

namespace penumbra::bdpt {

/// Light selection for emitted paths and next-event estimation (the MIS densities use the same pmf).
class LightChooser {
 public:
  /// uniform: every light equally likely; otherwise the scene's power distribution.
  LightChooser(const Scene& scene, bool uniform) : scene_(scene), uniform_(uniform) {}
  std::optional<SampledLight> sample(float u) const;
  float pmf(const Light* light) const;

 private:
  const Scene& scene_;
  bool uniform_;
};

enum class VertexKind : uint8_t { Camera, Light, Surface };

struct Vertex {
  VertexKind kind = VertexKind::Surface;
  // Surfaces: the BSDF has a non-delta lobe (connectible(); set once when the vertex is made, since
  // every connection asks, through two virtual calls into the BSDF's plugin). Fits in kind's padding.
  bool surface_connectible = false;
  Vec3 p{0.f};
  Vec3 p_error{0.f};      // bound on the floating-point error of p (surfaces), for ray offsets
  Vec3 ng{0.f}, ns{0.f};  // zero for points not on a surface (point lights, the lens)
  Frame shading;
  // Surfaces: where textured materials are evaluated (sc.tex; sc.tex.uv is the uv); every vertex: its
  // subpath's transport mode (sc.mode). Kept as the BSDF's argument itself, which every f(), pdf() and
  // sample_f() takes by reference, so the calls do not build one (76 bytes) each.
  ShadingContext sc;
  Vec3 wo{0.f};           // surfaces: unit direction towards the previous vertex of the subpath
  Vec3 wo_local{0.f};     // surfaces: wo in the shading frame (every f() and the sampling need it)
  // Surfaces: unit direction towards the previous vertex from their positions, in the shading frame:
  // what the densities use (see random_walk), made once instead of at every connection.
  Vec3 w_prev_local{0.f};
  Vec3 w_light{0.f};      // vertices at infinity (environment, distant light): direction light travels
  const Bsdf* bsdf = nullptr;
  const Light* light = nullptr;  // light endpoints, and surfaces that emit
  Rgb beta{0.f};          // subpath throughput up to and including this vertex's generation
  float pdf_fwd = 0.f;    // area density from the previous vertex of this subpath
  float pdf_rev = 0.f;    // area density from the next one, as if generated from the other end
  bool delta = false;     // scattered specularly towards the next vertex
  bool infinite = false;  // a direction rather than a point (escaped camera ray, environment, distant)
  MediumInterface media;  // surfaces: the media on their two sides (absorption between vertices)
  int16_t medium = kMediumUnknown;  // surfaces: the medium the subpath arrived in, where known
  // Light endpoints traced by light_subpath(): next_event_ratio(path[0], path[1]), which every
  // connection with s >= 2 light vertices needs for its MIS weight (NaN: not known, computed when
  // needed).
  float nee_ratio = std::numeric_limits<float>::quiet_NaN();
  // For vertex j of its subpath: the sum of (p_i / p_j')^beta over the possible strategies i that
  // give this vertex, and the vertices back to some earlier one, to the other subpath, where p_j' is
  // the strategy whose own side ends at this vertex (0 for the lens: no strategy moves it). Set by
  // camera_subpath() and light_subpath() for the O(1) weights (see the top of this file); valid for
  // every connection that changes neither this vertex nor those before it.
  double mis_sum = 0.0;

  bool on_surface() const { return ng != Vec3(0.f); }
  /// Whether a deterministic connection can end here (it needs a non-delta scattering or emission).
  bool connectible() const;
  /// BSDF towards `next` in this vertex's transport mode, with the adjoint shading-normal
  /// correction on light paths; 0 when the shading and geometric normals disagree about the side.
  Rgb f(const Vertex& next) const;
};

/// Unit direction from `from` towards `to` (towards the light for vertices at infinity).
inline Vec3 direction_to(const Vertex& from, const Vertex& to) {
  if (to.infinite) return -to.w_light;
  return glm::normalize(to.p - from.p);
}

struct Config {
  int max_depth = 5;  // bounces: strategies with s + t - 2 <= max_depth
  int rr_depth = 3;   // bounces of a subpath before Russian roulette may end it
  MisHeuristic heuristic = MisHeuristic::Balance;  // bdpt's default (docs/bdpt.md)
  // light_subpath() fills Vertex::nee_ratio and the folded sums (Vertex::mis_sum): every weighted
  // connection needs them; unweighted light tracing does not.
  bool store_nee_ratio = true;
};

/// Reads and checks the parameters bdpt and lighttracing share: "maxdepth", "rrdepth" and
/// "lightsampler" (power or uniform; `uniform_lights` is set for uniform). Throws located errors.
Config read_subpath_config(const ParamSet& p, bool* uniform_lights);

/// Sample dimensions at fixed offsets per purpose and depth, so that quasi-random samplers give
/// each decision the same dimension whatever happened elsewhere on the paths.
class PathSampler {
 public:
  PathSampler(Sampler& sampler, Point2i pixel, uint32_t index) : sampler_(sampler), pixel_(pixel), index_(index) {}
  // Dimensions 0-3 are the film position and the lens, 4 the wavelengths of a spectral render, all
  // drawn by the render loop. (The light subpath once started at 4: in a spectral render the light
  // choice then followed the wavelengths, and veach-bidir's two lights of different colours came out
  // 13 % too dark in red.)
  static constexpr uint32_t kLightChoice = 5, kLightPos = 6, kLightDir = 8, kLevels = 10, kPerLevel = 13;
  static uint32_t camera_bounce(int level) { return kLevels + kPerLevel * level; }       // 4: lobe, dir, roulette
  static uint32_t light_bounce(int level) { return kLevels + kPerLevel * level + 4; }    // 4
  static uint32_t next_event(int level) { return kLevels + kPerLevel * level + 8; }      // 3: light, point
  static uint32_t lens(int level) { return kLevels + kPerLevel * level + 11; }           // 2
  void seek(uint32_t dim) { sampler_.start_pixel_sample(pixel_, index_, dim); }
  float get_1d() { return sampler_.get_1d(); }
  Vec2 get_2d() { return sampler_.get_2d(); }

 private:
  Sampler& sampler_;
  Point2i pixel_;
  uint32_t index_;
};

/// Connection techniques: every strategy (s, t) can be sampled by several techniques, each with a
/// density c_tau * p_s where p_s is the strategy's path density (mis.h). The per-sample techniques have
/// c = 1 (or 0 when switched off); the cached ones (hierarchical Russian roulette over a light-vertex
/// cache, probabilistic connections) have a factor that depends on the edge they connect.
enum class Technique : uint8_t { Regular, Hrr, ProbConnect };

/// The factors of the cached techniques for an edge joining light-side vertex y (reached from y_prev on
/// the light side) and eye-side vertex z (whose eye-side neighbour is z_next): c_HRR = M P(y, z),
/// c_PC = n_c N_L P~(y | z). Must be a function of these four vertices only (never of the sample), so
/// that the MIS weights of all techniques for one path sum to 1. Implemented in connect_cached.cpp.
class CachedTechniques {
 public:
  virtual ~CachedTechniques() = default;
  virtual double factor(Technique tau, const Vertex& y_prev, const Vertex& y, const Vertex& z,
                        const Vertex& z_next) const = 0;
  virtual bool enabled(Technique tau) const = 0;
};

/// Which techniques are on. Emission hits (s = 0) are always on.
struct TechniqueSet {
  bool connect = true;     // s >= 2, t >= 2 with the sample's own light subpath
  bool nextevent = true;   // s = 1
  bool lighttrace = true;  // t = 1
  const CachedTechniques* cached = nullptr;
  bool all_regular() const { return connect && nextevent && lighttrace && !cached; }
};

struct Context {
  const Scene& scene;
  const LightChooser& lights;
  Config config;
  const TechniqueSet* techniques = nullptr;  // null: every per-sample technique, nothing cached
  /// A spectral render's wavelengths for the subpaths made and connected with this context (the
  /// sample's, or the pass's for a light-vertex cache): throughputs and contributions are then
  /// values at them. Null: RGB.
  const SampledWavelengths* wavelengths = nullptr;
};

/// Scratch storage for one subpath of `n` vertices, left uninitialised (the walks write every vertex
/// they return): on the stack up to kInline vertices (maxdepth 14), else a per-thread buffer (one per
/// Tag, so that a sample's two subpaths do not share it).
template <int Tag>
class SubpathStorage {
 public:
  static constexpr int kInline = 16;
  explicit SubpathStorage(int n) {
    if (n <= kInline) {
      data_ = inline_;
    } else {
      thread_local std::vector<Vertex> heap;
      if (static_cast<int>(heap.size()) < n) heap.resize(n);
      data_ = heap.data();
    }
  }
  ~SubpathStorage() {}
  SubpathStorage(const SubpathStorage&) = delete;
  SubpathStorage& operator=(const SubpathStorage&) = delete;
  Vertex* data() { return data_; }

 private:
  union {
    Vertex inline_[kInline];
  };
  Vertex* data_;
};

/// Traces the camera subpath of `ray` into path[0 .. max_depth + 1]; returns the vertex count.
int camera_subpath(const Context& ctx, const Ray& ray, PathSampler& ps, Vertex* path);
/// Traces a light subpath into path[0 .. max_depth]; returns the vertex count (0: no light).
int light_subpath(const Context& ctx, PathSampler& ps, Vertex* path);

static_assert(std::is_trivially_copyable_v<Vertex> && std::is_trivially_destructible_v<Vertex>);

struct Connection {
  Rgb L{0.f};          // unweighted contribution
  Rgb weighted{0.f};   // MIS-weighted contribution (what the image receives)
  double weight = 0.0; // MIS weight (for several environment lights: the last one's)
  bool splat = false;  // t = 1: lands at p_raster instead of the pixel being sampled
  Vec2 p_raster{0.f};
  bool has_sampled = false;
  // The endpoint drawn for s = 1 (light) or t = 1 (camera), valid only when has_sampled. Left
  // uninitialised otherwise: connect() runs about ten times per sample and most calls draw none,
  // and zeroing a vertex (272 bytes) each time was a visible part of its cost.
  union {
    Vertex sampled;
  };
  Connection() {}
};

/// Evaluates strategy (s, t) on the given subpaths. weighted = false skips MIS (weight 1), for pure
/// light tracing. Techniques switched off in ctx.techniques give nothing.
Connection connect(const Context& ctx, const Vertex* light, int s, const Vertex* camera, int t, PathSampler& ps,
                   bool weighted = true);

/// A cached technique's connection of light vertex light[s-1] (s >= 2, from a cached light subpath)
/// to camera vertex camera[t-1] (t >= 2): the regular connection divided by the technique's factor
/// `factor` (M P or n_c N_L P_j, the true selection density), MIS-weighted as technique `tau`.
Connection connect_cached(const Context& ctx, const Vertex* light, int s, const Vertex* camera, int t,
                          Technique tau, double factor);

/// MIS weight of strategy (s, t) sampled by technique `tau`; `light_end` / `camera_end` replace
/// light[s-1] / camera[t-1] when the connection drew its own endpoint (or, for s = 0, names the
/// environment light hit).
double mis_weight(const Context& ctx, const Vertex* light, int s, const Vertex* camera, int t,
                  const Vertex* light_end = nullptr, const Vertex* camera_end = nullptr,
                  Technique tau = Technique::Regular);

// Densities of single vertices, shared by the walks and the MIS weight.

/// Area density with which `cur` (reached from `prev`, null for endpoints) generates `next`.
float pdf_area(const Context& ctx, const Vertex* prev, const Vertex& cur, const Vertex& next);
/// Density with which the emitter at `cur` sends light to `next` (area, or planar for infinite lights).
float pdf_light_dir(const Vertex& cur, const Vertex& next);
/// Density of choosing `cur` as the origin of an emitted path (selection pmf included).
float pdf_light_origin(const Context& ctx, const Vertex& cur, const Vertex& next);
/// p_nee(x0 | x1) / pdf_light_origin(x0): how much more likely next-event estimation from x1 is to
/// pick x0 than emission sampling (1 unless x0 is on an area light or is a constant sky's direction).
double next_event_ratio(const Vertex& x0, const Vertex& x1);

}  // namespace penumbra::bdpt
