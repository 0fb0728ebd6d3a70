// Camera paths for SPPM. Light that the camera side can estimate well is summed into Ld here: emitters
// seen directly or through specular chains, and direct light at every non-specular vertex. Direct
// light combines a light sample and a BSDF sample by MIS, as the path integrator does, but the BSDF
// sample is traced here on its own, because the path stops at the visible point and never continues
// in that direction. Light reaching a vertex after it was emitted and scattered is the photons' part.
#include "camera_pass.h"

#include <penumbra/sampling.h>

namespace penumbra::sppm {

namespace {

// Shading and geometric normals must agree on whether wi is on wo's side (the path integrator's leak test).
bool consistent_sides(const SurfaceInteraction& si, const Vec3& wo_local, const Vec3& wi_local, const Vec3& wi) {
  bool reflect_shading = wi_local.z * wo_local.z > 0.f;
  bool reflect_geometric = glm::dot(wi, si.ng) * glm::dot(si.wo, si.ng) > 0.f;
  return reflect_shading == reflect_geometric;
}

struct DirectSamples {
  float u_light;
  Vec2 u_light_point;
  float u_lobe;
  Vec2 u_dir;
};

// The infinite lights a BSDF-sampled ray that escapes the scene sees, weighted against light sampling.
Rgb escaped_light(const Scene& scene, const Ray& ray, const LightSampleContext& lctx, const Vec3& wi,
                  const Rgb& weight, float bsdf_pdf, const SampledWavelengths* wavelengths) {
  Rgb L(0.f);
  SurfaceInteraction none;
  for (const Light* light : scene.infinite_lights()) {
    Rgb Le = light->Le(ray);
    if (is_black(Le)) continue;
    float light_pdf = scene.light_pmf(light) * light->pdf_li(lctx, wi, none);
    L += weight * emission_at(wavelengths, Le) * power_heuristic(1, bsdf_pdf, 1, light_pdf);
  }
  return L;
}

// Light sampling weighted against BSDF sampling, and BSDF sampling weighted against light sampling
// (power heuristic); the BSDF ray counts any emitter it finds, whose light-sampling density is
// pmf(light) * pdf_li, exactly as in the path integrator.
Rgb direct_light(const SurfaceInteraction& si, const Vec3& wo, const Bsdf& bsdf, const ShadingContext& sctx,
                 const Scene& scene, const DirectSamples& u, RaysFind rays_find, int arrived_in,
                 const SampledWavelengths* wavelengths) {
  Rgb L(0.f);
  LightSampleContext lctx = mis_light_context(si);
  if (std::optional<SampledLight> sl = scene.sample_light(u.u_light)) {
    std::optional<LightLiSample> ls = sl->light->sample_li(lctx, u.u_light_point);
    if (ls && ls->pdf > 0.f && !is_black(ls->L)) {
      Vec3 wi = si.shading.to_local(ls->wi);
      Rgb f = bsdf.f(wo, wi, sctx) * std::abs(wi.z);
      if (!is_black(f) && consistent_sides(si, wo, wi, ls->wi) &&
          !scene.occluded(si.spawn_ray_to(ls->p_light, ls->n_light))) {
        if (scene.has_media())
          f *= scene.segment_transmittance(si.media.leaving(si.ng, ls->wi, arrived_in), kMediumUnknown,
                                           glm::length(ls->p_light - si.p), wavelengths);
        float light_pdf = sl->pmf * ls->pdf;
        float w = is_delta_light(sl->light->type()) ? 1.f : power_heuristic(1, light_pdf, 1, bsdf.pdf(wo, wi, sctx));
        L += f * emission_at(wavelengths, ls->L) * w / light_pdf;
      }
    }
  }

  // With only point, spot and distant lights a BSDF-sampled ray finds no emitter: it would add
  // nothing, so it is not traced (its random numbers are drawn all the same).
  if (rays_find == RaysFind::Nothing) return L;
  std::optional<BsdfSample> bs = bsdf.sample_f(wo, u.u_lobe, u.u_dir, sctx);
  // A specular lobe cannot meet light sampling; the path continues through it instead (or, at a
  // visible point, that lobe is not followed, as in pbrt).
  if (!bs || bs->is_specular() || !(bs->pdf > 0.f) || is_black(bs->f)) return L;
  Vec3 wi = si.shading.to_world(bs->wi);
  if (!consistent_sides(si, wo, bs->wi, wi)) return L;
  Rgb weight = bs->f * std::abs(bs->wi.z) / bs->pdf;
  Ray ray = si.spawn_ray(wi);
  // Where only the sky emits, a ray that hits anything adds nothing: whether it escapes is enough
  // (an any-hit query, and no hit record to build).
  if (rays_find == RaysFind::Environment) {
    if (scene.occluded(ray)) return L;
    return L + escaped_light(scene, ray, lctx, wi, weight, bs->pdf, wavelengths);
  }
  std::optional<SurfaceInteraction> hit = scene.intersect(ray);
  if (scene.has_media())
    weight *= scene.segment_transmittance(si.media.leaving(si.ng, wi, arrived_in),
                                          hit ? hit->media.toward(hit->ng, -wi) : kMediumUnknown,
                                          hit ? hit->t * glm::length(ray.d) : Infinity, wavelengths);
  if (hit) {
    if (const Light* light = hit->area_light) {
      Rgb Le = light->L(hit->p, hit->ng, hit->uv, hit->wo);
      if (!is_black(Le)) {
        float light_pdf = scene.light_pmf(light) * light->pdf_li(lctx, wi, *hit);
        L += weight * emission_at(wavelengths, Le) * power_heuristic(1, bs->pdf, 1, light_pdf);
      }
    }
  } else {
    L += escaped_light(scene, ray, lctx, wi, weight, bs->pdf, wavelengths);
  }
  return L;
}

// The number of fresh BSDF samples up to and including the first that is not a delta: geometric with
// mean 1 / P(not a delta), an unbiased estimate of it (on average one draw per call, however small P
// is, since the caller reaches here with probability P). The cap only guards against a BSDF whose
// flags promise non-delta lobes it never samples. The dimensions follow the path's last ones: the
// path ends here.
int draws_until_not_specular(const Bsdf& bsdf, const Vec3& wo, const ShadingContext& sctx, Sampler& sampler) {
  constexpr int kMaxDraws = 1 << 16;
  int n = 1;
  for (; n < kMaxDraws; ++n) {
    float uc = sampler.get_1d();
    Vec2 u = sampler.get_2d();
    std::optional<BsdfSample> s = bsdf.sample_f(wo, uc, u, sctx);
    if (!s || !s->is_specular()) break;
  }
  return n;
}

}  // namespace

RaysFind what_rays_find(const Scene& scene) {
  for (const Light* light : scene.lights())
    if (light->type() == LightType::Area) return RaysFind::Anything;
  if (scene.infinite_lights().empty()) return RaysFind::Nothing;
  return scene.has_media() ? RaysFind::Anything : RaysFind::Environment;
}

CameraPathResult trace_camera_path(const Scene& scene, const Ray& camera_ray, Sampler& sampler, int max_depth,
                                   RaysFind rays_find, const SampledWavelengths* wavelengths) {
  CameraPathResult out;
  Ray ray = camera_ray;
  float distance = 0.f;
  // The filter's weight is left out: the film normalises pixel samples by their summed weights, and
  // SPPM's single sample per pixel and iteration is drawn from the (non-negative) filter itself.
  Rgb beta(1.f);
  float eta_scale = 1.f;  // product of eta'^2 over the refractions so far (as the path tracer's)
  bool specular_bounce = false;
  int medium = kMediumUnknown;  // the medium `ray` travels in, where known (absorbing media)
  const bool media = scene.has_media();
  for (int depth = 0;; ++depth) {
    std::optional<SurfaceInteraction> si = scene.intersect(ray);
    if (media) {
      medium = segment_medium(medium, si ? si->media.toward(si->ng, -ray.d) : kMediumUnknown);
      beta *= scene.transmittance(medium, si ? si->t * glm::length(ray.d) : Infinity, wavelengths);
    }
    // Emission counts here only where direct lighting could not have found it: on the camera ray
    // and after specular bounces.
    bool count_emission = depth == 0 || specular_bounce;
    if (!si) {
      if (count_emission)
        for (const Light* light : scene.infinite_lights()) out.Ld += beta * emission_at(wavelengths, light->Le(ray));
      break;
    }
    if (si->area_light && count_emission)
      out.Ld += beta * emission_at(wavelengths, si->area_light->L(si->p, si->ng, si->uv, si->wo));
    distance += glm::length(si->p - ray.o);
    if (depth == max_depth) break;

    const Bsdf& bsdf = *si->bsdf;
    uint32_t flags = bsdf.flags();
    DirectSamples du{sampler.get_1d(), sampler.get_2d(), sampler.get_1d(), sampler.get_2d()};
    float u_lobe = sampler.get_1d();
    Vec2 u_dir = sampler.get_2d();
    float u_rr = sampler.get_1d();
    if (flags == 0) break;
    Vec3 wo = si->shading.to_local(si->wo);
    ShadingContext sctx{si->texture_context(), TransportMode::Radiance};
    sctx.tex.wavelengths = wavelengths;
    if (!bsdf.is_specular_only())
      out.Ld += beta * direct_light(*si, wo, bsdf, sctx, scene, du, rays_find, medium, wavelengths);

    // The continuation; a BSDF with diffuse and delta lobes needs it for the decision below.
    const bool diffuse = flags & BsdfDiffuse, has_delta = flags & BsdfSpecular;
    std::optional<BsdfSample> bs;
    if (!diffuse || has_delta) bs = bsdf.sample_f(wo, u_lobe, u_dir, sctx);

    // A diffuse surface keeps the point for the photons, unless no photon path could still fit
    // within maxdepth (then direct light was all there was to add). A delta lobe next to the
    // diffuse one (a Disney mirror on a diffuse base) is invisible to the point (the gather uses
    // f(), which leaves deltas out), so its light must come from the camera side: the BSDF's own
    // lobe choice splits the two. A delta sample continues the path (its weight F / p_delta is
    // unbiased for the delta part); any other outcome leaves the point, weighted by an unbiased
    // estimate of 1 / P(not a delta).
    if (diffuse && !(has_delta && bs && bs->is_specular())) {
      if (depth + 1 < max_depth) {
        Rgb vp_beta = beta;
        if (has_delta) vp_beta *= float(draws_until_not_specular(bsdf, wo, sctx, sampler));
        out.vp = VisiblePoint{si->shading, wo, sctx.tex, &bsdf, vp_beta, max_depth - 1 - depth};
        out.p = si->p;
        out.distance = distance;
      }
      break;
    }

    // Specular and glossy surfaces (and a mixed BSDF's delta samples) pass the path on: photons are
    // poor at narrow lobes.
    if (!bs || !(bs->pdf > 0.f) || is_black(bs->f)) break;
    Vec3 wi = si->shading.to_world(bs->wi);
    if (!consistent_sides(*si, wo, bs->wi, wi)) break;
    beta *= bs->f * std::abs(bs->wi.z) / bs->pdf;
    if (bs->flags & BsdfTransmission) eta_scale *= sqr(bs->eta);
    specular_bounce = bs->is_specular();
    ray = si->spawn_ray(wi);
    medium = si->media.leaving(si->ng, wi, medium);
    // Roulette only for dim paths: a visible point's throughput multiplies every photon it gathers.
    // Radiance compressed inside glass (1/eta'^2) does not count as dim.
    float m = max_component(beta) * eta_scale;
    if (m < 0.25f) {
      if (u_rr >= m) break;
      beta /= m;
    }
  }
  return out;
}

}  // namespace penumbra::sppm
