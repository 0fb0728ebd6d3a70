// Integrators plug into the core's one render loop. The loop owns tiles, passes of samples, sample
// indices, the time budget, progress, AOVs, non-finite guards and splats; an integrator supplies the
// estimate of one pixel sample (SampleIntegrator::sample) and, where its algorithm needs it, work
// before and after each pass (a light-vertex cache, a photon pass). Most integrators estimate each
// pixel sample on its own from the camera ray: they derive from PixelIntegrator and implement Li().
#pragma once

#include <penumbra/bsdf.h>
#include <penumbra/camera.h>
#include <penumbra/film.h>
#include <penumbra/image.h>
#include <penumbra/object.h>
#include <penumbra/sampler.h>
#include <penumbra/scene.h>
#include <penumbra/spectrum.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <type_traits>
#include <vector>

namespace penumbra {

/// How much to render, decided by the scene and the command line.
struct RenderOptions {
  int spp = 16;                // samples per pixel (a maximum when a time budget is set)
  int first_sample = 0;        // index of the first sample: a part of a split render takes indices
                               // [first_sample, first_sample + spp) of one sequence (iterations for
                               // photon mapping, which seeds each part by its first iteration)
  double time_budget = 0.0;    // seconds; 0 means no limit
  int threads = 0;             // 0: all cores
  bool spectral = false;       // spectral transport (penumbra/spectrum.h): each pixel sample carries
                               // three wavelengths (PixelSample::wavelengths), and the loop turns its
                               // estimate and splats into RGB
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
  /// True once the render should end as soon as possible (the time budget is spent); work that
  /// takes long (a photon pass) checks it between batches. Thread-safe.
  virtual bool should_stop() const = 0;
  /// Reports progress in units of `total` (e.g. pixel samples); thread-safe.
  virtual void progress(uint64_t done, uint64_t total) = 0;
  /// Records a discarded non-finite sample at `pixel`; thread-safe.
  virtual void report_nonfinite(Point2i pixel) = 0;
  /// Records that `spp` samples per pixel (or iterations) are complete; called after every pass.
  /// `splat_spp` is what the film's splats are divided by (the pixel samples taken over the pixel
  /// count; it exceeds `spp` when a pass was cut short by the time budget; 0: `spp`). The runtime
  /// may take a snapshot of the current estimate (convergence studies): from the film or, when the
  /// film does not hold the estimate (photon mapping), from `estimate`, which it calls only for a
  /// snapshot. Time spent in snapshots is excluded from elapsed().
  virtual void set_completed_spp(int spp, const std::function<ImageRgb()>& estimate = {},
                                 double splat_spp = 0.0) = 0;
};

class Integrator : public Object {
 public:
  ~Integrator() override;
  virtual void render(RenderContext& ctx) = 0;
};

/// Receives light a pixel sample finds for arbitrary film positions (light paths connected to the
/// lens). Each thread has its own; the core sums them so that the image does not depend on the
/// thread count or scheduling. Values are divided by the samples per pixel when the image is made.
class SplatSink {
 public:
  virtual void splat(const Vec2& p_raster, const Rgb& value) = 0;

 protected:
  ~SplatSink() = default;
};

/// The byte stream of an integrator's own state in a checkpoint (SampleIntegrator::save_state).
class StateWriter {
 public:
  virtual void write(const void* data, size_t bytes) = 0;
  template <class T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    write(&v, sizeof v);
  }
  template <class T>
  void vector(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    value<uint64_t>(v.size());
    write(v.data(), v.size() * sizeof(T));
  }

 protected:
  ~StateWriter() = default;
};

/// Reads back what a StateWriter wrote, in the same order; throws Error when the data run short.
class StateReader {
 public:
  virtual void read(void* data, size_t bytes) = 0;
  template <class T>
  T value() {
    static_assert(std::is_trivially_copyable_v<T>);
    T v;
    read(&v, sizeof v);
    return v;
  }
  /// Reads a vector written by StateWriter::vector; throws Error unless it has `expected` elements.
  template <class T>
  void vector(std::vector<T>& v, uint64_t expected) {
    static_assert(std::is_trivially_copyable_v<T>);
    uint64_t n = value<uint64_t>();
    if (n != expected) mismatch(n, expected);
    v.resize(n);
    read(v.data(), n * sizeof(T));
  }

 protected:
  ~StateReader() = default;
  [[noreturn]] virtual void mismatch(uint64_t got, uint64_t expected) = 0;
};

/// One pixel sample as the render loop hands it over: the sampler has been started at
/// (pixel, index) and has already given the film position and the lens position.
struct PixelSample {
  Point2i pixel;
  uint32_t index = 0;      // sample index in the render's one sequence (split renders included)
  CameraSample camera;     // raster position (filter offset applied) and lens position
  const Ray* ray = nullptr;  // the camera ray; null when none leaves the lens
  /// In a spectral render, the sample's wavelengths (drawn by the loop after the lens position, or
  /// the pass's: see wavelengths_per_pass()): sample() then returns, and splats, values at these
  /// wavelengths, which the loop turns into RGB. Null in an RGB render.
  const SampledWavelengths* wavelengths = nullptr;
  /// The camera ray's first hit (what scene.intersect(*ray) returns), when the render loop traced
  /// it: the loop traces the camera rays of a block of neighbouring pixels as one packet, several
  /// times faster than one at a time, for pixel integrators that ask (PixelIntegrator's
  /// takes_first_hit()). Null otherwise.
  const std::optional<SurfaceInteraction>* first_hit = nullptr;
};

/// A run of sample indices [first_index, first_index + count) rendered for every pixel.
struct Pass {
  uint32_t first_index = 0;
  int count = 1;
  bool complete = true;    // end_pass(): false when the time budget cut the pass short
  /// A spectral render's one set of wavelengths for every sample of this pass, when the integrator
  /// asks for it (wavelengths_per_pass()); null otherwise. Valid until end_pass() returns.
  const SampledWavelengths* wavelengths = nullptr;
};

/// Base for every integrator that renders pixel samples: the core's render loop. Passes of samples
/// (1, 2, 4, ... up to max_pass_samples() per pixel, sized to fit a time budget) run over 16x16
/// tiles in parallel; each pixel's samples are taken in index order by one thread at a time, and
/// a sample must be a pure function of (pixel, index, seed and the state prepared in begin_pass),
/// so images are bit-identical for any thread count. When the time budget runs out the loop starts
/// no further tile; a pass cut short still counts its samples.
class SampleIntegrator : public Integrator {
 public:
  ~SampleIntegrator() override;
  void render(RenderContext& ctx) final;

  /// The estimate of one pixel sample: radiance for `ps.pixel` (added to the film with the filter
  /// weight) plus any splats. Called concurrently from several threads.
  virtual Rgb sample(const Scene& scene, const PixelSample& ps, Sampler& sampler, SplatSink& splats) = 0;

  /// Once, before the first pass.
  virtual void begin_render(RenderContext& ctx) {}
  /// Before each pass, on one thread (e.g. trace and index a light-vertex cache).
  virtual void begin_pass(RenderContext& ctx, const Pass& pass) {}
  /// After each pass, on one thread; may run parallel work of its own (a photon pass), checking
  /// ctx.should_stop() between batches of it and reporting ctx.progress().
  virtual void end_pass(RenderContext& ctx, const Pass& pass) {}
  /// Once, after the last pass; `spp` passes' worth of samples were completed.
  virtual void end_render(RenderContext& ctx, int spp) {}
  /// Largest number of samples per pixel in one pass (1 when begin_pass prepares per-sample state);
  /// asked after begin_render().
  virtual int max_pass_samples() const { return 16; }
  /// False when the film does not hold the estimate (photon mapping; asked after begin_render()):
  /// the loop then adds no pixel samples to the film (only AOVs), snapshots ask estimate(), and end_render() fills the film.
  virtual bool film_holds_estimate() const { return true; }
  /// The current estimate, when the film does not hold it.
  virtual ImageRgb estimate() const { return {}; }
  /// Whether sample() handles PixelSample::wavelengths (converts emission with
  /// emission_at() of penumbra/spectrum.h, hands the wavelengths to the BSDFs' TextureEvalContext). A
  /// spectral render with an integrator that does not is refused before it starts.
  virtual bool supports_spectral() const { return false; }
  /// True when every sample of a pass must share one set of wavelengths (asked after
  /// begin_render()): work prepared for the whole pass (a photon pass, a light-vertex cache) meets
  /// the pixels' paths, and values at different wavelengths cannot be multiplied. The loop then
  /// draws them once per pass (Pass::wavelengths, also PixelSample::wavelengths), stratified over
  /// passes by a radical inverse of the pass's first index; false: each sample draws its own.
  virtual bool wavelengths_per_pass() const { return false; }

  /// Checkpoints (penumbra render --checkpoint / --resume) are taken between passes. An integrator
  /// whose next passes depend on more than (pixel, index, seed) and what begin_render() computes
  /// (photon mapping's per-pixel statistics) saves that state here, after end_pass() ...
  virtual void save_state(StateWriter& out) const {}
  /// ... and reads it back after begin_render() when a render resumes, so that the resumed render
  /// gives the uninterrupted render's image bit for bit.
  virtual void load_state(StateReader& in) {}
};

/// Base for integrators whose pixel samples are independent estimates along the camera ray (path
/// tracing and its relatives).
class PixelIntegrator : public SampleIntegrator {
 public:
  ~PixelIntegrator() override;
  Rgb sample(const Scene& scene, const PixelSample& ps, Sampler& sampler, SplatSink& splats) final {
    return ps.ray ? Li(*ps.ray, ps.first_hit, ps.wavelengths, sampler, scene) : Rgb(0.f);
  }
  /// Radiance arriving along the camera ray: RGB, or in a spectral render (`wavelengths` not null)
  /// its values at the wavelengths. Draw random numbers only from `sampler`. `first_hit` is null,
  /// or scene.intersect(ray) traced by the loop (only when takes_first_hit() says so): use it
  /// instead of tracing the camera ray again.
  virtual Rgb Li(const Ray& ray, const std::optional<SurfaceInteraction>* first_hit,
                 const SampledWavelengths* wavelengths, Sampler& sampler, const Scene& scene) const = 0;
  /// True when Li() starts by tracing the camera ray: the loop then traces it, in packets.
  virtual bool takes_first_hit() const { return false; }
};

}  // namespace penumbra
