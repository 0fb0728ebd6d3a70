#include "scene/alpha_cutout.h"

#include "scene/cutout_shape.h"
#include "scene/quadrics.h"
#include "scene/sphere.h"
#include "scene/triangle_mesh.h"

#include <penumbra/rng.h>

#include <bit>

namespace penumbra {

float alpha_hash(const Vec3& o, const Vec3& d, uint64_t salt) {
  auto bits = [](float a, float b) {
    return uint64_t(std::bit_cast<uint32_t>(a)) | (uint64_t(std::bit_cast<uint32_t>(b)) << 32);
  };
  uint64_t h = hash_ints(bits(o.x, o.y), bits(o.z, d.x), bits(d.y, d.z), salt);
  return float(h >> 40) * 0x1p-24f;
}

bool AlphaCutout::keeps(const TextureEvalContext& ctx, const Vec3& o, const Vec3& d, uint64_t salt) const {
  float a = alpha.evaluate(ctx);
  if (a >= 1.f) return true;
  if (!(a > 0.f)) return false;
  return alpha_hash(o, d, salt) <= a;
}

bool CutoutShape::present(const ShapeSample& s) const {
  TextureEvalContext ctx;
  ctx.p = s.p;
  ctx.n = s.n;
  ctx.uv = s.uv;
  // pbrt-v4 hashes the point alone; the normal takes the place of the ray direction here.
  return cutout_.keeps(ctx, s.p, s.n, 0);
}

uint64_t hit_salt(unsigned geom, unsigned prim, float t) {
  return hash_ints((uint64_t(geom) << 32) | prim, std::bit_cast<uint32_t>(t));
}

namespace {

// The hit's lookup context (no footprint: pbrt-v4 tests alpha before differentials exist).
TextureEvalContext hit_context(const GeometryUserData& g, float u, float v, unsigned prim) {
  TextureEvalContext ctx;
  Vec3 b(1.f - u - v, u, v);
  ctx.p = g.mesh->position(prim, b);
  ctx.n = g.mesh->geometric_normal(prim, b);
  ctx.uv = g.mesh->uv_at(prim, b);
  return ctx;
}

template <bool Occlusion>
void alpha_filter(const RTCFilterFunctionNArguments* args) {
  const auto* g = static_cast<const GeometryUserData*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    RTCRayN* ray = args->ray;
    RTCHitN* hit = args->hit;
    unsigned N = args->N;
    Vec3 o(RTCRayN_org_x(ray, N, i), RTCRayN_org_y(ray, N, i), RTCRayN_org_z(ray, N, i));
    Vec3 d(RTCRayN_dir_x(ray, N, i), RTCRayN_dir_y(ray, N, i), RTCRayN_dir_z(ray, N, i));
    float t = RTCRayN_tfar(ray, N, i);
    unsigned prim = RTCHitN_primID(hit, N, i), geom = RTCHitN_geomID(hit, N, i);
    TextureEvalContext ctx = hit_context(*g, RTCHitN_u(hit, N, i), RTCHitN_v(hit, N, i), prim);
    if (!g->cutout.keeps(ctx, o, d, hit_salt(geom, prim, t))) args->valid[i] = 0;
  }
}

}  // namespace

void set_alpha_filters(RTCGeometry geom, const GeometryUserData* data) {
  rtcSetGeometryUserData(geom, const_cast<GeometryUserData*>(data));
  rtcSetGeometryIntersectFilterFunction(geom, alpha_filter<false>);
  rtcSetGeometryOccludedFilterFunction(geom, alpha_filter<true>);
}

bool user_hit_kept(const GeometryUserData& data, const Ray& ray, float t, uint64_t salt) {
  if (!data.cutout.active()) return true;
  TextureEvalContext ctx;
  if (data.quadric) {
    Quadric::Surface s = data.quadric->surface_at(ray, t);
    ctx.p = s.p;
    ctx.n = s.n;
    ctx.uv = s.uv;
  } else {
    ctx.p = data.sphere->reproject(ray.o + t * ray.d);
    ctx.n = data.sphere->normal_at(ctx.p);
    ctx.uv = data.sphere->uv_at(ctx.p);
  }
  return data.cutout.keeps(ctx, ray.o, ray.d, salt);
}

}  // namespace penumbra
