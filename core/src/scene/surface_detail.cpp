#include "scene/surface_detail.h"

#include <cmath>

namespace penumbra {

void bump_map(const TexturedFloat& displacement, const TextureEvalContext& ctx, const ShadingGeometry& g,
              Vec3* dpdu, Vec3* dpdv) {
  TextureEvalContext shifted = ctx;
  float du = 0.5f * (std::abs(ctx.dudx) + std::abs(ctx.dudy));
  if (du == 0.f) du = 0.0005f;
  shifted.p = ctx.p + du * g.dpdu;
  shifted.uv = ctx.uv + Vec2(du, 0.f);
  float u_displace = displacement.evaluate(shifted);
  float dv = 0.5f * (std::abs(ctx.dvdx) + std::abs(ctx.dvdy));
  if (dv == 0.f) dv = 0.0005f;
  shifted.p = ctx.p + dv * g.dpdv;
  shifted.uv = ctx.uv + Vec2(0.f, dv);
  float v_displace = displacement.evaluate(shifted);
  float displace = displacement.evaluate(ctx);
  *dpdu = g.dpdu + (u_displace - displace) / du * g.n + displace * g.dndu;
  *dpdv = g.dpdv + (v_displace - displace) / dv * g.n + displace * g.dndv;
}

void normal_map(const NormalMapImage& map, Vec2 uv, const ShadingGeometry& g, Vec3* dpdu, Vec3* dpdv) {
  Vec3 c = map.bilerp(Vec2(uv.x, 1.f - uv.y));
  Vec3 local = 2.f * c - Vec3(1.f);
  float len = glm::length(local);
  local = len > 0.f ? local / len : Vec3(0.f, 0.f, 1.f);
  float ulen = glm::length(g.dpdu), vlen = glm::length(g.dpdv);
  Vec3 x = ulen > 0.f ? g.dpdu / ulen : Vec3(0.f);
  Vec3 y = glm::cross(g.n, x);
  Vec3 ns = glm::normalize(local.x * x + local.y * y + local.z * g.n);
  Vec3 gs = g.dpdu - glm::dot(g.dpdu, ns) * ns;  // Gram-Schmidt
  float gl = glm::length(gs);
  *dpdu = gl > 0.f ? gs * (ulen / gl) : gs;
  Vec3 v = glm::cross(ns, *dpdu);
  float vl = glm::length(v);
  *dpdv = vl > 0.f ? v * (vlen / vl) : v;
}

Frame tangent_frame(const Vec3& n, const Vec3& dpdu) {
  Vec3 s = dpdu - glm::dot(dpdu, n) * n;
  float len2 = glm::dot(s, s);
  if (!(len2 > 1e-12f * glm::dot(dpdu, dpdu)) || !std::isfinite(len2)) return Frame(n);
  Frame f;
  f.n = n;
  f.s = s / std::sqrt(len2);
  f.t = glm::cross(n, f.s);
  return f;
}

void apply_surface_detail(const SurfaceDetail& detail, const ShadingGeometry& g, SurfaceInteraction& si) {
  Vec3 dpdu, dpdv;
  if (detail.normal_map) normal_map(*detail.normal_map, si.uv, g, &dpdu, &dpdv);
  else bump_map(detail.displacement, si.texture_context(), g, &dpdu, &dpdv);
  Vec3 c = glm::cross(dpdu, dpdv);
  float len = glm::length(c);
  if (!(len > 0.f) || !std::isfinite(len)) return;  // degenerate: keep the hit's own shading
  Vec3 ns = c / len;
  if (glm::dot(ns, si.ng) < 0.f) ns = -ns;
  si.ns = ns;
  si.shading = tangent_frame(ns, dpdu);
}

}  // namespace penumbra
