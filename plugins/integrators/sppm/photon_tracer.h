// Photon paths for SPPM: one light chosen by power, one emitted ray, then BSDF sampling in importance
// mode with Russian roulette that keeps photon weights near the emitted power (pbrt's rule).
#pragma once

#include <penumbra/bsdf.h>
#include <penumbra/rng.h>
#include <penumbra/scene.h>
#include <penumbra/spectrum.h>

#include <algorithm>
#include <cstdint>

namespace penumbra::sppm {

/// Random numbers of photon `index` in iteration `iteration`: a PCG32 stream of its own, so photons
/// do not depend on which thread traces them or in what order.
inline Pcg32 photon_rng(uint64_t seed, uint64_t iteration, uint64_t index) {
  return Pcg32(hash_ints(seed, iteration, index), hash_ints(index, seed));
}

/// Traces one photon with at most `max_depth` hits and calls
///   deposit(const SurfaceInteraction& hit, const Vec3& wi, const Rgb& beta, int depth)
/// at every hit on a surface that can scatter non-specularly (no visible point lies on a mirror or
/// clear glass, so hits there carry nothing to gather). wi points back along the photon; beta is the
/// photon's flux weight, whose expectation at depth d is the power that arrives after d bounces.
/// Depth 0 is the light's own direct illumination. In a spectral render beta holds the flux at
/// `wavelengths` (the iteration's); null: RGB.
template <class Deposit>
void trace_photon(const Scene& scene, Pcg32& rng, int max_depth, const SampledWavelengths* wavelengths,
                  Deposit&& deposit) {
  float u_light = rng.next_float();
  Vec2 u_pos(rng.next_float(), rng.next_float());
  Vec2 u_dir(rng.next_float(), rng.next_float());
  std::optional<SampledLight> sl = scene.sample_light(u_light);
  if (!sl || !(sl->pmf > 0.f)) return;
  std::optional<LightLeSample> le = sl->light->sample_le(u_pos, u_dir);
  if (!le || !(le->pdf_pos > 0.f) || !(le->pdf_dir > 0.f) || is_black(le->L)) return;
  // Points, spots and infinite lights have no surface at the origin: their L already is what
  // leaves along the ray (intensity, or radiance over the disk the ray starts on).
  float cos = le->n == Vec3(0.f) ? 1.f : std::abs(glm::dot(le->n, glm::normalize(le->ray.d)));
  Rgb beta = emission_at(wavelengths, le->L) * cos / (sl->pmf * le->pdf_pos * le->pdf_dir);
  if (!is_finite(beta) || is_black(beta)) return;

  Ray ray = le->ray;
  ray.d = glm::normalize(ray.d);
  int medium = kMediumUnknown;  // the medium `ray` travels in, where known (absorbing media)
  const bool media = scene.has_media();
  for (int depth = 0; depth < max_depth; ++depth) {
    std::optional<SurfaceInteraction> si = scene.intersect(ray);
    if (!si) return;
    if (media) {  // absorption along the segment: the photon's flux weight falls
      medium = segment_medium(medium, si->media.toward(si->ng, -ray.d));
      beta *= scene.transmittance(medium, si->t, wavelengths);
      if (is_black(beta)) return;
    }
    const Bsdf& bsdf = *si->bsdf;
    uint32_t flags = bsdf.flags();
    if (flags == 0) return;  // black: absorbs everything
    if (!bsdf.is_specular_only()) deposit(*si, si->wo, beta, depth);
    if (depth + 1 == max_depth) return;

    // The next bounce; the three numbers are drawn whatever happens, so streams stay aligned.
    float u_lobe = rng.next_float();
    Vec2 u = Vec2(rng.next_float(), rng.next_float());
    float u_rr = rng.next_float();
    ShadingContext sctx{si->texture_context(), TransportMode::Importance};
    sctx.tex.wavelengths = wavelengths;
    Vec3 wo = si->shading.to_local(si->wo);
    std::optional<BsdfSample> bs = bsdf.sample_f(wo, u_lobe, u, sctx);
    if (!bs || !(bs->pdf > 0.f) || is_black(bs->f)) return;
    Vec3 wi = si->shading.to_world(bs->wi);
    // The path integrator's leak test: shading and geometry must agree on reflection vs transmission.
    bool reflect_shading = bs->wi.z * wo.z > 0.f;
    bool reflect_geometric = glm::dot(wi, si->ng) * glm::dot(si->wo, si->ng) > 0.f;
    if (reflect_shading != reflect_geometric) return;
    Rgb beta_new = beta * bs->f * std::abs(bs->wi.z) / bs->pdf;

    // Survive with probability lum(beta_new) / lum(beta), then divide: surviving photons keep about
    // the weight they had, so the deposits of one pass have similar magnitudes. Values at three
    // wavelengths have no luminance weights (a flux left at the wavelength weighted 0.07 would
    // survive rarely and then carry 14 times its weight): there the largest value plays its part.
    auto weight = [wavelengths](const Rgb& b) { return wavelengths ? max_component(b) : luminance(b); };
    float lum = weight(beta), lum_new = weight(beta_new);
    if (!(lum > 0.f) || !(lum_new > 0.f) || !is_finite(beta_new)) return;
    float q = std::max(0.f, 1.f - lum_new / lum);
    if (u_rr < q) return;
    beta = beta_new / (1.f - q);
    ray = si->spawn_ray(wi);
    medium = si->media.leaving(si->ng, wi, medium);
  }
}

}  // namespace penumbra::sppm
