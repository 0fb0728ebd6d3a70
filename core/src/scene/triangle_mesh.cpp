#include "scene/triangle_mesh.h"

#include "scene/shape_sample_direction.h"
#include "scene/triangle_surface.h"

#include "util/cpu_clones.h"
#include "util/triangle_warp.h"

#include <penumbra/interaction.h>
#include <penumbra/sampling.h>

namespace penumbra {

// pbrt's parameterisation of a triangle without uv: (0,0), (1,0), (1,1) at its vertices 0, 1, 2.
static Vec2 default_uv(int vertex) { return Vec2(vertex == 0 ? 0.f : 1.f, vertex == 2 ? 1.f : 0.f); }

Vec3 TriangleMesh::position(size_t i, const Vec3& b) const {
  const uint32_t* v = &indices[3 * i];
  return b.x * P[v[0]] + b.y * P[v[1]] + b.z * P[v[2]];
}

Vec3 TriangleMesh::position_error(size_t i, const Vec3& b) const {
  const uint32_t* v = &indices[3 * i];
  return error_gamma(7) * (abs_each(b.x * P[v[0]]) + abs_each(b.y * P[v[1]]) + abs_each(b.z * P[v[2]]));
}

Vec3 TriangleMesh::shading_normal(size_t i, const Vec3& b) const {
  if (N.empty()) return Vec3(0.f);
  const uint32_t* v = &indices[3 * i];
  Vec3 n = b.x * N[v[0]] + b.y * N[v[1]] + b.z * N[v[2]];
  float len2 = glm::dot(n, n);
  return len2 > 0.f ? n / std::sqrt(len2) : Vec3(0.f);
}

void TriangleMesh::finish() {
  face_normals.resize(triangle_count());
  for (size_t i = 0; i < face_normals.size(); ++i) {
    const uint32_t* v = &indices[3 * i];
    face_normals[i] = glm::normalize(glm::cross(P[v[0]] - P[v[2]], P[v[1]] - P[v[2]]));
  }
}

Vec3 TriangleMesh::face_normal(size_t i) const {
  if (i < face_normals.size()) return face_normals[i];
  const uint32_t* v = &indices[3 * i];
  return glm::normalize(glm::cross(P[v[0]] - P[v[2]], P[v[1]] - P[v[2]]));
}

// pbrt's orientation: towards the shading normal when the mesh has one, else by the winding.
Vec3 TriangleMesh::oriented(const Vec3& n, const Vec3& ns) const {
  if (ns != Vec3(0.f)) return glm::dot(n, ns) < 0.f ? -n : n;
  return flip_normal ? -n : n;
}

Vec3 TriangleMesh::geometric_normal(size_t i, const Vec3& b) const {
  return oriented(face_normal(i), shading_normal(i, b));
}

// Out of line (and cloned for x86-64-v3) for callers other than EmbreeScene's hit path, which
// inlines fill_surface() itself.
PENUMBRA_X86_64_V3_CLONES void TriangleMesh::surface(size_t i, const Vec3& b, const Vec3& embree_ng,
                                                     SurfaceInteraction& si) const {
  fill_surface(i, b, embree_ng, si);
}

void TriangleMesh::uv_derivatives(size_t i, Vec3* dpdu, Vec3* dpdv) const {
  const uint32_t* v = &indices[3 * i];
  Vec2 uv0 = default_uv(0), uv1 = default_uv(1), uv2 = default_uv(2);
  if (!uv.empty()) uv0 = uv[v[0]], uv1 = uv[v[1]], uv2 = uv[v[2]];
  // p - p2 = (u - u2) dpdu + (v - v2) dpdv for the two edges to vertex 2, solved for dpdu, dpdv.
  Vec2 duv02 = uv0 - uv2, duv12 = uv1 - uv2;
  Vec3 dp02 = P[v[0]] - P[v[2]], dp12 = P[v[1]] - P[v[2]];
  float det = duv02.x * duv12.y - duv02.y * duv12.x;
  if (std::abs(det) > 1e-12f) {
    float inv = 1.f / det;
    *dpdu = (duv12.y * dp02 - duv02.y * dp12) * inv;
    *dpdv = (duv02.x * dp12 - duv12.x * dp02) * inv;
    if (is_finite(*dpdu) && is_finite(*dpdv) && glm::dot(glm::cross(*dpdu, *dpdv), glm::cross(*dpdu, *dpdv)) > 0.f)
      return;
  }
  Frame f(face_normal(i));
  *dpdu = f.s, *dpdv = f.t;
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
  ShapeSample s;
  area_sample_into(u, s);
  return s;
}

// Samples are written field by field into the object the caller returns: built whole and copied
// out of an std::optional, they stalled store forwarding (docs/benchmarks.md, "Results built in place").
// This and area_sample_into() are inlined into sample_area_seen_from(), which nearly every light
// sample on a triangle goes through: out of line they were three calls deep, each result a round
// trip through memory.
[[gnu::always_inline]] inline void Triangle::fill_at(const Vec3& b, ShapeSample& s) const {
  s.p = b.x * p_[0] + b.y * p_[1] + b.z * p_[2];
  s.n = n_flat_ != Vec3(0.f) ? n_flat_ : mesh_->geometric_normal(index_, b);
  s.uv = b.x * uv_[0] + b.y * uv_[1] + b.z * uv_[2];
}

[[gnu::always_inline]] inline void Triangle::area_sample_into(Vec2 u, ShapeSample& s) const {
  Vec2 b12 = uniform_triangle_barycentrics(u);
  fill_at(Vec3(1.f - b12.x - b12.y, b12.x, b12.y), s);
  s.pdf = inv_area_;
}

namespace {

// Spherical sampling is used between these solid angles: below, the triangle's spherical angles lose
// their precision in float; above, it nearly covers a hemisphere and area sampling does as well.
constexpr float kMinSphericalSolidAngle = 3e-4f, kMaxSphericalSolidAngle = 6.22f;

// Solid angle of the triangle (a, b, c: unit directions) by Van Oosterom and Strackee's formula.
float solid_angle(const Vec3& a, const Vec3& b, const Vec3& c) {
  return std::abs(2.f * std::atan2(glm::dot(a, glm::cross(b, c)), 1.f + glm::dot(a, b) + glm::dot(a, c) + glm::dot(b, c)));
}

float angle_between(const Vec3& x, const Vec3& y) {
  return std::acos(std::clamp(glm::dot(x, y), -1.f, 1.f));
}

// The component of v orthogonal to unit w, normalised.
Vec3 orthonormal_part(const Vec3& v, const Vec3& w) { return glm::normalize(v - glm::dot(v, w) * w); }

// Arvo (1995): a direction uniformly distributed over the spherical triangle abc of area `omega`.
std::optional<Vec3> sample_spherical_triangle(const Vec3& a, const Vec3& b, const Vec3& c, float omega, Vec2 u) {
  Vec3 n_ab = glm::cross(a, b), n_ac = glm::cross(a, c), n_bc = glm::cross(b, c);
  if (glm::dot(n_ab, n_ab) == 0.f || glm::dot(n_ac, n_ac) == 0.f || glm::dot(n_bc, n_bc) == 0.f) return std::nullopt;
  float alpha = angle_between(glm::normalize(n_ab), glm::normalize(n_ac));  // interior angle at a
  float cos_c = glm::dot(a, b);                                             // arc length a-b
  // Choose the sub-triangle a b c' of area u.x * omega: c' lies on the arc from a to c.
  float area = u.x * omega;
  float s = std::sin(area - alpha), t = std::cos(area - alpha);
  float cos_alpha = std::cos(alpha), sin_alpha = std::sin(alpha);
  float uu = t - cos_alpha, vv = s + sin_alpha * cos_c;
  float denom = (vv * s + uu * t) * sin_alpha;
  if (denom == 0.f) return std::nullopt;
  float q = std::clamp(((vv * t - uu * s) * cos_alpha - vv) / denom, -1.f, 1.f);
  Vec3 c_prime = q * a + safe_sqrt(1.f - q * q) * orthonormal_part(c, a);
  // Then a point on the arc from b to c', uniform in solid angle.
  float z = 1.f - u.y * (1.f - glm::dot(c_prime, b));
  Vec3 w = z * b + safe_sqrt(1.f - z * z) * orthonormal_part(c_prime, b);
  if (!is_finite(w)) return std::nullopt;
  return glm::normalize(w);
}

}  // namespace

Triangle::Triangle(const TriangleMesh* mesh, uint32_t index) : mesh_(mesh), index_(index) {
  const uint32_t* v = &mesh->indices[3 * index];
  for (int k = 0; k < 3; ++k) {
    p_[k] = mesh->P[v[k]];
    uv_[k] = mesh->uv.empty() ? default_uv(k) : mesh->uv[v[k]];
  }
  n_front_ = mesh->geometric_normal(index, Vec3(1.f / 3.f));
  if (mesh->N.empty()) n_flat_ = n_front_;  // the same for every b
  centroid_ = (p_[0] + p_[1] + p_[2]) / 3.f;
  area_ = mesh->area(index);
  inv_area_ = 1.f / area_;
}

// Spherical sampling pays for its trigonometry only where the triangle is near and large: area over
// squared centroid distance (about its solid angle) of at least this. On the Cornell box, sampling
// every triangle sphericaly cost 11.5 % more instructions per ray for the same variance.
constexpr float kSphericalAboveApproxSolidAngle = 0.25f;

// And only where the point is in front of the triangle (the side its oriented normal faces): a
// one-sided emitter, the usual area light, sends nothing behind it, so spherical samples there would
// all carry zero. On the Cornell box every spherical sample was such a one (ceiling points within
// 0.6 of the light, which faces down): 1.7-1.9 % of the path tracer's time (docs/benchmarks.md,
// "What bounds the path tracer"). A two-sided emitter is sampled by area from behind.
bool Triangle::spherical_worthwhile(const Vec3& p) const {
  Vec3 d = centroid_ - p;
  return area_ >= kSphericalAboveApproxSolidAngle * glm::dot(d, d) && glm::dot(d, n_front_) < 0.f;
}

// Uniform in the solid angle the triangle subtends (Arvo's spherical triangle sampling) where the
// triangle is near and large and that is numerically safe, otherwise uniform in area;
// pdf_solid_angle() makes the same choice.
std::optional<ShapeSample> Triangle::sample_solid_angle(const ShapeSampleContext& ctx, Vec2 u) const {
  if (unseen_front(ctx)) return std::nullopt;
  if (spherical_worthwhile(ctx.p)) return sample_spherical(ctx, u);
  return sample_by_area(ctx, u);
}

// A flat triangle (no shading normals: one oriented normal everywhere) with the caller asking for its
// front only, seen from behind or edge-on: every sample would carry nothing. 17 % of the Cornell box's
// light samples are such ones, from the ceiling behind the light (docs/benchmarks.md, "What bounds the
// path tracer").
bool Triangle::unseen_front(const ShapeSampleContext& ctx) const {
  return ctx.front_only && n_flat_ != Vec3(0.f) && glm::dot(centroid_ - ctx.p, n_flat_) >= 0.f;
}

// Out of line: inlined, its loads of the vertices and its stack frame were paid by the area samples
// too (about 60 instructions each).
[[gnu::noinline]] std::optional<ShapeSample> Triangle::sample_spherical(const ShapeSampleContext& ctx, Vec2 u) const {
  const Vec3 &p0 = p_[0], &p1 = p_[1], &p2 = p_[2];
  Vec3 a = glm::normalize(p0 - ctx.p), b = glm::normalize(p1 - ctx.p), c = glm::normalize(p2 - ctx.p);
  float omega = solid_angle(a, b, c);
  if (omega >= kMinSphericalSolidAngle && omega <= kMaxSphericalSolidAngle) {
    std::optional<Vec3> w = sample_spherical_triangle(a, b, c, omega, u);
    if (!w) return std::nullopt;
    // Where the direction meets the triangle: barycentrics by Cramer's rule (Moeller-Trumbore).
    Vec3 e1 = p1 - p0, e2 = p2 - p0, s1 = glm::cross(*w, e2);
    float divisor = glm::dot(s1, e1);
    if (divisor == 0.f) return std::nullopt;
    Vec3 d = ctx.p - p0;
    float b1 = std::clamp(glm::dot(d, s1) / divisor, 0.f, 1.f);
    float b2 = std::clamp(glm::dot(*w, glm::cross(d, e1)) / divisor, 0.f, 1.f);
    if (b1 + b2 > 1.f) {
      float sum = b1 + b2;
      b1 /= sum, b2 /= sum;
    }
    std::optional<ShapeSample> out(std::in_place);
    fill_at(Vec3(1.f - b1 - b2, b1, b2), *out);
    out->pdf = 1.f / omega;
    set_direction_from(*out, ctx.p);
    return out;
  }
  return sample_by_area(ctx, u);
}

[[gnu::always_inline]] inline std::optional<ShapeSample> Triangle::sample_by_area(const ShapeSampleContext& ctx,
                                                                              Vec2 u) const {
  std::optional<ShapeSample> out(std::in_place);
  if (!sample_area_seen_from(ctx.p, u, *out)) out.reset();
  return out;
}

// area_sample_into() and the free area_sample_seen_from() in one function, compiled for x86-64-v3
// too: nearly every light sample on a triangle takes this branch, and the baseline's scalar SSE code
// for it (with sample_solid_angle()'s share) was about 230 instructions.
PENUMBRA_X86_64_V3_CLONES bool Triangle::sample_area_seen_from(const Vec3& ref, Vec2 u, ShapeSample& s) const {
  area_sample_into(u, s);
  area_sample_seen_from(s, ref);
  return s.pdf > 0.f && !std::isinf(s.pdf);
}

float Triangle::pdf_solid_angle(const ShapeSampleContext& ctx, const Vec3& wi, const Vec3& p_hit,
                                const Vec3& n_hit) const {
  if (unseen_front(ctx)) return 0.f;
  if (!spherical_worthwhile(ctx.p)) {
    float pdf = area_to_solid_angle_pdf(inv_area_, ctx.p, p_hit, n_hit);
    return std::isinf(pdf) ? 0.f : pdf;
  }
  Vec3 a = glm::normalize(p_[0] - ctx.p), b = glm::normalize(p_[1] - ctx.p), c = glm::normalize(p_[2] - ctx.p);
  float omega = solid_angle(a, b, c);
  if (omega >= kMinSphericalSolidAngle && omega <= kMaxSphericalSolidAngle) return 1.f / omega;
  float pdf = area_to_solid_angle_pdf(inv_area_, ctx.p, p_hit, n_hit);
  return std::isinf(pdf) ? 0.f : pdf;
}

}  // namespace penumbra
