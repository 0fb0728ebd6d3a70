// First-hit data of a camera ray for the albedo, normal and depth AOVs.
#pragma once

#include <penumbra/film.h>
#include <penumbra/scene.h>

#include <cstdint>
#include <optional>

namespace penumbra {

/// Describes a camera ray's first hit (none: a miss). The albedo is f cos / pdf of one BSDF sample
/// drawn from a stream of its own keyed by (pixel, index), so the beauty's sampler dimensions are
/// untouched and split renders reproduce it.
SurfaceSample describe_surface_sample(const std::optional<SurfaceInteraction>& hit, Point2i pixel, uint32_t index);

/// describe_surface_sample() of scene.intersect(ray): the camera ray traced once more.
SurfaceSample trace_surface_sample(const Scene& scene, const Ray& ray, Point2i pixel, uint32_t index);

}  // namespace penumbra
