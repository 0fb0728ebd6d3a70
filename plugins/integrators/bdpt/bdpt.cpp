// Integrator "bdpt": bidirectional path tracing (Veach 1997, ch. 10; pbrt-v3's design). Each pixel
// sample traces a camera subpath and a light subpath (light chosen by power, or uniformly) and
// evaluates every strategy (s, t) that gives a path of at most maxdepth bounces:
//   s = 0       the camera subpath hits an emitter (area lights, environment lights);
//   s = 1       next-event estimation with the light's own sample_li();
//   t = 1       the light subpath connects to the lens (camera sample_wi) and splats on the film;
//   s, t >= 2   a shadow ray joins light vertex s-1 and camera vertex t-1.
// The strategies are combined by MIS (balance heuristic by default, as in pbrt-v3 and v4) computed
// from the path's forward and reverse densities (mis.h, subpath.h: formulation and reasons). Delta
// lights and specular lobes are never connected to; environment and distant lights are directions
// whose emitted paths start on a disk covering the scene. Subpaths use Russian roulette after rrdepth
// bounces (kept out of the MIS densities, see subpath.h); set rrdepth above maxdepth for pbrt-v3's
// behaviour (none).
//
// | parameter                | default | meaning                                                |
// |--------------------------|---------|--------------------------------------------------------|
// | integer maxdepth         | 5       | longest path in bounces (pbrt's convention, as "path") |
// | integer rrdepth          | 1       | bounces of a subpath before Russian roulette           |
// | string lightsampler      | power   | light choice: power or uniform                         |
// | string misheuristic      | balance | balance or power (beta = 2); docs/bdpt.md: why balance |
// | bool visualizestrategies | false   | write each strategy's contribution, weighted and not   |
// | bool visualizeweights    | false   | write each strategy's mean MIS weight                  |
// | string visualizeprefix   | bdpt_   | path prefix of those images                            |
// | bool connect             | true    | s, t >= 2 with the sample's own light subpath          |
// | bool nextevent           | true    | s = 1 (next-event estimation)                          |
// | bool lighttrace          | true    | t = 1 (light subpaths splatted through the lens)       |
// | bool hrr                 | false   | hierarchical Russian roulette over a light-vertex cache|
// | float hrrc               | 0       | HRR's C (area x sr); 0: calibrated to hrrconnections   |
// | integer hrrconnections   | 32      | target mean HRR connections per eye vertex             |
// | bool hrrcull             | true    | cull BVH nodes outside the acceptance range            |
// | float hrrmaxalpha        | 0.3     | HRR only at eye lobes with roughness alpha <= this     |
// | bool probconnect         | false   | probabilistic connections over the same cache          |
// | integer probconnections  | 4       | draws per eye vertex (n_c)                             |
// | integer pcrecords        | 100     | candidate light vertices per cache point               |
// | integer lightpaths       | 0       | light paths per iteration (M); 0: the pixel count      |
//
// With hrr or probconnect, each pass renders one sample per pixel (an iteration): M light subpaths
// are traced first into a cache (path j < pixel count is pixel j's own light subpath, reused), a BVH
// is built over their vertices, and every non-specular camera vertex connects to cached vertices by
// the cached techniques (connect_cached.h) besides its own strategies. All techniques share one MIS;
// switching any of them off leaves the image the same in expectation as long as the others still
// sample every path (emission hits, s = 0, are always on; without nextevent and lighttrace, paths
// from delta lights are lost).
//
// Spectral renders (docs/spectral.md): a sample's subpaths and connections carry values at its
// wavelengths. With a light-vertex cache the loop gives every sample of an iteration the same
// wavelengths (wavelengths_per_pass()), at which the cache's light subpaths are traced too.
//
// The strategy images are <prefix>d<depth>_s<s>_t<t>.exr (weighted: they sum to the image when the
// filter is a box), ..._unweighted.exr (each alone estimates the depth-d image, where the strategy can
// sample it) and ..._weight.exr (mean weight over the samples the strategy found light with).
#include "connect_cached.h"
#include "subpath.h"

#include <penumbra/image.h>
#include <penumbra/integrator.h>
#include <penumbra/plugin.h>
#include <penumbra/rng.h>

#include <fmt/core.h>
#include <tbb/enumerable_thread_specific.h>

#include <map>

namespace {

using namespace penumbra;
using namespace penumbra::bdpt;

// One strategy's contribution to one pixel sample, for the strategy images.
struct TaggedSplat {
  int tag;
  Vec2 p_raster;
  Rgb weighted, unweighted;
  float weight;
};

// Per-strategy images for visualizestrategies / visualizeweights: one set per thread (double sums),
// added together at the end. A debugging aid: its last bits may depend on the thread count.
class StrategyImages {
 public:
  StrategyImages(Point2i res, int max_depth) : res_(res), max_depth_(max_depth) {}
  static int tag(int s, int t, int max_depth) { return t * (max_depth + 3) + s; }

  void add(const TaggedSplat& ts) {
    int x = static_cast<int>(std::floor(ts.p_raster.x)), y = static_cast<int>(std::floor(ts.p_raster.y));
    if (x < 0 || y < 0 || x >= res_.x || y >= res_.y) return;
    Buffers& b = buffers_[ts.tag];
    if (b.weighted.empty()) {
      size_t n = static_cast<size_t>(res_.x) * res_.y;
      b.weighted.assign(3 * n, 0.0);
      b.unweighted.assign(3 * n, 0.0);
      b.weight.assign(n, 0.0);
      b.count.assign(n, 0.0);
    }
    size_t i = static_cast<size_t>(y) * res_.x + x;
    for (int c = 0; c < 3; ++c) {
      b.weighted[3 * i + c] += ts.weighted[c];
      b.unweighted[3 * i + c] += ts.unweighted[c];
    }
    b.weight[i] += ts.weight;
    b.count[i] += 1.0;
  }

  void merge(const StrategyImages& other) {
    for (const auto& [tag, b] : other.buffers_) {
      Buffers& mine = buffers_[tag];
      if (mine.weighted.empty()) {
        mine = b;
        continue;
      }
      for (size_t i = 0; i < b.weighted.size(); ++i) mine.weighted[i] += b.weighted[i], mine.unweighted[i] += b.unweighted[i];
      for (size_t i = 0; i < b.weight.size(); ++i) mine.weight[i] += b.weight[i], mine.count[i] += b.count[i];
    }
  }

  void write(const std::string& prefix, int spp, bool strategies, bool weights) const {
    for (int t = 1; t <= max_depth_ + 2; ++t)
      for (int s = 0; s <= max_depth_ + 1; ++s) {
        int depth = s + t - 2;
        if ((s == 1 && t == 1) || depth < 0 || depth > max_depth_) continue;
        auto it = buffers_.find(tag(s, t, max_depth_));
        std::string name = fmt::format("{}d{:02}_s{:02}_t{:02}", prefix, depth, s, t);
        const Buffers* b = it == buffers_.end() ? nullptr : &it->second;
        if (strategies) {
          write_image(name + ".exr", image(b ? &b->weighted : nullptr, 1.0 / spp));
          write_image(name + "_unweighted.exr", image(b ? &b->unweighted : nullptr, 1.0 / spp));
        }
        if (weights) {
          ImageRgb img = image(nullptr, 0.0);
          if (b)
            for (size_t i = 0; i < b->weight.size(); ++i)
              for (int c = 0; c < 3; ++c)
                img.pixels[3 * i + c] = b->count[i] > 0 ? static_cast<float>(b->weight[i] / b->count[i]) : 0.f;
          write_image(name + "_weight.exr", img);
        }
      }
  }

 private:
  struct Buffers {
    std::vector<double> weighted, unweighted, weight, count;
  };
  ImageRgb image(const std::vector<double>* rgb, double scale) const {
    ImageRgb img;
    img.width = res_.x;
    img.height = res_.y;
    img.pixels.assign(3 * static_cast<size_t>(res_.x) * res_.y, 0.f);
    if (rgb)
      for (size_t i = 0; i < rgb->size(); ++i) img.pixels[i] = static_cast<float>((*rgb)[i] * scale);
    return img;
  }
  Point2i res_;
  int max_depth_;
  std::map<int, Buffers> buffers_;
};

// The cached techniques' own random streams follow the render's seed: the SDK does not hand the seed
// to integrators, so it is read through the sampler (a few values at a sample index never rendered).
uint64_t seed_of(const Sampler& proto) {
  std::unique_ptr<Sampler> sampler = proto.clone();
  sampler->start_pixel_sample(Point2i(0, 0), 0xfffffff0u, 0);
  uint64_t h = 0x5eed;
  for (int i = 0; i < 4; ++i) h = hash_ints(h, static_cast<uint64_t>(sampler->get_1d() * 0x1p32f));
  return h;
}

class BdptIntegrator final : public SampleIntegrator {
 public:
  BdptIntegrator(Config config, bool uniform_lights, bool vis_strategies, bool vis_weights, std::string prefix,
                 TechniqueSet techniques, CachedOptions cached)
      : config_(config), uniform_lights_(uniform_lights), vis_strategies_(vis_strategies),
        vis_weights_(vis_weights), prefix_(std::move(prefix)), techniques_(techniques), cached_options_(cached) {}

  void begin_render(RenderContext& rc) override {
    const Scene& scene = rc.scene();
    res_ = rc.film().resolution();
    chooser_ = std::make_unique<LightChooser>(scene, uniform_lights_);
    active_ = techniques_;
    if (cached_options_.hrr || cached_options_.probconnect) {
      CachedOptions options = cached_options_;
      options.seed = seed_of(rc.sampler());
      cached_ = std::make_unique<CachedConnector>(options, config_.max_depth);
      active_.cached = cached_.get();
    }
    ctx_ = std::make_unique<Context>(Context{scene, *chooser_, config_, active_.all_regular() ? nullptr : &active_});
    visualize_ = vis_strategies_ || vis_weights_;
    if (visualize_)
      images_ = std::make_unique<tbb::enumerable_thread_specific<StrategyImages>>(
          [this] { return StrategyImages(res_, config_.max_depth); });
    if (cached_) {
      // The pilot stops when the time budget is spent; the render then takes no sample.
      bool whole = cached_->prepare(*ctx_, rc.sampler(), res_, [&rc] { return rc.should_stop(); });
      // HRR alone where no eye vertex may use it would only cost time (a cache, a BVH and one sample
      // per pass): render plain bdpt instead, which samples the same paths.
      if (whole && cached_options_.hrr && !cached_options_.probconnect && !cached_->hrr_eligible()) {
        warning({}, fmt::format("bdpt: hrr is on, but no eye vertex of the pilot has a non-specular lobe with "
                                "alpha <= hrrmaxalpha ({:g}); rendering without the light-vertex cache",
                                cached_options_.hrr_max_alpha));
        cached_.reset();
        active_.cached = nullptr;
        ctx_ = std::make_unique<Context>(Context{scene, *chooser_, config_, active_.all_regular() ? nullptr : &active_});
        built_.push_back("hrr_pilot");
      }
    }
  }

  // With a light-vertex cache, a pass is one iteration: one sample per pixel over one cache.
  int max_pass_samples() const override { return cached_ ? 1 : 16; }
  bool supports_spectral() const override { return true; }
  bool wavelengths_per_pass() const override { return cached_ != nullptr; }

  void begin_pass(RenderContext& rc, const Pass& pass) override {
    // Cut short when the time budget runs out; the loop then renders no tile of this pass.
    if (cached_) {
      Context pass_ctx = *ctx_;
      pass_ctx.wavelengths = pass.wavelengths;
      cached_->begin_iteration(pass_ctx, rc.sampler(), res_, pass.first_index, [&rc] { return rc.should_stop(); });
    }
  }

  Rgb sample(const Scene& scene, const PixelSample& px, Sampler& sampler, SplatSink& splats) override {
    const int max_depth = config_.max_depth;
    if (!px.ray) return Rgb(0.f);
    // The sample's wavelengths (null in RGB) go with a copy of the context (48 bytes).
    Context ctx = *ctx_;
    ctx.wavelengths = px.wavelengths;
    SubpathStorage<0> camera_path(max_depth + 2);
    SubpathStorage<1> own_light_path(max_depth + 1);
    PathSampler ps(sampler, px.pixel, px.index);
    int nc = camera_subpath(ctx, *px.ray, ps, camera_path.data());
    // The pixel's light subpath: from the iteration's cache when it holds it (the same path).
    size_t j = static_cast<size_t>(px.pixel.y) * res_.x + px.pixel.x;
    const Vertex* light_path = own_light_path.data();
    int nl;
    if (cached_ && j < cached_->cache().path_count()) {
      light_path = cached_->cache().path(j);
      nl = cached_->cache().path_length(j);
    } else {
      nl = light_subpath(ctx, ps, own_light_path.data());
    }
    StrategyImages* images = visualize_ ? &images_->local() : nullptr;
    // Strategies whose connection would end at a vertex that cannot be connected (specular-only, an
    // escaped camera ray) give nothing: skipped here, with the tests connect() would make itself,
    // rather than set up a Connection each. Bit i: vertex i (beyond 64 vertices connect() decides).
    const Vertex* camera = camera_path.data();
    uint64_t camera_ok = 0, light_ok = 0, emitter = 0;
    for (int i = 0; i < std::min(nc, 64); ++i) {
      if (camera[i].kind != VertexKind::Light && camera[i].connectible()) camera_ok |= uint64_t(1) << i;
      if (camera[i].light || camera[i].kind == VertexKind::Light) emitter |= uint64_t(1) << i;
    }
    for (int i = 0; i < std::min(nl, 64); ++i)
      if (light_path[i].connectible()) light_ok |= uint64_t(1) << i;
    auto has = [](uint64_t mask, int i) { return i >= 64 || ((mask >> i) & 1); };
    Rgb L(0.f);
    // s = 1 draws a light point of its own: it runs even when the light subpath is empty (its
    // emission was cut out by an emitter's alpha, or had no density).
    const int s_max = std::max(nl, 1);
    for (int t = 1; t <= nc; ++t)
      for (int s = 0; s <= s_max; ++s) {
        int depth = s + t - 2;
        if ((s == 1 && t == 1) || depth < 0 || depth > max_depth) continue;
        if (s == 0 ? !has(emitter, t - 1)
                   : (t >= 2 && !has(camera_ok, t - 1)) || ((s >= 2 || t == 1) && !has(light_ok, s - 1)))
          continue;
        Connection c = connect(ctx, light_path, s, camera_path.data(), t, ps);
        if (is_black(c.L)) continue;
        if (c.splat)
          splats.splat(c.p_raster, c.weighted);
        else
          L += c.weighted;
        if (images)
          images->add(TaggedSplat{StrategyImages::tag(s, t, max_depth), c.splat ? c.p_raster : px.camera.p_film,
                                  c.weighted, c.L, static_cast<float>(c.weight)});
      }
    if (cached_)
      for (int t = 2; t <= nc; ++t)
        cached_->connect_eye_vertex(ctx, camera_path.data(), t, px.pixel, px.index,
                                    [&](const Connection& c, int) { L += c.weighted; });
    return L;
  }

  void end_render(RenderContext& rc, int spp) override {
    if (visualize_ && spp > 0) {
      StrategyImages all(res_, config_.max_depth);
      for (const StrategyImages& part : *images_) all.merge(part);
      all.write(prefix_, spp, vis_strategies_, vis_weights_);
    }
    if (cached_) {
      statistics_ = cached_->statistics();
      built_.push_back("light_vertex_cache");
      if (cached_options_.hrr) built_.push_back("light_vertex_bvh");
      if (cached_options_.probconnect) built_.push_back("connection_cache_points");
    }
  }

  std::vector<std::string> structures_built() const override { return built_; }
  std::vector<std::pair<std::string, double>> statistics() const override { return statistics_; }

 private:
  Config config_;
  bool uniform_lights_, vis_strategies_, vis_weights_;
  std::string prefix_;
  TechniqueSet techniques_;
  CachedOptions cached_options_;
  // State of one render, set up in begin_render().
  Point2i res_{0};
  std::unique_ptr<LightChooser> chooser_;
  TechniqueSet active_;
  std::unique_ptr<CachedConnector> cached_;
  std::unique_ptr<Context> ctx_;
  bool visualize_ = false;
  std::unique_ptr<tbb::enumerable_thread_specific<StrategyImages>> images_;
  std::vector<std::string> built_;
  std::vector<std::pair<std::string, double>> statistics_;
};

const ParamSpec kParams[] = {
    {"integer", "maxdepth", "5", "longest path in bounces"},
    {"integer", "rrdepth", "1", "bounces of a subpath before Russian roulette may end it"},
    {"string", "lightsampler", "power", "light selection: power or uniform"},
    {"string", "misheuristic", "balance", "MIS heuristic: balance or power"},
    {"bool", "visualizestrategies", "false", "write each strategy's contribution (weighted and unweighted)"},
    {"bool", "visualizeweights", "false", "write each strategy's mean MIS weight"},
    {"string", "visualizeprefix", "bdpt_", "path prefix of the strategy images"},
    {"unsupported", "regularize", "", "path regularisation is not implemented"},
    {"bool", "connect", "true", "connect camera vertices to the sample's own light subpath (s, t >= 2)"},
    {"bool", "nextevent", "true", "next-event estimation (s = 1)"},
    {"bool", "lighttrace", "true", "splat light subpaths through the lens (t = 1)"},
    {"bool", "hrr", "false", "hierarchical Russian roulette connections to a light-vertex cache"},
    {"float", "hrrc", "0", "HRR's C in P = min(C q / d^2, 1); 0: calibrate to hrrconnections"},
    {"integer", "hrrconnections", "32", "target mean HRR connections per eye vertex (when hrrc is 0)"},
    {"bool", "hrrcull", "true", "cull light-vertex BVH nodes outside the acceptance range"},
    {"float", "hrrmaxalpha", "0.3", "HRR only at eye vertices whose lobe roughness alpha is at most this (1: all)"},
    {"bool", "probconnect", "false", "probabilistic connections to the light-vertex cache"},
    {"integer", "probconnections", "4", "probabilistic connections per eye vertex"},
    {"integer", "pcrecords", "100", "candidate light vertices per cache point"},
    {"integer", "lightpaths", "0", "light paths in the cache per iteration; 0: the pixel count"},
};

Object* create(const CreateContext& ctx) {
  const ParamSet& p = ctx.params;
  bool uniform_lights = false;
  Config config = read_subpath_config(p, &uniform_lights);
  std::string h = p.get_string("misheuristic");
  if (h != "power" && h != "balance")
    throw Error(p.loc_of("misheuristic"), "misheuristic '" + h + "' is not supported; available: balance, power");
  config.heuristic = h == "power" ? MisHeuristic::Power : MisHeuristic::Balance;
  TechniqueSet techniques;
  techniques.connect = p.get_bool("connect");
  techniques.nextevent = p.get_bool("nextevent");
  techniques.lighttrace = p.get_bool("lighttrace");
  CachedOptions cached = read_cached_options(p);
  return new BdptIntegrator(config, uniform_lights, p.get_bool("visualizestrategies"), p.get_bool("visualizeweights"),
                            p.get_string("visualizeprefix"), techniques, cached);
}

}  // namespace

PENUMBRA_PLUGIN(Integrator, "bdpt", "bidirectional path tracer with multiple importance sampling of every strategy",
                kParams, create)
