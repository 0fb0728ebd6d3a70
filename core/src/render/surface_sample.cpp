#include "render/surface_sample.h"

#include <penumbra/bsdf.h>
#include <penumbra/rng.h>

namespace penumbra {

SurfaceSample trace_surface_sample(const Scene& scene, const Ray& ray, Point2i pixel, uint32_t index) {
  return describe_surface_sample(scene.intersect(ray), pixel, index);
}

SurfaceSample describe_surface_sample(const std::optional<SurfaceInteraction>& si, Point2i pixel, uint32_t index) {
  SurfaceSample out;
  if (!si) return out;
  out.hit = true;
  out.normal = si->ns;
  out.depth = si->t;
  if (!si->bsdf || si->bsdf->flags() == 0) return out;
  Pcg32 rng(hash_ints(uint32_t(pixel.x), uint32_t(pixel.y), index), 0xa1bed0ull);
  Vec3 wo = si->shading.to_local(si->wo);
  ShadingContext ctx{si->texture_context(), TransportMode::Radiance};
  float uc = rng.next_float();
  Vec2 u(rng.next_float(), rng.next_float());
  std::optional<BsdfSample> bs = si->bsdf->sample_f(wo, uc, u, ctx);
  if (bs && bs->pdf > 0.f) out.albedo = bs->f * (std::abs(bs->wi.z) / bs->pdf);
  return out;
}

}  // namespace penumbra
