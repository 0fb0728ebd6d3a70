// TriangleMesh::fill_surface(): what a hit on a triangle needs, written straight into the record.
// Inlined by the scene's hit path (EmbreeScene::intersect()) and by TriangleMesh::surface().
#pragma once

#include "scene/triangle_mesh.h"

#include <penumbra/interaction.h>

#include <cmath>

namespace penumbra {

// The hit's point, error bound, normals and uv. The face normal is Embree's for the hit (object
// space, so the prototype's for an instance): the same cross product of two edges by the same
// winding, so the same sign, rounded differently in its last bits, and no read of face_normals[i],
// a cache miss on a large mesh.
inline void TriangleMesh::fill_surface(size_t i, const Vec3& b_in, const Vec3& embree_ng, SurfaceInteraction& si) const {
  const Vec3 b = b_in;  // a local: stores into `si` could otherwise alias it and force reloads
  const Vec3 fn = glm::normalize(embree_ng);
  const uint32_t* v = &indices[3 * i];
  const Vec3 &p0 = P[v[0]], &p1 = P[v[1]], &p2 = P[v[2]];
  si.p = b.x * p0 + b.y * p1 + b.z * p2;
  si.p_error = error_gamma(7) * (abs_each(b.x * p0) + abs_each(b.y * p1) + abs_each(b.z * p2));
  Vec3 ns(0.f);
  if (!N.empty()) {
    Vec3 n = b.x * N[v[0]] + b.y * N[v[1]] + b.z * N[v[2]];
    float len2 = glm::dot(n, n);
    if (len2 > 0.f) ns = n / std::sqrt(len2);
  }
  // oriented() written out: an x86-64-v3 clone of the caller called it out of line.
  if (ns == Vec3(0.f)) {
    si.ng = si.ns = flip_normal ? -fn : fn;
  } else {
    si.ng = glm::dot(fn, ns) < 0.f ? -fn : fn;
    si.ns = ns;
  }
  si.uv = uv.empty() ? Vec2(b.y + b.z, b.z) : b.x * uv[v[0]] + b.y * uv[v[1]] + b.z * uv[v[2]];
}

}  // namespace penumbra
