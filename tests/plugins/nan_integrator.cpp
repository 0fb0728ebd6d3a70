// Integrator "nan": returns NaN or +Inf for about one sample in five and 1 otherwise, so the tests can
// check that non-finite samples are discarded, counted and reported, and never reach the image.
#include <penumbra/integrator.h>
#include <penumbra/plugin.h>

#include <limits>

namespace {

using namespace penumbra;

class NanIntegrator final : public PixelIntegrator {
 public:
  Rgb Li(const Ray&, const std::optional<SurfaceInteraction>*, const SampledWavelengths*, Sampler& sampler,
         const Scene&) const override {
    float u = sampler.get_1d();
    if (u < 0.1f) return Rgb(std::numeric_limits<float>::quiet_NaN());
    if (u < 0.2f) return Rgb(std::numeric_limits<float>::infinity(), 0.f, 0.f);
    return Rgb(1.f);
  }
};

const ParamSpec kParams[] = {{"integer", "maxdepth", "5", "ignored"}};
Object* create(const CreateContext&) { return new NanIntegrator; }

}  // namespace

PENUMBRA_PLUGIN(Integrator, "nan", "test plugin producing non-finite samples", kParams, create)
