// Out-of-line destructors and defaults of the SDK's interfaces. Defining them here makes the core
// library the one home of their vtables and type information, which dynamic_cast across plugin
// libraries relies on.
#include <penumbra/bsdf.h>
#include <penumbra/camera.h>
#include <penumbra/film.h>
#include <penumbra/integrator.h>
#include <penumbra/light.h>
#include <penumbra/object.h>
#include <penumbra/sampler.h>
#include <penumbra/scene.h>
#include <penumbra/shape.h>
#include <penumbra/texture.h>

namespace penumbra {

Object::~Object() = default;
Sampler::~Sampler() = default;
Bsdf::~Bsdf() = default;
Light::~Light() = default;
Integrator::~Integrator() = default;
SampleIntegrator::~SampleIntegrator() = default;
PixelIntegrator::~PixelIntegrator() = default;
RenderContext::~RenderContext() = default;
Shape::~Shape() = default;
Camera::~Camera() = default;
Film::~Film() = default;
Scene::~Scene() = default;
Rgb Scene::transmittance(int, float, const SampledWavelengths*) const { return Rgb(1.f); }
FloatTexture::~FloatTexture() = default;
SpectrumTexture::~SpectrumTexture() = default;

LobeSummary Bsdf::lobe(const Vec3& wo, const ShadingContext&) const {
  LobeSummary l;
  l.peak = Vec3(0.f, 0.f, wo.z < 0.f ? -1.f : 1.f);
  l.coefficient = 1.f;
  l.cosine = true;
  return l;
}

Rgb Light::L(const Vec3&, const Vec3&, const Vec2&, const Vec3&) const { return Rgb(0.f); }
Rgb Light::Le(const Ray&) const { return Rgb(0.f); }

}  // namespace penumbra
