// The camera pass of SPPM: one path per pixel and iteration, followed through specular and glossy
// bounces to the first diffuse surface, where it leaves a visible point for the photons.
#pragma once

#include "visible_point.h"

#include <penumbra/camera.h>
#include <penumbra/sampler.h>
#include <penumbra/scene.h>
#include <penumbra/spectrum.h>

namespace penumbra::sppm {

/// What a BSDF-sampled direct-light ray can find, which decides how it is traced.
enum class RaysFind {
  Nothing,     // only point, spot and distant lights: the ray is not traced
  Environment, // infinite lights only, no media: an occlusion test tells whether the ray escapes
  Anything,    // area lights (or media on the way): the closest hit is needed
};

struct CameraPathResult {
  Rgb Ld{0.f};       // emission seen along the prefix plus direct light at its non-specular vertices
  VisiblePoint vp;   // vp.bsdf == nullptr when the path found no diffuse surface
  Vec3 p{0.f};       // the visible point's position
  float distance = 0.f;  // length of the camera path up to the visible point
};

/// Traces the camera path that starts with `camera_ray`; the render loop has started `sampler` at
/// the pixel sample and drawn the pixel (2) and lens (2) dimensions. Then 10 dimensions per bounce
/// (light 1 + 2, direct-light BSDF sample 1 + 2, continuation 1 + 2, roulette 1), drawn whether used
/// or not so that quasi-random samplers keep their dimensions aligned across paths. A visible point
/// on a BSDF with delta and diffuse lobes draws 3 more per extra BSDF sample after the last bounce's.
/// `rays_find` is what_rays_find(scene): which emitters a BSDF-sampled direct-light ray can find.
/// In a spectral render `wavelengths` are the iteration's: Ld and the visible point's throughput are
/// then values at those wavelengths (null: RGB).
CameraPathResult trace_camera_path(const Scene& scene, const Ray& camera_ray, Sampler& sampler, int max_depth,
                                   RaysFind rays_find = RaysFind::Anything,
                                   const SampledWavelengths* wavelengths = nullptr);

/// Which emitters a ray can find in `scene`.
RaysFind what_rays_find(const Scene& scene);

}  // namespace penumbra::sppm
