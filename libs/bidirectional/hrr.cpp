// Hierarchical Russian roulette: the SEL lobe, the acceptance probability and range test, the
// stratified minimum, and the light-vertex BVH built with Embree's user-BVH builder. The design and
// the derivations are in hrr.h.
#include "hrr.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>

namespace penumbra::bdpt {

namespace {

Vec3d to_double(const Vec3& v) { return Vec3d(v.x, v.y, v.z); }

/// The SEL is defined for alpha in [1e-3, 1]; every user of a lobe's alphas goes through this so
/// that K, P and the range test always see the same numbers, even for a hand-made SelLobe.
double effective_alpha(double alpha) { return std::isnan(alpha) ? 1.0 : std::clamp(alpha, 1e-3, 1.0); }

/// The lobe frame re-orthonormalised in double (Gram-Schmidt from n, then s). A float Frame is
/// orthonormal only to ~1e-7, which for alpha = 1e-3 would shift the ellipsoid by ~1e-5 of its
/// width; in double the local map is a rotation and the ellipsoid of hrr.h is exact.
SelLobe::Axes orthonormal_axes(const Frame& frame) {
  Vec3d n = to_double(frame.n);
  const double n_len = glm::length(n);
  n = n_len > 0.0 && std::isfinite(n_len) ? n / n_len : Vec3d(0.0, 0.0, 1.0);
  Vec3d s = to_double(frame.s);
  s -= n * glm::dot(s, n);
  const double s_len = glm::length(s);
  if (s_len > 1e-6 && std::isfinite(s_len)) {
    s /= s_len;
  } else {  // no usable tangent: any will do for the axes' roles are then arbitrary anyway
    s = glm::normalize(glm::cross(n, std::abs(n.x) < 0.9 ? Vec3d(1.0, 0.0, 0.0) : Vec3d(0.0, 1.0, 0.0)));
  }
  return {s, glm::cross(n, s), n};
}

/// Coordinates of a world vector along the lobe's axes.
Vec3d lobe_coordinates(const SelLobe::Axes& axes, const Vec3d& v) {
  return {glm::dot(v, axes.s), glm::dot(v, axes.t), glm::dot(v, axes.n)};
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// SEL

double sel_kernel(const Vec3d& x, double alpha_x, double alpha_y) {
  // K = 4 a^4 / ((U - x_z) + a^2 (U + x_z))^2 with U = |diag(a/alpha_x, a/alpha_y, 1) x|. One of
  // U -+ x_z cancels on the axis (forward for U - x_z, backward for U + x_z); there it is rewritten
  // as tangential / (U +- x_z), so K keeps full relative precision everywhere. That matters: the
  // range test trusts P to ~1e-15, and a narrow lobe lives within 1e-3 of its axis.
  const double a = std::max(alpha_x, alpha_y), a2 = a * a;
  const double sx = x.x * (a / alpha_x), sy = x.y * (a / alpha_y);
  const double tangential = sx * sx + sy * sy;
  const double U = std::sqrt(tangential + x.z * x.z);
  double u_minus_z, u_plus_z;
  if (x.z >= 0.0) {
    u_plus_z = U + x.z;
    u_minus_z = u_plus_z > 0.0 ? tangential / u_plus_z : 0.0;
  } else {
    u_minus_z = U - x.z;
    u_plus_z = tangential / u_minus_z;
  }
  const double denom = u_minus_z + a2 * u_plus_z;
  if (!(denom > 0.0)) return std::numeric_limits<double>::infinity();  // x == 0
  return 4.0 * a2 * a2 / (denom * denom);
}

SelLobe::Axes SelLobe::axes() const { return orthonormal_axes(frame); }

double SelLobe::K(const Vec3d& w) const {
  return sel_kernel(lobe_coordinates(axes(), w), effective_alpha(alpha_x), effective_alpha(alpha_y));
}
double SelLobe::K(const Vec3& w) const { return K(to_double(w)); }

double SelLobe::q(const Vec3d& w) const {
  if (half_space != Vec3(0.f) && !(glm::dot(w, to_double(half_space)) > 0.0)) return 0.0;
  return c * K(w);
}
double SelLobe::q(const Vec3& w) const { return q(to_double(w)); }

SelLobe::Ellipsoid SelLobe::range_ellipsoid(double s) const {
  const double ax = effective_alpha(alpha_x), ay = effective_alpha(alpha_y);
  const double a2 = std::max(ax, ay) * std::max(ax, ay);
  const Axes frame_axes = axes();
  return {to_double(z) + frame_axes.n * (s * (1.0 - a2) / 2.0), Vec3d(s * ax, s * ay, s * (1.0 + a2) / 2.0),
          frame_axes};
}

SelLobe make_sel_lobe(const Vec3& z, const Frame& shading, const LobeSummary& summary, double c,
                      const Vec3& half_space) {
  SelLobe lobe;
  lobe.z = z;
  lobe.c = c > 0.0 ? c : 0.0;  // also maps NaN to "no lobe"
  lobe.half_space = half_space;

  Vec3 axis = shading.to_world(summary.peak);
  float len = glm::length(axis);
  axis = len > 0.f && std::isfinite(len) ? axis / len : shading.n;
  if (summary.cosine) {
    // K == 1 for alpha 1 whatever the tangents: any frame around the axis will do.
    lobe.frame = Frame(axis);
    lobe.alpha_x = lobe.alpha_y = 1.0;
    return lobe;
  }

  // Tangent axes: the shading s axis projected perpendicular to the peak keeps alpha_x on the
  // direction it describes. If s is (nearly) the peak itself, go through t instead.
  Vec3 s = shading.s - axis * glm::dot(shading.s, axis);
  Vec3 t;
  if (glm::dot(s, s) > 1e-6f) {
    s = glm::normalize(s);
    t = glm::cross(axis, s);
  } else {
    t = glm::normalize(shading.t - axis * glm::dot(shading.t, axis));
    s = glm::cross(t, axis);
  }
  lobe.frame.s = s;
  lobe.frame.t = t;
  lobe.frame.n = axis;
  lobe.alpha_x = effective_alpha(summary.alpha_x);
  lobe.alpha_y = effective_alpha(summary.alpha_y);
  return lobe;
}

// ---------------------------------------------------------------------------------------------
// Acceptance and range test

HrrRange::HrrRange(const SelLobe& lobe, double C)
    : z_(to_double(lobe.z)),
      axes_(orthonormal_axes(lobe.frame)),
      h_(to_double(lobe.half_space)),
      alpha_x_(effective_alpha(lobe.alpha_x)),
      alpha_y_(effective_alpha(lobe.alpha_y)),
      cc_(C * lobe.c) {
  nothing_ = !(cc_ > 0.0);
  has_half_ = h_ != Vec3d(0.0);
  const double a = std::max(alpha_x_, alpha_y_), a2 = a * a;
  m0_ = {axes_.s / alpha_x_, axes_.t / alpha_y_, axes_.n * (2.0 / (1.0 + a2))};
  for (int k = 0; k < 3; ++k) abs_m0_[k] = glm::abs(m0_[k]);
  kappa_ = (1.0 - a2) / (1.0 + a2);  // z's image in sphere space is (0, 0, -kappa)
  inv_sqrt_cc_ = nothing_ ? 0.0 : 1.0 / std::sqrt(cc_);  // 0 for C c = inf: no range culling
}

double HrrRange::acceptance(const Vec3& y) const {
  if (nothing_) return 0.0;
  const Vec3d v = to_double(y) - z_;
  if (has_half_ && !(glm::dot(v, h_) > 0.0)) return 0.0;
  if (v == Vec3d(0.0)) return 0.0;  // degenerate pair, see hrr_acceptance()
  // Homogeneity: C q(v/d) / d^2 = C c K(v) for the unnormalised v.
  const Vec3d x = lobe_coordinates(axes_, v);
  const double p = cc_ * sel_kernel(x, alpha_x_, alpha_y_);
  if (!(p > 0.0)) return 0.0;  // also NaN (inf * 0)
  return p < 1.0 ? p : 1.0;
}

bool HrrRange::may_accept(const Vec3& lo_f, const Vec3& hi_f, double xi_min) const {
  if (nothing_) return false;
  const Vec3d lo = to_double(lo_f), hi = to_double(hi_f);
  const Vec3d centre = (lo + hi) * 0.5, half = (hi - lo) * 0.5;
  const Vec3d rel = centre - z_;

  // Entirely on the closed back side of the half space: q == 0 there. For a leaf box this is the
  // same dot product as in acceptance(), so slack >= 0 can never cull an accepted vertex; for a
  // larger box the slack dwarfs the rounding of the support value.
  if (has_half_) {
    const Vec3d abs_h = glm::abs(h_);
    const double support = glm::dot(rel, h_) + glm::dot(half, abs_h);
    const double slack = 1e-9 * (glm::dot(glm::abs(rel), abs_h) + glm::dot(half, abs_h));
    if (support + slack <= 0.0) return false;
  }

  // Sphere space: the range ellipsoid of xi_min becomes the unit ball, the box a parallelepiped
  // whose AABB is centre +- |M| half (exactly the AABB of the mapped corners). Arvo's test on that
  // AABB. xi_min == 0 gives inv_s == 0: every box maps onto z's image, inside the ball. The slack
  // (1e-9 relative, 1e-9 absolute) covers the double rounding here and in P by many orders of
  // magnitude while costing no measurable culling.
  const double inv_s = std::sqrt(xi_min) * inv_sqrt_cc_;
  double dist2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double c = inv_s * glm::dot(m0_[k], rel) - (k == 2 ? kappa_ : 0.0);
    const double e = inv_s * glm::dot(abs_m0_[k], half);
    const double gap = std::abs(c) - e - 1e-9 * (std::abs(c) + e + 1.0);
    if (gap > 0.0) dist2 += gap * gap;
  }
  return !(dist2 > 1.0);  // NaN keeps the box
}

double hrr_acceptance(const SelLobe& lobe, double C, const Vec3& y) { return HrrRange(lobe, C).acceptance(y); }

// ---------------------------------------------------------------------------------------------
// Stratified minimum

StratifiedMinimum StratifiedMinimum::root(double xi, uint64_t n) {
  const double dn = static_cast<double>(n);
  StratifiedMinimum m{};
  m.xi_min = xi / dn;
  m.b = 1.0 / dn;
  m.one_minus_b = static_cast<double>(n - 1) / dn;
  return m;
}

StratifiedMinimum StratifiedMinimum::other_child(uint64_t n_other, double xi) const {
  const double dn = static_cast<double>(n_other);
  const double width = one_minus_b / dn;  // the other child's stratum [b, b + width)
  StratifiedMinimum m{};
  m.xi_min = std::min(b + width * xi, kBelowOne);
  m.b = b + width;
  m.one_minus_b = one_minus_b * (static_cast<double>(n_other - 1) / dn);
  return m;
}

// ---------------------------------------------------------------------------------------------
// BVH

struct LightVertexBvh::Embree {
  RTCDevice device = nullptr;
  std::mutex mutex;
  std::string message;  // first Embree error of the current build

  Embree() {
    device = rtcNewDevice(nullptr);
    if (!device) throw std::runtime_error("hrr: cannot create an Embree device");
    rtcSetDeviceErrorFunction(device, &Embree::on_error, this);
  }
  ~Embree() { rtcReleaseDevice(device); }

  static void on_error(void* user, RTCError, const char* text) {
    auto* self = static_cast<Embree*>(user);
    std::lock_guard lock(self->mutex);
    if (self->message.empty()) self->message = text ? text : "unknown error";
  }
};

namespace {

/// Embree's view of the tree while it builds: nodes in its thread-local arenas, flattened afterwards.
struct BuildNode {
  const BuildNode* child[2] = {nullptr, nullptr};
  uint32_t vertex = 0;
  bool leaf = false;
};

struct BuildContext {
  std::atomic<bool> malformed{false};  // a leaf with != 1 vertex or a node with != 2 children
};

void* create_node(RTCThreadLocalAllocator alloc, unsigned int child_count, void* user) {
  if (child_count != 2) static_cast<BuildContext*>(user)->malformed = true;
  return new (rtcThreadLocalAlloc(alloc, sizeof(BuildNode), alignof(BuildNode))) BuildNode{};
}

void set_node_children(void* node, void** children, unsigned int child_count, void* user) {
  if (child_count != 2) {
    static_cast<BuildContext*>(user)->malformed = true;
    return;
  }
  auto* n = static_cast<BuildNode*>(node);
  n->child[0] = static_cast<const BuildNode*>(children[0]);
  n->child[1] = static_cast<const BuildNode*>(children[1]);
}

// Boxes are recomputed from the leaves after flattening (exact float min/max), so Embree's are unused.
void set_node_bounds(void*, const RTCBounds**, unsigned int, void*) {}

void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void* user) {
  if (count != 1) static_cast<BuildContext*>(user)->malformed = true;
  auto* leaf = new (rtcThreadLocalAlloc(alloc, sizeof(BuildNode), alignof(BuildNode))) BuildNode{};
  leaf->leaf = true;
  leaf->vertex = count > 0 ? prims[0].primID : 0;
  return leaf;
}

}  // namespace

LightVertexBvh::LightVertexBvh() : embree_(std::make_unique<Embree>()) {}
LightVertexBvh::~LightVertexBvh() = default;

void LightVertexBvh::build(std::span<const Vec3> points) {
  const auto start = std::chrono::steady_clock::now();
  nodes_.clear();
  vertex_count_ = 0;
  depth_ = 0;
  if (points.size() > (size_t(1) << 31) - 1) throw std::invalid_argument("hrr: too many light vertices");
  for (const Vec3& p : points)
    if (!is_finite(p)) throw std::invalid_argument("hrr: non-finite light vertex");

  if (points.size() == 1) {
    nodes_.push_back({points[0], 1u, points[0], 0u});
    depth_ = 1;
  } else if (points.size() > 1) {
    std::vector<RTCBuildPrimitive> prims(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
      const Vec3& p = points[i];
      prims[i] = {p.x, p.y, p.z, 0u, p.x, p.y, p.z, static_cast<unsigned>(i)};
    }
    BuildContext context;
    RTCBVH bvh = rtcNewBVH(embree_->device);
    RTCBuildArguments args = rtcDefaultBuildArguments();
    args.buildQuality = RTC_BUILD_QUALITY_MEDIUM;  // binned SAH, no spatial splits (points)
    args.maxBranchingFactor = 2;
    args.maxDepth = kMaxDepth;
    args.minLeafSize = 1;
    args.maxLeafSize = 1;
    args.bvh = bvh;
    args.primitives = prims.data();
    args.primitiveCount = prims.size();
    args.primitiveArrayCapacity = prims.size();
    args.createNode = create_node;
    args.setNodeChildren = set_node_children;
    args.setNodeBounds = set_node_bounds;
    args.createLeaf = create_leaf;
    args.userPtr = &context;
    embree_->message.clear();
    const void* root = rtcBuildBVH(&args);
    const RTCError error = rtcGetDeviceError(embree_->device);
    if (!root || error != RTC_ERROR_NONE || context.malformed) {
      rtcReleaseBVH(bvh);
      throw std::runtime_error("hrr: Embree BVH build failed: " +
                               (embree_->message.empty() ? std::string("malformed tree") : embree_->message));
    }
    try {
      flatten_from(root, points);
    } catch (...) {
      rtcReleaseBVH(bvh);
      nodes_.clear();
      depth_ = 0;
      throw;
    }
    rtcReleaseBVH(bvh);  // frees Embree's build nodes: only the flat array stays
    finish_nodes();
  }
  vertex_count_ = points.size();
  build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void LightVertexBvh::flatten_from(const void* embree_root, std::span<const Vec3> points) {
  // Pre-order with the first child next: the first child of node i is i + 1, the second child's
  // index is patched into its parent when it is reached.
  struct Pending {
    const BuildNode* node;
    uint32_t parent;  // node whose `index` must point here; UINT32_MAX if none
    uint32_t depth;
  };
  nodes_.reserve(2 * points.size() - 1);
  std::vector<Pending> stack;
  stack.push_back({static_cast<const BuildNode*>(embree_root), UINT32_MAX, 1u});
  while (!stack.empty()) {
    const Pending item = stack.back();
    stack.pop_back();
    const auto here = static_cast<uint32_t>(nodes_.size());
    if (item.parent != UINT32_MAX) nodes_[item.parent].index = here;
    depth_ = std::max(depth_, item.depth);
    if (item.depth > kMaxDepth) throw std::runtime_error("hrr: BVH deeper than the traversal stack");
    if (item.node->leaf) {
      const Vec3& p = points[item.node->vertex];
      nodes_.push_back({p, 1u, p, item.node->vertex});
      continue;
    }
    nodes_.push_back({Vec3(0.f), 0u, Vec3(0.f), 0u});  // box, count and second child filled later
    stack.push_back({item.node->child[1], here, item.depth + 1});
    stack.push_back({item.node->child[0], UINT32_MAX, item.depth + 1});
  }
  if (nodes_.size() != 2 * points.size() - 1) throw std::runtime_error("hrr: Embree BVH lost vertices");
}

void LightVertexBvh::finish_nodes() {
  // Children always follow their parent in pre-order, so one backward sweep sees them finished.
  for (size_t i = nodes_.size(); i-- > 0;) {
    Node& node = nodes_[i];
    if (node.is_leaf()) continue;
    const Node& a = nodes_[i + 1];
    const Node& b = nodes_[node.second_child()];
    node.lo = glm::min(a.lo, b.lo);
    node.hi = glm::max(a.hi, b.hi);
    node.count = a.count + b.count;
  }
}

}  // namespace penumbra::bdpt
