// First-hit data of a camera ray for the albedo, normal and depth AOVs.
#pragma once

#include <penumbra/film.h>
#include <penumbra/scene.h>

#include <cstdint>

namespace penumbra {

/// Traces `ray` once more and describes its first hit. The albedo is f cos / pdf of one BSDF
/// sample drawn from a stream of its own keyed by (pixel, index), so the beauty's sampler
/// dimensions are untouched and split renders reproduce it.
SurfaceSample trace_surface_sample(const Scene& scene, const Ray& ray, Point2i pixel, uint32_t index);

}  // namespace penumbra
