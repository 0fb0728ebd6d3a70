// The scene as integrators see it: ray queries through Embree, lights with a selection
// distribution proportional to power, the camera and the bounds.
#pragma once

#include <penumbra/camera.h>
#include <penumbra/interaction.h>
#include <penumbra/light.h>

#include <optional>
#include <span>

namespace penumbra {

struct Bounds3 {
  Vec3 min{Infinity};
  Vec3 max{-Infinity};
  void extend(const Vec3& p) { min = glm::min(min, p); max = glm::max(max, p); }
};

struct SampledLight {
  const Light* light = nullptr;
  float pmf = 0.f;
};

class Scene {
 public:
  virtual ~Scene();
  /// Closest hit along the ray in (0, ray.tmax).
  virtual std::optional<SurfaceInteraction> intersect(const Ray& ray) const = 0;
  /// Whether anything is hit in (0, ray.tmax).
  virtual bool occluded(const Ray& ray) const = 0;

  virtual std::span<const Light* const> lights() const = 0;
  /// Lights that rays escaping the scene see (environment, distant sources excluded).
  virtual std::span<const Light* const> infinite_lights() const = 0;
  /// Picks a light with probability proportional to its power. Empty when there are no lights.
  virtual std::optional<SampledLight> sample_light(float u) const = 0;
  /// Probability that sample_light() picks `light`.
  virtual float light_pmf(const Light* light) const = 0;

  virtual const Camera& camera() const = 0;
  virtual Bounds3 bounds() const = 0;

  /// Participating media: pbrt-v4's homogeneous media that absorb without scattering, bounded by
  /// surfaces whose SurfaceInteraction::media differ on their two sides. Whether the scene has any
  /// (integrators may skip all medium bookkeeping when not).
  virtual bool has_media() const { return false; }
  /// Beer-Lambert transmittance exp(-sigma_a distance) of medium `medium` (-1, vacuum: 1). An
  /// infinite distance through an absorbing medium gives 0. In a spectral render, at `wavelengths`
  /// (sigma_a as an unbounded spectrum); null: RGB.
  virtual Rgb transmittance(int medium, float distance, const SampledWavelengths* wavelengths = nullptr) const;
  /// Transmittance of a segment between two ends (see segment_medium()).
  Rgb segment_transmittance(int from_side, int to_side, float distance,
                            const SampledWavelengths* wavelengths = nullptr) const {
    int m = segment_medium(from_side, to_side);
    return m < 0 ? Rgb(1.f) : transmittance(m, distance, wavelengths);
  }
};

}  // namespace penumbra
