// Integrator "path": unidirectional path tracing with next-event estimation, combining light and
// BSDF sampling by multiple importance sampling (power heuristic), and Russian roulette.
//
// | parameter       | default | meaning                                                    |
// |-----------------|---------|------------------------------------------------------------|
// | integer maxdepth| 5       | longest path in bounces (0: emitters seen directly only)   |
// | integer rrdepth | 3       | bounces before Russian roulette may end a path             |
// | string strategy | mis     | "mis": light and BSDF sampling combined; "bsdf": BSDF      |
// |                 |         | sampling only (emitters count when hit; for comparisons)   |
//
// Depth convention (pbrt's): a path of depth d has d scattering events between camera and emitter,
// so maxdepth D sums the series L_e + ... + (throughput)^D L_e exactly.
//
// Russian roulette (after rrdepth bounces) continues with probability min(1, max component of the
// throughput times the product of eta'^2 of the refractions so far), as pbrt-v4 does.
//
// Sample dimensions per bounce are fixed (light choice 1, light point 2, BSDF lobe 1, BSDF
// direction 2, roulette 1), so quasi-random samplers see the same dimension at every depth.
#include <penumbra/integrator.h>
#include <penumbra/plugin.h>
#include <penumbra/sampling.h>

namespace {

using namespace penumbra;

class PathIntegrator final : public PixelIntegrator {
 public:
  PathIntegrator(int max_depth, int rr_depth, bool light_sampling)
      : max_depth_(max_depth), rr_depth_(rr_depth), light_sampling_(light_sampling) {}

  bool supports_spectral() const override { return true; }

  bool takes_first_hit() const override { return true; }

  Rgb Li(const Ray& camera_ray, const std::optional<SurfaceInteraction>* first_hit,
         const SampledWavelengths* wavelengths, Sampler& sampler, const Scene& scene) const override {
    Rgb L(0.f), beta(1.f);
    Ray ray = camera_ray;
    bool specular_bounce = false;
    float bsdf_pdf = 0.f;            // density of the direction that produced `ray`
    float eta_scale = 1.f;           // product of eta'^2 over the refractions so far
    LightSampleContext prev_ctx;     // the vertex that produced `ray`
    int medium = kMediumUnknown;     // the medium `ray` travels in, where known (absorbing media)
    const bool media = scene.has_media();

    for (int depth = 0;; ++depth) {
      std::optional<SurfaceInteraction> si = depth == 0 && first_hit ? *first_hit : scene.intersect(ray);
      if (media) {  // absorption along the segment just traced
        medium = segment_medium(medium, si ? si->media.toward(si->ng, -ray.d) : kMediumUnknown);
        beta *= scene.transmittance(medium, si ? si->t * glm::length(ray.d) : Infinity, wavelengths);
      }
      if (!si) {
        for (const Light* light : scene.infinite_lights()) {
          Rgb Le = light->Le(ray);
          if (is_black(Le)) continue;
          Le = emission_at(wavelengths, Le);
          if (depth == 0 || specular_bounce || !light_sampling_) {
            L += beta * Le;
          } else {
            SurfaceInteraction none;
            float light_pdf = scene.light_pmf(light) * light->pdf_li(prev_ctx, ray.d, none);
            L += beta * Le * power_heuristic(1, bsdf_pdf, 1, light_pdf);
          }
        }
        break;
      }

      // Emission found by the BSDF-sampled ray, weighted against light sampling.
      if (si->area_light) {
        Rgb Le = si->area_light->L(si->p, si->ng, si->uv, si->wo);
        if (!is_black(Le)) {
          Le = emission_at(wavelengths, Le);
          if (depth == 0 || specular_bounce || !light_sampling_) {
            L += beta * Le;
          } else {
            float light_pdf = scene.light_pmf(si->area_light) * si->area_light->pdf_li(prev_ctx, ray.d, *si);
            L += beta * Le * power_heuristic(1, bsdf_pdf, 1, light_pdf);
          }
        }
      }
      if (depth == max_depth_) break;

      const Bsdf& bsdf = *si->bsdf;
      const uint32_t flags = bsdf.flags();  // asked once: a virtual call
      Vec3 wo = si->shading.to_local(si->wo);
      ShadingContext sctx{si->texture_context(), TransportMode::Radiance};
      sctx.tex.wavelengths = wavelengths;

      // Next-event estimation (the dimensions are drawn even when unused). A BSDF with delta lobes
      // among others (Disney's mirror on a diffuse base) gets it through f() and pdf() of the others;
      // its delta samples are told apart below by their own flag (no MIS for what they hit).
      float u_light = sampler.get_1d();
      Vec2 u_light_point = sampler.get_2d();
      // The BSDF sample that continues the path is drawn before next-event estimation and used after
      // it: its chain of dependent arithmetic then overlaps the light sample and the shadow ray
      // instead of delaying the next ray (same values, same sampler dimensions, in the same order).
      float u_lobe = sampler.get_1d();
      Vec2 u_dir = sampler.get_2d();
      float u_rr = sampler.get_1d();
      std::optional<BsdfSample> bs = flags ? bsdf.sample_f(wo, u_lobe, u_dir, sctx) : std::nullopt;
      if (light_sampling_ && flags != 0 && !Bsdf::is_specular_only(flags))
        L += beta * sample_direct(*si, wo, bsdf, sctx, scene, u_light, u_light_point, medium, wavelengths);

      // Continue the path with the BSDF sample.
      if (!bs || !(bs->pdf > 0.f) || is_black(bs->f)) break;
      Vec3 wi = si->shading.to_world(bs->wi);
      // Reject directions that the shading normal calls reflection but the geometry calls
      // transmission (and vice versa): they would leak light through the surface.
      bool reflect_shading = bs->wi.z * wo.z > 0.f;
      bool reflect_geometric = glm::dot(wi, si->ng) * glm::dot(si->wo, si->ng) > 0.f;
      if (reflect_shading != reflect_geometric) break;
      beta *= bs->f * std::abs(bs->wi.z) / bs->pdf;
      specular_bounce = bs->is_specular();
      bsdf_pdf = bs->pdf;
      if (bs->flags & BsdfTransmission) eta_scale *= sqr(bs->eta);
      // mis_light_context(*si), member by member: built whole and copied, the context was stored in
      // pieces and reloaded in wider ones, which stalls store forwarding (3 % of the path tracer's time).
      prev_ctx.p = si->p;
      prev_ctx.n = ng_towards_wo(*si);
      prev_ctx.allow_incomplete_pdf = true;
      ray = si->spawn_ray(wi);
      medium = si->media.leaving(si->ng, wi, medium);

      // Roulette on the throughput without the 1/eta'^2 of refractions (pbrt-v4's etaScale): radiance
      // compressed inside glass is not less important, and would otherwise be ended too often.
      if (depth + 1 >= rr_depth_) {
        float q = std::max(0.f, 1.f - max_component(beta * eta_scale));
        if (u_rr < q) break;
        beta /= 1.f - q;
      }
    }
    return L;
  }

 private:
  Rgb sample_direct(const SurfaceInteraction& si, const Vec3& wo, const Bsdf& bsdf, const ShadingContext& sctx,
                    const Scene& scene, float u_light, Vec2 u, int arrived_in,
                    const SampledWavelengths* wavelengths) const {
    std::optional<SampledLight> sl = scene.sample_light(u_light);
    if (!sl) return Rgb(0.f);
    LightSampleContext lctx = mis_light_context(si);
    std::optional<LightLiSample> ls = sl->light->sample_li(lctx, u);
    if (!ls || !(ls->pdf > 0.f) || is_black(ls->L)) return Rgb(0.f);
    Vec3 wi = si.shading.to_local(ls->wi);
    Rgb f = bsdf.f(wo, wi, sctx) * std::abs(wi.z);
    if (is_black(f)) return Rgb(0.f);
    // Same leak test as for BSDF sampling, against the geometric normal.
    if ((wi.z * wo.z > 0.f) != (glm::dot(ls->wi, si.ng) * glm::dot(si.wo, si.ng) > 0.f)) return Rgb(0.f);
    if (scene.occluded(si.spawn_ray_to(ls->p_light, ls->n_light))) return Rgb(0.f);
    if (scene.has_media())
      f *= scene.segment_transmittance(si.media.leaving(si.ng, ls->wi, arrived_in), kMediumUnknown,
                                       glm::length(ls->p_light - si.p), wavelengths);
    Rgb Li = emission_at(wavelengths, ls->L);
    float light_pdf = sl->pmf * ls->pdf;
    if (is_delta_light(sl->light->type())) return f * Li / light_pdf;
    float w = power_heuristic(1, light_pdf, 1, bsdf.pdf(wo, wi, sctx));
    return f * Li * w / light_pdf;
  }

  int max_depth_, rr_depth_;
  bool light_sampling_;
};

const ParamSpec kParams[] = {
    {"integer", "maxdepth", "5", "longest path in bounces (0: emitters seen directly only)"},
    {"integer", "rrdepth", "3", "bounces before Russian roulette may end a path"},
    {"unsupported", "regularize", "", "path regularisation is not implemented"},
    {"string", "lightsampler", "power", "light selection: power (the only one so far)"},
    {"string", "strategy", "mis", "mis: light + BSDF sampling with MIS; bsdf: BSDF sampling only"},
};

Object* create(const CreateContext& ctx) {
  int max_depth = ctx.params.get_int("maxdepth");
  if (max_depth < 0) throw Error(ctx.params.loc_of("maxdepth"), "maxdepth must be >= 0");
  int rr_depth = ctx.params.get_int("rrdepth");
  if (rr_depth < 1) throw Error(ctx.params.loc_of("rrdepth"), "rrdepth must be >= 1");
  std::string ls = ctx.params.get_string("lightsampler");
  if (ls != "power")
    throw Error(ctx.params.loc_of("lightsampler"), "lightsampler '" + ls + "' is not supported; available: power");
  std::string strategy = ctx.params.get_string("strategy");
  if (strategy != "mis" && strategy != "bsdf")
    throw Error(ctx.params.loc_of("strategy"), "strategy '" + strategy + "' is not supported; available: mis, bsdf");
  return new PathIntegrator(max_depth, rr_depth, strategy == "mis");
}

// pbrt-v4's "volpath" is its path tracer with media; this one simulates the media Penumbra has
// (absorbing, core/src/scene/media.h), so scenes that name it render unchanged.
const char* const kAliases[] = {"volpath", nullptr};

}  // namespace

PENUMBRA_PLUGIN_WITH_ALIASES(Integrator, "path", "unidirectional path tracer with next-event estimation and MIS",
                             kParams, create, kAliases)
