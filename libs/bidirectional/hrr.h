// Hierarchical Russian roulette (HRR) for connecting an eye vertex z to a large cache of light
// vertices {y_i} (Tokuyoshi & Harada, TOG 38(4), 2019; docs/algorithms.md and docs/hrr.md).
//
// Every pair (y_i, z) is kept with probability P(y_i, z) = min(C q(w) / d^2, 1), where q is an
// approximation of z's scattering lobe. Rather than drawing one uniform per pair, the numbers are
// generated top-down over a BVH of the light vertices: each subtree knows only the *minimum* of its
// numbers, and a subtree whose box misses the range that minimum allows is rejected as a whole.
//
// Pieces, in the order the algorithm uses them:
//
//  * SelLobe: q(w) = c K(w), with K the squared ellipsoid lobe (SEL). K is homogeneous of degree
//    -2, so the acceptance region {y : C q(w) / d^2 > xi} is the inside of an ellipsoid, which makes
//    the node test cheap and exact. Derivation (x = y - z in the lobe frame, a = max(alpha_x,
//    alpha_y), s = sqrt(C c / xi), K extended homogeneously so that C q(w)/d^2 = C c K(x)):
//    C c K(x) > xi  <=>  (U - x_z) + a^2 (U + x_z) < 2 a^2 s  <=>  (1 + a^2) U < 2 a^2 s + (1 - a^2) x_z.
//    Since U >= |x_z|, every solution has x_z > -a^2 s, where the right side is positive, so
//    squaring both sides is an equivalence; U^2 is quadratic in x and
//    (1 + a^2)^2 - (1 - a^2)^2 = 4 a^2, so the quadric completes to
//        x_x^2 / (s alpha_x)^2 + x_y^2 / (s alpha_y)^2 + (x_z - s (1 - a^2)/2)^2 / (s (1 + a^2)/2)^2 < 1:
//    an ellipsoid with semi-axes s alpha_x, s alpha_y, s (1 + a^2)/2, centred s (1 - a^2)/2 ahead
//    of z along the lobe axis. This is exact, not a bound (the dossier's [derived] claim holds; the
//    SEL geometry test finds boundary points on it to ~1e-10). z itself is inside it, s a^2 in front
//    of the back pole (a focus when alpha_x == alpha_y), and a = 1 gives the sphere of radius s
//    around z. A reflective z cuts the region by its tangent plane (the half space). The lobe
//    frame is re-orthonormalised in double, so "exact" holds for a float Frame too.
//
//  * LightVertexBvh: a binary BVH, one vertex per leaf, built by Embree's user-BVH builder
//    (binned SAH) and flattened into 32-byte nodes in depth-first order. The numbers of a traversal
//    are keyed by node index, so the tree must be a deterministic function of the points. Embree's
//    binned builder is: split decisions depend only on bin counts and bounds (exact min/max
//    reductions), and the one order-dependent step, the object-median fallback for coincident
//    centroids, sorts the primitives by id first (Embree's deterministic_order()). Verified: the
//    tests build 1e5 points (uniform, and a cloud with clusters and ~20 % coincident points) at 1 and
//    2 TBB threads and on a second device and compare the flattened trees byte for byte, so no
//    canonicalisation or builder of our own is needed. Boxes are recomputed bottom-up from the
//    leaves (exact float min/max), so a parent's box contains its children's bit for bit. Cost:
//    about 1 us per point (Embree's binned SAH spends most of it on the many tiny nodes of a
//    leaf-size-1 tree) and 64 bytes per point.
//
//  * StratifiedMinimum: the state (xi_min, b) of Algorithm 1 with the paper's semi-stratified
//    minimum (xi_min = xi / |L| at the root). At an internal node the child l that keeps the
//    minimum is picked with probability |L_l| / (|L_l| + |L_m|) and inherits the PARENT's state;
//    the other child m gets a fresh minimum in its stratum [b, b + (1 - b)/|L_m|). (The seed's
//    pseudo-code hands the new minimum to both children; that loses the real minimum, and the
//    marginal-uniformity test catches it.) b climbs toward 1 with depth, so b and 1 - b are both
//    kept in double: b is added to (accurate while b is small) and 1 - b is multiplied by
//    (1 - 1/|L_m|) (accurate while b is near 1; docs/algorithms.md, "The bound b"). A float b does stall, but only
//    in very deep trees: along any path b <= (depth + 1)/|L|, so the step (1 - b)/|L_m| is at least
//    ~b/depth (~1/depth^2 once b nears 1); the tests build a chain of depth 2^26 to show the stall.
//    In float, 1 - b does stall in ordinary trees (1 - 2^-40 rounds to 1), which the tests also
//    show. xi/|L| keeps full relative precision for any |L| (one division, no 1 - (1 - xi)^(1/N)
//    cancellation; docs/algorithms.md, "The minimum of N uniforms").
//
//  * HrrRandom: counter-based numbers hash(seed, node, slot), so a culled traversal and an unculled
//    one see the same number at the same node. That is what makes "culling changes nothing but the
//    cost" testable exactly.
//
//  * HrrRange: the conservative node test (the ellipsoid mapped to the unit sphere, Arvo's box
//    test, plus the half space), and the leaf test P, sharing one double-precision evaluation so
//    that the two can never disagree by more than the node test's explicit slack.
//
//  * hrr_walk / hrr_traverse: Algorithm 1 with an explicit fixed-size stack (no allocation, no
//    std::function). hrr_walk is the bare generator (callers choose the pruning and the leaf
//    action; tests use it to observe every leaf's number); hrr_traverse adds the lobe.
#pragma once

#include <penumbra/bsdf.h>
#include <penumbra/math.h>
#include <penumbra/rng.h>

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

namespace penumbra::bdpt {

using Vec3d = glm::dvec3;

// ---------------------------------------------------------------------------------------------
// Squared ellipsoid lobe

/// The SEL in the lobe's local frame, extended homogeneously (degree -2) to any non-zero x:
/// sel_kernel(x) = K(x / |x|) / |x|^2. For a unit x it is K itself, peak value 1 at +z.
/// Returns +infinity for x == 0.
double sel_kernel(const Vec3d& x, double alpha_x, double alpha_y);

/// Squared ellipsoid lobe (SEL) approximating the scattering lobe of an eye vertex z, world space.
struct SelLobe {
  Vec3 z{0.f};                          // eye vertex position
  Frame frame;                          // frame.n: lobe axis (unit); frame.s / frame.t: axes of alpha_x / alpha_y
  double alpha_x = 1.0, alpha_y = 1.0;  // clamped to [1e-3, 1]; alpha 1 and 1 gives K == 1 (a sphere)
  double c = 0.0;                       // coefficient >= 0: q at the peak
  Vec3 half_space{0.f};                 // if non-zero: q(w) = 0 for dot(w, half_space) <= 0 (a reflective z)

  /// The frame's axes re-orthonormalised in double (n first, then s; t = n x s). Everything below
  /// works in these, so the SEL is an exact rotation of the local one even for a float frame.
  struct Axes {
    Vec3d s, t, n;
  };
  Axes axes() const;

  /// SEL function of a unit world direction, peak value 1 (at axes().n).
  double K(const Vec3& w) const;
  double K(const Vec3d& w) const;
  /// c * K(w), 0 outside the half space.
  double q(const Vec3& w) const;
  double q(const Vec3d& w) const;

  /// The acceptance region {y : c K(y - z) > 1 / s^2}, s = sqrt(C c / xi), as an ellipsoid
  /// (before the half-space cut). See the header comment.
  struct Ellipsoid {
    Vec3d centre;
    Vec3d semi_axes;  // along axes.s, axes.t, axes.n
    Axes axes;
  };
  Ellipsoid range_ellipsoid(double s) const;
};

/// The lobe of an eye vertex at world position z with shading frame `shading` from a BSDF's
/// LobeSummary (peak in the local shading frame). A GGX lobe becomes K(w; Q_peak, alpha_x, alpha_y):
/// the reflected-direction lobe of a GGX with roughness alpha is ~ K with the SAME alpha around the
/// mirror direction, since theta_half ~ theta_refl / 2 and pi alpha^2 D ~ K(alpha / 2) (derived in
/// docs/hrr.md, "HRR at one eye vertex"; checked against the real BSDF in the tests). Its tangent axes are the shading s/t
/// axes projected perpendicular to the peak. A cosine lobe becomes the sphere (alpha 1), a valid
/// bound for rho/pi cos. c (the BSDF * cos at the peak) and the half space come from the caller.
SelLobe make_sel_lobe(const Vec3& z, const Frame& shading, const LobeSummary& lobe, double c,
                      const Vec3& half_space);

/// P(y, z) = min(C q(w) / d^2, 1) with w = (y - z) / d, d = |y - z|, evaluated in double as
/// min(C c sel_kernel(L (y - z)), 1) (homogeneity: no normalisation needed).
/// d == 0 gives 0: the direction is undefined and the connection degenerate (G has 1/d^2), and
/// rejecting a measure-zero set of pairs biases nothing. Non-finite products (C = inf times an
/// underflowed K) also give 0.
double hrr_acceptance(const SelLobe& lobe, double C, const Vec3& y);

// ---------------------------------------------------------------------------------------------
// BVH over light vertices

/// Binary BVH over light-vertex positions, leaf size 1, each node with AABB and leaf count, built
/// with Embree's builder API (binned SAH, RTC_BUILD_QUALITY_MEDIUM) and flattened into a compact
/// node array in depth-first order: a node's first child is the next node, its second child is
/// stored. Owns its RTCDevice (created once in the constructor); the Embree BVH is created and
/// released per build, so only the flattened nodes stay in memory (32 bytes * (2N - 1)).
/// Deterministic (see the header comment). Up to 2^31 - 1 finite points.
class LightVertexBvh {
 public:
  struct Node {
    Vec3 lo;         // box (for a leaf: lo == hi == the vertex)
    uint32_t count;  // leaves below this node, |L|; 1 for a leaf
    Vec3 hi;
    uint32_t index;  // leaf: vertex index; internal: index of the second child (the first is this + 1)

    bool is_leaf() const { return count == 1; }
    uint32_t vertex() const { return index; }
    uint32_t second_child() const { return index; }
  };
  static_assert(sizeof(Node) == 32);

  /// Depth bound handed to Embree (its root is depth 1); also sizes the traversal stack.
  static constexpr uint32_t kMaxDepth = 128;

  LightVertexBvh();
  ~LightVertexBvh();
  LightVertexBvh(const LightVertexBvh&) = delete;
  LightVertexBvh& operator=(const LightVertexBvh&) = delete;

  /// Rebuilds over `points` (an empty span gives an empty tree). Throws std::invalid_argument for
  /// non-finite points or too many of them, std::runtime_error if Embree fails.
  void build(std::span<const Vec3> points);

  size_t vertex_count() const { return vertex_count_; }
  size_t node_count() const { return nodes_.size(); }
  /// Bytes of the flattened tree.
  size_t memory_bytes() const { return nodes_.size() * sizeof(Node); }
  double last_build_seconds() const { return build_seconds_; }
  /// Levels of the tree (a lone leaf: 1; empty: 0).
  uint32_t depth() const { return depth_; }

  std::span<const Node> nodes() const { return nodes_; }
  const Node& node(size_t i) const { return nodes_[i]; }

 private:
  struct Embree;  // device handle; keeps Embree's headers out of this one
  std::unique_ptr<Embree> embree_;
  std::vector<Node> nodes_;
  size_t vertex_count_ = 0;
  double build_seconds_ = 0.0;
  uint32_t depth_ = 0;

  void flatten_from(const void* embree_root, std::span<const Vec3> points);
  void finish_nodes();
};

// ---------------------------------------------------------------------------------------------
// Random numbers and the stratified minimum

/// Counter-based random numbers for one eye vertex: value(key, slot) is a uniform double in [0,1)
/// with 53 random bits from hash_ints(seed, key, slot). Keyed by node so that a culled traversal and
/// an unculled one see the same numbers for the same nodes.
struct HrrRandom {
  uint64_t seed;
  uint64_t bits(uint64_t node, uint32_t slot) const { return hash_ints(seed, node, slot); }
  double operator()(uint64_t node, uint32_t slot) const {
    return static_cast<double>(bits(node, slot) >> 11) * 0x1p-53;
  }
};

/// Slots of HrrRandom used at a node.
enum HrrSlot : uint32_t {
  kSlotRootMinimum = 0,  // root only: xi of xi_min = xi / |L_root|
  kSlotPickChild = 1,    // internal: which child keeps the minimum
  kSlotFreshMinimum = 2, // internal: xi' of the other child's minimum
};

/// (xi_min, b) of Algorithm 1 for one subtree: xi_min is the smallest of the subtree's numbers,
/// every other number lies in [b, 1). 1 - b is carried separately (multiplicative update) so that
/// the strata keep their width when b is close to 1; b itself is carried additively so that it
/// keeps its relative precision when it is small. The two agree to ~1e-16 absolute.
/// Deliberately trivial (no member initialisers): the traversal's fixed stack of these is then
/// left uninitialised instead of being filled on every call. root() and other_child() set all fields.
struct StratifiedMinimum {
  double xi_min;
  double b;
  double one_minus_b;

  /// Largest double below 1: numbers stay in [0, 1) even if b + (1 - b) rounds up.
  static constexpr double kBelowOne = 0x1.fffffffffffffp-1;

  /// Root of a tree with n >= 1 leaves: the minimum of n stratified uniforms is xi / n.
  static StratifiedMinimum root(double xi, uint64_t n);

  /// State of the child m (n_other leaves) that does NOT keep the minimum: its minimum is fresh in
  /// [b, b + (1 - b)/n_other), and its other numbers lie above b' = b + (1 - b)/n_other.
  StratifiedMinimum other_child(uint64_t n_other, double xi) const;

  struct Children;
  /// The child l keeping the minimum inherits this state unchanged.
  Children split(uint64_t n_other, double xi) const;
};

struct StratifiedMinimum::Children {
  StratifiedMinimum keeper, other;
};

inline StratifiedMinimum::Children StratifiedMinimum::split(uint64_t n_other, double xi) const {
  return {*this, other_child(n_other, xi)};
}

struct HrrTraversalStats {
  uint64_t nodes_visited = 0, leaves_tested = 0, accepted = 0;
};

/// Picks the child that keeps the minimum: true for the first child with probability
/// n_first / (n_first + n_second), exactly up to 2^-64 (Lemire's multiply-high range reduction).
inline bool first_child_keeps_minimum(uint64_t bits, uint64_t n_first, uint64_t n_second) {
  unsigned __int128 product = static_cast<unsigned __int128>(bits) * (n_first + n_second);
  return static_cast<uint64_t>(product >> 64) < n_first;
}

/// Algorithm 1 as a generator: walks the tree depth-first, carrying each subtree's Minimum state.
/// prune(node, xi_min) -> bool skips a subtree (true = skip); leaf(vertex, node, xi) receives the
/// number of every leaf that was not pruned. Minimum is StratifiedMinimum except in tests.
template <class Minimum = StratifiedMinimum, class Prune, class Leaf>
void hrr_walk(const LightVertexBvh& bvh, const HrrRandom& rng, Prune&& prune, Leaf&& leaf,
              HrrTraversalStats* stats = nullptr) {
  if (bvh.node_count() == 0) return;
  using Node = LightVertexBvh::Node;
  struct Entry {
    uint32_t node;
    Minimum state;
  };
  // Depth-first with the first child processed next: at most one pending sibling per level.
  std::array<Entry, LightVertexBvh::kMaxDepth + 1> stack;
  size_t top = 0;
  stack[top++] = {0u, Minimum::root(rng(0, kSlotRootMinimum), bvh.node(0).count)};
  while (top > 0) {
    const Entry entry = stack[--top];
    const Node& node = bvh.node(entry.node);
    if (stats) ++stats->nodes_visited;
    if (prune(node, entry.state.xi_min)) continue;
    if (node.is_leaf()) {
      if (stats) ++stats->leaves_tested;
      leaf(node.vertex(), node, entry.state.xi_min);
      continue;
    }
    const uint32_t first = entry.node + 1, second = node.second_child();
    const uint64_t n_first = bvh.node(first).count, n_second = bvh.node(second).count;
    const bool first_keeps = first_child_keeps_minimum(rng.bits(entry.node, kSlotPickChild), n_first, n_second);
    const auto children = entry.state.split(first_keeps ? n_second : n_first, rng(entry.node, kSlotFreshMinimum));
    stack[top++] = {second, first_keeps ? children.other : children.keeper};
    stack[top++] = {first, first_keeps ? children.keeper : children.other};
  }
}

// ---------------------------------------------------------------------------------------------
// Range test and traversal

/// The lobe in double precision plus the range test for one (lobe, C). Both the leaf test P and the
/// node test go through this, so the node test only needs slack for its own rounding.
class HrrRange {
 public:
  HrrRange(const SelLobe& lobe, double C);

  /// P(y, z); bit-identical to hrr_acceptance(lobe, C, y).
  double acceptance(const Vec3& y) const;

  /// False only if no point of the box [lo, hi] can have P > xi_min (conservative). xi_min == 0
  /// means an infinite range: only the half space can then reject the box.
  bool may_accept(const Vec3& lo, const Vec3& hi, double xi_min) const;

 private:
  Vec3d z_;
  SelLobe::Axes axes_;
  Vec3d h_;
  double alpha_x_, alpha_y_, cc_;  // cc_ = C * c
  bool nothing_ = false;           // C c == 0 (or NaN): P == 0 everywhere
  bool has_half_ = false;
  // Sphere space: u = inv_s * M0 (p - z) - (0, 0, kappa) maps the range ellipsoid to the unit ball,
  // with inv_s = sqrt(xi_min / (C c)); M0's rows are s / alpha_x, t / alpha_y, n * 2 / (1 + a^2).
  std::array<Vec3d, 3> m0_, abs_m0_;
  double kappa_ = 0.0, inv_sqrt_cc_ = 0.0;
};

/// Tokuyoshi & Harada's Algorithm 1 with the stratified minimum. A leaf (vertex y) is accepted iff
/// xi_min < P(y, z); then accept(vertex_index, P, xi_leaf) is called. With cull = true, nodes whose
/// box cannot meet the acceptance region of their xi_min (the ellipsoid cut by the half space) are
/// skipped; that changes only the cost, never the accepted pairs. This form takes the eye vertex's
/// range already built (for callers that also need P elsewhere); the one below builds it.
template <class Accept>
void hrr_traverse(const LightVertexBvh& bvh, const HrrRange& range, const HrrRandom& rng, Accept&& accept,
                  bool cull = true, HrrTraversalStats* stats = nullptr) {
  using Node = LightVertexBvh::Node;
  hrr_walk(
      bvh, rng,
      // Leaves are decided by the exact test alone (the box test of a leaf would only repeat it,
      // conservatively and at twice the cost: culling never rejects a vertex the exact test accepts).
      [&](const Node& node, double xi_min) {
        return cull && !node.is_leaf() && !range.may_accept(node.lo, node.hi, xi_min);
      },
      [&](uint32_t vertex, const Node& node, double xi) {
        const double P = range.acceptance(node.lo);
        if (xi < P) {
          if (stats) ++stats->accepted;
          accept(vertex, P, xi);
        }
      },
      stats);
}

template <class Accept>
void hrr_traverse(const LightVertexBvh& bvh, const SelLobe& lobe, double C, const HrrRandom& rng,
                  Accept&& accept, bool cull = true, HrrTraversalStats* stats = nullptr) {
  hrr_traverse(bvh, HrrRange(lobe, C), rng, std::forward<Accept>(accept), cull, stats);
}

}  // namespace penumbra::bdpt
