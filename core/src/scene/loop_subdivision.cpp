#include "scene/loop_subdivision.h"

#include <fmt/core.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <unordered_map>

namespace penumbra {

namespace {

// The edges and one-rings of a triangle mesh, as the rules need them.
struct Topology {
  struct Edge {
    int a, b;          // a < b
    int faces = 0;     // 1: boundary, 2: interior, more: non-manifold
    int opposite[2] = {-1, -1};
  };
  std::vector<Edge> edges;
  std::vector<int> face_edges;  // per face, the edges (v0 v1), (v1 v2), (v2 v0)
  std::vector<std::vector<int>> neighbours;       // every vertex joined to it by an edge
  std::vector<std::vector<int>> boundary_neighbours;
  std::vector<bool> irregular;  // on a non-manifold edge: kept in place

  Topology(size_t vertex_count, const std::vector<int>& idx) {
    std::unordered_map<uint64_t, int> edge_of;
    edge_of.reserve(idx.size());
    face_edges.resize(idx.size());
    for (size_t f = 0; f < idx.size() / 3; ++f)
      for (int k = 0; k < 3; ++k) {
        int u = idx[3 * f + k], v = idx[3 * f + (k + 1) % 3], w = idx[3 * f + (k + 2) % 3];
        int a = std::min(u, v), b = std::max(u, v);
        uint64_t key = (uint64_t(uint32_t(a)) << 32) | uint32_t(b);
        auto [it, inserted] = edge_of.try_emplace(key, int(edges.size()));
        if (inserted) edges.push_back(Edge{a, b});
        Edge& e = edges[it->second];
        if (e.faces < 2) e.opposite[e.faces] = w;
        ++e.faces;
        face_edges[3 * f + k] = it->second;
      }
    neighbours.resize(vertex_count);
    boundary_neighbours.resize(vertex_count);
    irregular.assign(vertex_count, false);
    for (const Edge& e : edges) {
      neighbours[e.a].push_back(e.b);
      neighbours[e.b].push_back(e.a);
      if (e.faces == 1) {
        boundary_neighbours[e.a].push_back(e.b);
        boundary_neighbours[e.b].push_back(e.a);
      } else if (e.faces > 2) {
        irregular[e.a] = irregular[e.b] = true;
      }
    }
  }

  bool on_boundary(int v) const { return !boundary_neighbours[v].empty(); }
  // Boundary rules need exactly two boundary edges at the vertex; anything else stays in place.
  bool keep_in_place(int v) const {
    return irregular[v] || neighbours[v].empty() || (on_boundary(v) && boundary_neighbours[v].size() != 2);
  }
};

double loop_beta(size_t valence) { return valence == 3 ? 3.0 / 16.0 : 3.0 / (8.0 * double(valence)); }

Vec3 weigh_ring(const std::vector<Vec3>& P, int v, const std::vector<int>& ring, double w) {
  glm::dvec3 sum(0.0);
  for (int u : ring) sum += glm::dvec3(P[u]);
  return Vec3((1.0 - double(ring.size()) * w) * glm::dvec3(P[v]) + w * sum);
}

// One step of Loop's scheme: even (old) vertices first, then one odd vertex per edge.
void refine(std::vector<Vec3>& P, std::vector<int>& idx) {
  Topology t(P.size(), idx);
  std::vector<Vec3> next(P.size() + t.edges.size());
  for (size_t v = 0; v < P.size(); ++v) {
    int iv = int(v);
    if (t.keep_in_place(iv))
      next[v] = P[v];
    else if (t.on_boundary(iv))
      next[v] = weigh_ring(P, iv, t.boundary_neighbours[v], 1.0 / 8.0);
    else
      next[v] = weigh_ring(P, iv, t.neighbours[v], loop_beta(t.neighbours[v].size()));
  }
  for (size_t i = 0; i < t.edges.size(); ++i) {
    const Topology::Edge& e = t.edges[i];
    glm::dvec3 a(P[e.a]), b(P[e.b]);
    if (e.faces == 2)
      next[P.size() + i] = Vec3(0.375 * (a + b) + 0.125 * (glm::dvec3(P[e.opposite[0]]) + glm::dvec3(P[e.opposite[1]])));
    else
      next[P.size() + i] = Vec3(0.5 * (a + b));
  }
  std::vector<int> out;
  out.reserve(idx.size() * 4);
  int base = int(P.size());
  for (size_t f = 0; f < idx.size() / 3; ++f) {
    int v0 = idx[3 * f], v1 = idx[3 * f + 1], v2 = idx[3 * f + 2];
    int m01 = base + t.face_edges[3 * f], m12 = base + t.face_edges[3 * f + 1], m20 = base + t.face_edges[3 * f + 2];
    int faces[12] = {v0, m01, m20, v1, m12, m01, v2, m20, m12, m01, m12, m20};
    out.insert(out.end(), faces, faces + 12);
  }
  P = std::move(next);
  idx = std::move(out);
}

// The one-ring of v in winding order (from one boundary neighbour to the other on a boundary);
// empty when the faces around v do not form a single fan.
std::vector<int> ordered_ring(const std::vector<std::pair<int, int>>& fan, bool boundary) {
  std::unordered_map<int, int> next;
  std::unordered_map<int, int> incoming;
  for (auto [a, b] : fan) {
    if (!next.emplace(a, b).second) return {};
    ++incoming[b];
  }
  int start = fan.empty() ? -1 : fan[0].first;
  if (boundary) {
    start = -1;
    for (auto [a, b] : fan)
      if (!incoming.count(a)) start = a;
    if (start < 0) return {};
  }
  std::vector<int> ring{start};
  for (int v = start; next.count(v);) {
    v = next[v];
    if (v == start) break;
    ring.push_back(v);
    if (ring.size() > fan.size() + 1) return {};
  }
  return ring.size() == fan.size() + (boundary ? 1 : 0) ? ring : std::vector<int>{};
}

// Tangents of the limit surface from the ring (pbrt's book, after Loop and Hoppe et al.).
Vec3 limit_normal(const std::vector<Vec3>& P, int v, const std::vector<int>& ring, bool boundary) {
  size_t n = ring.size();
  glm::dvec3 s(0.0), t(0.0);
  auto p = [&](size_t i) { return glm::dvec3(P[ring[i]]); };
  if (!boundary) {
    for (size_t i = 0; i < n; ++i) {
      double phi = 2.0 * std::numbers::pi * double(i) / double(n);
      s += std::cos(phi) * p(i);
      t += std::sin(phi) * p(i);
    }
  } else {
    s = p(n - 1) - p(0);
    glm::dvec3 c(P[v]);
    if (n == 2) {
      t = p(0) + p(1) - 2.0 * c;
    } else if (n == 3) {
      t = p(1) - c;
    } else if (n == 4) {
      t = -p(0) + 2.0 * p(1) + 2.0 * p(2) - p(3);
    } else {
      double theta = std::numbers::pi / double(n - 1);
      t = std::sin(theta) * (p(0) + p(n - 1));
      for (size_t k = 1; k + 1 < n; ++k) t += (2.0 * std::cos(theta) - 2.0) * std::sin(double(k) * theta) * p(k);
      t = -t;
    }
  }
  return Vec3(glm::cross(s, t));
}

}  // namespace

LoopSurface loop_subdivide(const std::vector<Vec3>& P, const std::vector<int>& indices, int levels,
                           const FileLoc& indices_loc, const FileLoc& levels_loc) {
  if (P.empty()) throw Error(indices_loc, "loopsubdiv has no vertices (\"point3 P\")");
  if (indices.empty() || indices.size() % 3 != 0)
    throw Error(indices_loc, fmt::format("\"indices\" has {} values, not a positive multiple of 3", indices.size()));
  for (size_t i = 0; i < indices.size(); ++i)
    if (indices[i] < 0 || size_t(indices[i]) >= P.size())
      throw Error(indices_loc, fmt::format("index {} (value {}) is out of range: the mesh has {} vertices", i,
                                           indices[i], P.size()));
  if (levels < 0) throw Error(levels_loc, fmt::format("\"levels\" is {}; it must be >= 0", levels));
  double triangles = double(indices.size() / 3) * std::pow(4.0, double(levels));
  if (triangles > double(1 << 26))
    throw Error(levels_loc, fmt::format("{} levels would make {:.3g} triangles (at most 2^26)", levels, triangles));

  LoopSurface out{P, {}, indices};
  for (int l = 0; l < levels; ++l) refine(out.P, out.indices);

  // Limit positions: the rules' eigen-analysis gives these masks (pbrt's book: gamma for interior
  // vertices, 1/5 for boundary ones).
  Topology t(out.P.size(), out.indices);
  std::vector<Vec3> limit(out.P.size());
  for (size_t v = 0; v < out.P.size(); ++v) {
    int iv = int(v);
    if (t.keep_in_place(iv)) {
      limit[v] = out.P[v];
    } else if (t.on_boundary(iv)) {
      limit[v] = weigh_ring(out.P, iv, t.boundary_neighbours[v], 1.0 / 5.0);
    } else {
      size_t n = t.neighbours[v].size();
      limit[v] = weigh_ring(out.P, iv, t.neighbours[v], 1.0 / (double(n) + 3.0 / (8.0 * loop_beta(n))));
    }
  }
  out.P = std::move(limit);

  // Limit normals from the ordered rings, oriented like the faces around the vertex (whose
  // area-weighted normal is also the fallback where the ring is not a single fan).
  std::vector<std::vector<std::pair<int, int>>> fans(out.P.size());
  std::vector<glm::dvec3> face_sum(out.P.size(), glm::dvec3(0.0));
  for (size_t f = 0; f < out.indices.size() / 3; ++f) {
    const int* c = &out.indices[3 * f];
    glm::dvec3 n = glm::cross(glm::dvec3(out.P[c[1]] - out.P[c[0]]), glm::dvec3(out.P[c[2]] - out.P[c[0]]));
    for (int k = 0; k < 3; ++k) {
      fans[c[k]].emplace_back(c[(k + 1) % 3], c[(k + 2) % 3]);
      face_sum[c[k]] += n;
    }
  }
  out.N.resize(out.P.size());
  for (size_t v = 0; v < out.P.size(); ++v) {
    int iv = int(v);
    Vec3 n(0.f);
    if (!t.keep_in_place(iv)) {
      std::vector<int> ring = ordered_ring(fans[v], t.on_boundary(iv));
      if (!ring.empty()) n = limit_normal(out.P, iv, ring, t.on_boundary(iv));
    }
    glm::dvec3 fn = face_sum[v];
    double len = glm::length(glm::dvec3(n));
    if (!(len > 1e-30)) n = Vec3(fn), len = glm::length(fn);
    if (glm::dot(glm::dvec3(n), fn) < 0.0) n = -n;
    out.N[v] = len > 0.0 ? Vec3(glm::dvec3(n) / len) : Vec3(0.f, 0.f, 1.f);
  }
  return out;
}

}  // namespace penumbra
