// Integrator "ambientocclusion" (alias "ao"): the fraction of the hemisphere above the first hit
// that is open up to a distance, the same estimate and parameters as pbrt-v4's integrator of that
// name, so its scenes render unchanged. An example of a plugin written against the installed SDK.
//
// | parameter         | default   | meaning                                                  |
// |-------------------|-----------|----------------------------------------------------------|
// | bool cossample    | true      | sample directions by cosine (else uniformly)             |
// | float maxdistance | unlimited | occluders further than this do not count                 |
//
// The estimate of one sample is cos(theta) V(wi) / (pi pdf(wi)): with cosine sampling it is the
// visibility itself, 0 or 1. Escaping camera rays are black.
#include <penumbra/integrator.h>
#include <penumbra/plugin.h>
#include <penumbra/sampling.h>

namespace {

using namespace penumbra;

class AmbientOcclusion final : public PixelIntegrator {
 public:
  AmbientOcclusion(bool cos_sample, float max_distance) : cos_sample_(cos_sample), max_distance_(max_distance) {}

  // The loop traces the camera rays of neighbouring pixels as one packet and hands each its hit.
  bool takes_first_hit() const override { return true; }

  Rgb Li(const Ray& ray, const std::optional<SurfaceInteraction>* first_hit, const SampledWavelengths*,
         Sampler& sampler, const Scene& scene) const override {
    std::optional<SurfaceInteraction> si = first_hit ? *first_hit : scene.intersect(ray);
    Vec2 u = sampler.get_2d();  // drawn for misses too, so every sample uses the same dimensions
    if (!si) return Rgb(0.f);

    // The hemisphere on the camera's side of the surface.
    Vec3 n = glm::dot(si->ns, si->wo) < 0.f ? -si->ns : si->ns;
    Vec3 local;
    float pdf;
    if (cos_sample_) {
      local = sample_cosine_hemisphere(u);
      pdf = cosine_hemisphere_pdf(local.z);
    } else {
      local = sample_uniform_sphere(u);
      local.z = std::abs(local.z);
      pdf = Inv2Pi;
    }
    if (!(pdf > 0.f)) return Rgb(0.f);
    Vec3 wi = Frame(n).to_world(local);
    Ray shadow = si->spawn_ray(wi);
    shadow.tmax = max_distance_;
    if (scene.occluded(shadow)) return Rgb(0.f);
    return Rgb(local.z * InvPi / pdf);
  }

 private:
  bool cos_sample_;
  float max_distance_;
};

const ParamSpec kParams[] = {
    {"bool", "cossample", "true", "sample directions by cosine (true) or uniformly over the hemisphere"},
    {"float", "maxdistance", "", "occluders further than this do not count (default: unlimited)"},
};

Object* create(const CreateContext& ctx) {
  float max_distance = ctx.params.get_float("maxdistance", Infinity);
  if (!(max_distance > 0.f)) throw Error(ctx.params.loc_of("maxdistance"), "maxdistance must be > 0");
  return new AmbientOcclusion(ctx.params.get_bool("cossample"), max_distance);
}

const char* const kAliases[] = {"ao", nullptr};

}  // namespace

PENUMBRA_PLUGIN_WITH_ALIASES(Integrator, "ambientocclusion", "ambient occlusion (pbrt-v4's AO integrator)",
                             kParams, create, kAliases)
