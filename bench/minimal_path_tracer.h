// A minimal path tracer written straight on Embree, as the yardstick for the renderer's own
// overheads: what a one-file path tracer with the same estimator reaches on the same geometry.
//
// It traces the top-level Embree scene of an EmbreeScene and computes the same estimator as the
// "path" integrator on scenes of Lambertian triangles lit by diffuse area lights: next-event
// estimation of a light chosen by power and sampled uniformly by area, cosine-weighted BSDF
// sampling, the two combined by the power heuristic, Russian roulette on the throughput from
// `rr_depth`, paths up to `max_depth` bounces. What it leaves out is what makes the renderer a
// renderer: plugins and virtual calls per vertex, samplers, hit records with shading frames and
// texture footprints, robust ray offsets (it starts rays at a fixed tnear), pixel filters (a box),
// AOVs, checkpoints, progress. The constructor refuses any other scene with an Error.
//
// Layers put the renderer's own pieces back one at a time, so that the cost of each shows as a
// difference in time at the same estimator: kHits traces through Scene::intersect() and occluded()
// (hit records, robust ray offsets), kLights samples lights through Scene::sample_light() and
// Light::sample_li() / pdf_li(), kBsdf evaluates and samples the Bsdf objects in the shading frame.
// kRobust instead keeps the minimal tracer and gives it only the renderer's robust ray origins.
#pragma once

#include "scene/embree_scene.h"

#include <penumbra/math.h>

#include <cstdint>
#include <vector>

namespace penumbra {

// kRobust is the minimal tracer alone with the renderer's robust ray origins instead of a fixed tnear:
// hit points from the barycentrics with their error bounds, secondary and shadow rays offset past
// them (penumbra/interaction.h), everything else as kMinimalOnly. It goes alone, not with the layers.
enum MinimalLayers : unsigned { kMinimalOnly = 0, kHits = 1, kLights = 2, kBsdf = 4, kRobust = 8 };

struct MinimalRenderResult {
  double seconds = 0.0;  // rendering only
  uint64_t rays = 0;     // closest-hit and shadow rays
  uint64_t samples = 0;
  double mean = 0.0;     // mean over the image of the pixels' mean of R, G and B
};

class MinimalPathTracer {
 public:
  MinimalPathTracer(const EmbreeScene& scene, int max_depth, int rr_depth);
  /// Renders the scene's camera at `resolution` (the camera must have been built for it) with
  /// `spp` samples per pixel on `threads` threads; `seed` picks the random streams.
  MinimalRenderResult render(Point2i resolution, int spp, int threads, uint64_t seed = 0,
                             unsigned layers = kMinimalOnly) const;

 private:
  struct Triangle {
    Vec3 p0, e1, e2;      // a vertex and the two edges from it
    Vec3 n;               // the renderer's geometric normal (the side lights emit on)
    Rgb albedo;           // reflectance of the Lambertian BSDF
    Rgb le_front, le_back;  // emitted radiance on the side of n and on the other side
    float area;
    const Bsdf* bsdf;
  };
  template <unsigned kLayers>
  Rgb Li(const Ray& camera_ray, uint64_t stream, uint64_t seed, uint64_t* rays) const;
  template <unsigned kLayers>
  MinimalRenderResult render_with(Point2i resolution, int spp, int threads, uint64_t seed) const;

  const EmbreeScene& scene_;
  int max_depth_, rr_depth_;
  std::vector<uint32_t> first_triangle_;  // per Embree geometry id, into triangles_
  std::vector<Triangle> triangles_;
  std::vector<Vec3> other_vertices_;      // p1 and p2 of each triangle, for kRobust's hit points
  std::vector<const Light*> tri_lights_;  // per triangle, null where it does not emit
  std::vector<uint32_t> emitters_;        // indices into triangles_
  std::vector<float> emitter_cdf_;        // by the lights' power, emitters_.size() + 1 entries
  std::vector<float> emitter_pmf_;        // per triangle (0 for those that do not emit)
};

}  // namespace penumbra
