// Integrators own their render loop. Most estimate each pixel sample on its own: they derive from
// PixelIntegrator and implement Li(); the runtime then renders tiles in parallel (oneTBB), in passes
// of samples so that a time budget or a snapshot never cuts a pass, shows progress, and discards
// non-finite samples (counted in the stats) before they reach the film.
#pragma once

#include <penumbra/bsdf.h>
#include <penumbra/film.h>
#include <penumbra/image.h>
#include <penumbra/object.h>
#include <penumbra/sampler.h>
#include <penumbra/scene.h>

#include <cstdint>
#include <functional>

namespace penumbra {

/// How much to render, decided by the scene and the command line.
struct RenderOptions {
  int spp = 16;                // samples per pixel (a maximum when a time budget is set)
  int first_sample = 0;        // index of the first sample: a part of a split render takes indices
                               // [first_sample, first_sample + spp) of one sequence (iterations for
                               // photon mapping, which seeds each part by its first iteration)
  double time_budget = 0.0;    // seconds; 0 means no limit
  int threads = 0;             // 0: all cores
};

/// What the runtime hands an integrator.
class RenderContext {
 public:
  virtual ~RenderContext();
  virtual const Scene& scene() const = 0;
  virtual Film& film() = 0;
  /// Prototype sampler; clone() one per thread.
  virtual const Sampler& sampler() const = 0;
  virtual const RenderOptions& options() const = 0;
  /// Seconds since the render started.
  virtual double elapsed() const = 0;
  /// Reports progress in units of `total` (e.g. pixel samples); thread-safe.
  virtual void progress(uint64_t done, uint64_t total) = 0;
  /// Records a discarded non-finite sample at `pixel`; thread-safe.
  virtual void report_nonfinite(Point2i pixel) = 0;
  /// Records that `spp` samples per pixel (or iterations) are complete; call it after every whole
  /// pass. The runtime may then take a snapshot of the current estimate (convergence studies): from
  /// the film, or, when the film does not hold the estimate (photon mapping), from `estimate`, which
  /// it calls only for a snapshot. Time spent in snapshots is excluded from elapsed().
  virtual void set_completed_spp(int spp, const std::function<ImageRgb()>& estimate = {}) = 0;
};

class Integrator : public Object {
 public:
  ~Integrator() override;
  virtual void render(RenderContext& ctx) = 0;
};

/// Base for integrators whose pixel samples are independent (path tracing and its relatives).
class PixelIntegrator : public Integrator {
 public:
  ~PixelIntegrator() override;
  void render(RenderContext& ctx) override;
  /// Radiance arriving along the camera ray. Draw random numbers only from `sampler`.
  virtual Rgb Li(const Ray& ray, Sampler& sampler, const Scene& scene) const = 0;
};

}  // namespace penumbra
