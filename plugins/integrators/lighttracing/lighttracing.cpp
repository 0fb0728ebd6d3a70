// Integrator "lighttracing": particle tracing from the lights alone, every vertex connected to the
// lens and splatted (bdpt's t = 1 strategies, unweighted, sharing its code). Points on area lights
// connect directly too, so emitters appear. What it cannot render: anything seen through a specular
// chain from the camera, and environment lights seen directly (both need camera rays). For
// debugging bdpt and for scenes dominated by caustics seen on diffuse surfaces.
//
// | parameter           | default | meaning                                     |
// |---------------------|---------|---------------------------------------------|
// | integer maxdepth    | 5       | longest path in bounces                      |
// | integer rrdepth     | 3       | bounces before Russian roulette may end it  |
// | string lightsampler | power   | light choice: power or uniform              |
//
// One light path per pixel sample: the image has as many light paths as a camera-ray render has
// camera rays, and splats are divided by the samples per pixel.
#include "subpath.h"

#include <penumbra/integrator.h>
#include <penumbra/plugin.h>

namespace {

using namespace penumbra;
using namespace penumbra::bdpt;

class LightTracingIntegrator final : public SampleIntegrator {
 public:
  LightTracingIntegrator(Config config, bool uniform_lights) : config_(config), uniform_lights_(uniform_lights) {
    lens_.kind = VertexKind::Camera;  // connect() only looks at the camera endpoint's kind for t = 1
  }

  void begin_render(RenderContext& rc) override {
    if (!rc.scene().camera().connectible())
      throw Error("integrator 'lighttracing' connects every light vertex to the lens, and this camera cannot be "
                  "connected to (an orthographic camera's rays are one direction per film point); use path, bdpt or sppm");
    chooser_ = std::make_unique<LightChooser>(rc.scene(), uniform_lights_);
    ctx_ = std::make_unique<Context>(Context{rc.scene(), *chooser_, config_});
  }

  // Spectral renders: the light subpath carries values at the sample's wavelengths, which the loop
  // turns into RGB as it splats them.
  bool supports_spectral() const override { return true; }

  Rgb sample(const Scene&, const PixelSample& px, Sampler& sampler, SplatSink& splats) override {
    SubpathStorage<0> light_path(config_.max_depth + 1);
    PathSampler ps(sampler, px.pixel, px.index);
    Context ctx = *ctx_;
    ctx.wavelengths = px.wavelengths;
    int nl = light_subpath(ctx, ps, light_path.data());
    for (int s = 1; s <= nl; ++s) {
      Connection c = connect(ctx, light_path.data(), s, &lens_, 1, ps, /*weighted=*/false);
      if (c.splat && !is_black(c.L)) splats.splat(c.p_raster, c.L);
    }
    return Rgb(0.f);
  }

 private:
  Config config_;
  bool uniform_lights_;
  Vertex lens_;
  std::unique_ptr<LightChooser> chooser_;
  std::unique_ptr<Context> ctx_;
};

const ParamSpec kParams[] = {
    {"integer", "maxdepth", "5", "longest path in bounces"},
    {"integer", "rrdepth", "3", "bounces of a light path before Russian roulette may end it"},
    {"string", "lightsampler", "power", "light selection: power or uniform"},
};

Object* create(const CreateContext& ctx) {
  const ParamSet& p = ctx.params;
  bool uniform_lights = false;
  Config config = read_subpath_config(p, &uniform_lights);
  config.store_nee_ratio = false;  // unweighted: no MIS
  return new LightTracingIntegrator(config, uniform_lights);
}

}  // namespace

PENUMBRA_PLUGIN(Integrator, "lighttracing", "light tracing: paths from the lights connected to the camera", kParams,
                create)
