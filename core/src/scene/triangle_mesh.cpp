#include "scene/triangle_mesh.h"

#include <penumbra/sampling.h>

namespace penumbra {

Vec3 TriangleMesh::position(size_t i, const Vec3& b) const {
  const uint32_t* v = &indices[3 * i];
  return b.x * P[v[0]] + b.y * P[v[1]] + b.z * P[v[2]];
}

Vec3 TriangleMesh::shading_normal(size_t i, const Vec3& b) const {
  if (N.empty()) return Vec3(0.f);
  const uint32_t* v = &indices[3 * i];
  Vec3 n = b.x * N[v[0]] + b.y * N[v[1]] + b.z * N[v[2]];
  float len2 = glm::dot(n, n);
  return len2 > 0.f ? n / std::sqrt(len2) : Vec3(0.f);
}

Vec3 TriangleMesh::geometric_normal(size_t i, const Vec3& b) const {
  const uint32_t* v = &indices[3 * i];
  Vec3 n = glm::normalize(glm::cross(P[v[0]] - P[v[2]], P[v[1]] - P[v[2]]));
  Vec3 ns = shading_normal(i, b);
  if (ns != Vec3(0.f)) return glm::dot(n, ns) < 0.f ? -n : n;
  return flip_normal ? -n : n;
}

Vec2 TriangleMesh::uv_at(size_t i, const Vec3& b) const {
  if (uv.empty()) return Vec2(b.y + b.z, b.z);  // pbrt's default (0,0), (1,0), (1,1)
  const uint32_t* v = &indices[3 * i];
  return b.x * uv[v[0]] + b.y * uv[v[1]] + b.z * uv[v[2]];
}

float TriangleMesh::area(size_t i) const {
  const uint32_t* v = &indices[3 * i];
  return 0.5f * glm::length(glm::cross(P[v[1]] - P[v[0]], P[v[2]] - P[v[0]]));
}

ShapeSample Triangle::sample_area(Vec2 u) const {
  Vec2 b12 = sample_uniform_triangle(u);
  Vec3 b(1.f - b12.x - b12.y, b12.x, b12.y);
  return ShapeSample{mesh_->position(index_, b), mesh_->geometric_normal(index_, b),
                     mesh_->uv_at(index_, b), 1.f / area()};
}

// Area sampling converted to solid angle. Spherical-triangle sampling arrives with the lights issue.
std::optional<ShapeSample> Triangle::sample_solid_angle(const ShapeSampleContext& ctx, Vec2 u) const {
  ShapeSample s = sample_area(u);
  s.pdf = area_to_solid_angle_pdf(s.pdf, ctx.p, s.p, s.n);
  if (!(s.pdf > 0.f) || std::isinf(s.pdf)) return std::nullopt;
  return s;
}

float Triangle::pdf_solid_angle(const ShapeSampleContext& ctx, const Vec3& wi, const Vec3& p_hit,
                                const Vec3& n_hit) const {
  float pdf = area_to_solid_angle_pdf(1.f / area(), ctx.p, p_hit, n_hit);
  return std::isinf(pdf) ? 0.f : pdf;
}

}  // namespace penumbra
