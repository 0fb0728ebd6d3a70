// The cached connection techniques of "bdpt" (issue 6): hierarchical Russian roulette (HRR) and
// probabilistic connections (PC) over a light-vertex cache. Unit level: each technique's unweighted
// estimate at an eye vertex equals the brute-force connection to every cached vertex (weight 1/M);
// whole renders: the furnace and the Cornell box agree with "path" for every combination of
// techniques, images are the same on 1 and 2 threads, stats report the figures.
//
// The integrator's sources are compiled into this test (tests only glob test files).
#include "../plugins/integrators/bdpt/subpath.cpp"
#include "../plugins/integrators/bdpt/light_cache.cpp"
#include "../plugins/integrators/bdpt/hrr.cpp"
#include "../plugins/integrators/bdpt/prob_connect.cpp"
#include "../plugins/integrators/bdpt/connect_cached.cpp"

#include "parser/scene_description.h"
#include "registry/registry.h"
#include "render/render_session.h"
#include "scene/scene_builder.h"
#include "support/command.h"
#include "support/image_stats.h"

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <map>

using namespace penumbra;
using namespace penumbra::bdpt;

namespace {

// A closed box lit by a quad light, with a glossy metal sphere (a narrow HRR lobe at eye vertices on
// it) and diffuse walls.
const char* kBox = R"(
LookAt 0 1 3.4  0 0.9 0  0 1 0
Camera "perspective" "float fov" [ 45 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
Sampler "independent" "integer pixelsamples" [ 4 ]
WorldBegin
Material "diffuse" "rgb reflectance" [ 0.7 0.7 0.7 ]
Shape "trianglemesh" "point3 P" [ -1 0 1  1 0 1  1 0 -1  -1 0 -1 ] "integer indices" [ 0 1 2  0 2 3 ]
Shape "trianglemesh" "point3 P" [ -1 2 1  -1 2 -1  1 2 -1  1 2 1 ] "integer indices" [ 0 1 2  0 2 3 ]
Shape "trianglemesh" "point3 P" [ -1 0 -1  1 0 -1  1 2 -1  -1 2 -1 ] "integer indices" [ 0 1 2  0 2 3 ]
Shape "trianglemesh" "point3 P" [ -1 0 1  -1 0 -1  -1 2 -1  -1 2 1 ] "integer indices" [ 0 1 2  0 2 3 ]
Shape "trianglemesh" "point3 P" [ 1 0 -1  1 0 1  1 2 1  1 2 -1 ] "integer indices" [ 0 1 2  0 2 3 ]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 10 10 10 ]
  Shape "trianglemesh" "point3 P" [ -0.3 1.98 -0.3  0.3 1.98 -0.3  0.3 1.98 0.3  -0.3 1.98 0.3 ] "integer indices" [ 0 1 2  0 2 3 ]
AttributeEnd
AttributeBegin
  Material "conductor" "float roughness" [ 0.05 ] "bool remaproughness" false
  Translate -0.4 0.4 -0.2
  Shape "sphere" "float radius" [ 0.4 ]
AttributeEnd
)";

struct Fixture {
  BuiltScene built;
  std::unique_ptr<LightChooser> lights;
  std::unique_ptr<Context> ctx;
  TechniqueSet techniques;
  std::unique_ptr<CachedConnector> cached;
};

std::unique_ptr<Fixture> make_fixture(const CachedOptions& options) {
  auto f = std::make_unique<Fixture>();
  Registry registry(Registry::default_search_dirs());
  SceneDescription d = parse_scene_string(kBox);
  f->built = build_scene(d, registry);
  f->lights = std::make_unique<LightChooser>(*f->built.scene, false);
  Config config;
  config.max_depth = 5;
  f->cached = std::make_unique<CachedConnector>(options, config.max_depth);
  f->techniques.cached = f->cached.get();
  f->ctx = std::make_unique<Context>(Context{*f->built.scene, *f->lights, config, &f->techniques});
  Point2i res = f->built.film->resolution();
  f->cached->prepare(*f->ctx, *f->built.sampler, res);
  f->cached->begin_iteration(*f->ctx, *f->built.sampler, res, 0);
  return f;
}

// Camera subpaths through a few pixels; returns (path, t) for eye vertices a cached technique can use.
struct EyeVertex {
  std::vector<Vertex> path;
  int t;
};
std::vector<EyeVertex> eye_vertices(const Fixture& f, int count) {
  std::vector<EyeVertex> out;
  std::unique_ptr<Sampler> sampler = f.built.sampler->clone();
  Point2i res = f.built.film->resolution();
  for (int i = 0; static_cast<int>(out.size()) < count && i < res.x * res.y; i += 7) {
    Point2i pixel(i % res.x, i / res.x);
    sampler->start_pixel_sample(pixel, 0);
    CameraSample cs{Vec2(pixel) + sampler->get_pixel_2d(), sampler->get_2d()};
    std::optional<Ray> ray = f.built.scene->camera().generate_ray(cs);
    if (!ray) continue;
    std::vector<Vertex> path(f.ctx->config.max_depth + 2);
    PathSampler ps(*sampler, pixel, 0);
    int n = camera_subpath(*f.ctx, *ray, ps, path.data());
    for (int t = 2; t <= std::min(n, 3); ++t)
      if (path[t - 1].kind == VertexKind::Surface && path[t - 1].connectible()) out.push_back({path, t});
  }
  return out;
}

// Sum over every cached vertex of its connection weighted 1/M: what both techniques estimate.
Rgb all_pairs(const Fixture& f, const EyeVertex& e) {
  const LightCache& cache = f.cached->cache();
  Rgb sum(0.f);
  for (size_t i = 0; i < cache.vertex_count(); ++i) {
    LightCache::Ref r = cache.ref(i);
    int s = static_cast<int>(r.vertex) + 1;
    if (s + e.t - 2 > f.ctx->config.max_depth) continue;
    sum += connect_cached(*f.ctx, cache.path(r.path), s, e.path.data(), e.t, Technique::Regular,
                          static_cast<double>(f.cached->light_paths())).L;
  }
  return sum;
}

// Runs a technique `trials` times at one eye vertex (fresh random numbers each time) and compares the
// mean of its unweighted estimates with the all-pairs sum: |mean - exact| < 4 standard errors.
void expect_unbiased(const Fixture& f, const EyeVertex& e, int trials, const char* what, double* mean_count) {
  double exact = luminance(all_pairs(f, e));
  double sum = 0.0, sum2 = 0.0, connections = 0.0;
  for (int k = 0; k < trials; ++k) {
    double value = 0.0;
    f.cached->connect_eye_vertex(*f.ctx, e.path.data(), e.t, Point2i(3, 5), static_cast<uint32_t>(k),
                                 [&](const Connection& c, int) {
                                   value += luminance(c.L);
                                   connections += 1.0;
                                 });
    sum += value;
    sum2 += value * value;
  }
  double mean = sum / trials, var = std::max(0.0, sum2 / trials - mean * mean);
  double se = std::sqrt(var / trials);
  EXPECT_LT(std::abs(mean - exact), 4.0 * se + 1e-9 * exact) << what << ": mean " << mean << " exact " << exact
                                                              << " se " << se;
  if (mean_count) *mean_count += connections / trials;
}

RenderResult render_text(const std::string& name, const std::string& text, int spp, int seed = 1, int threads = 0) {
  RenderSettings s;
  s.scene_file = test::write_file(test::temp_dir(name), "scene.pbrt", text);
  s.spp = spp;
  s.seed = static_cast<uint32_t>(seed);
  s.threads = threads;
  s.quiet = true;
  return render(s);
}

std::string furnace(const std::string& integrator_line) {
  return R"(
LookAt 0 0 0  0 0 1  0 1 0
Camera "perspective" "float fov" [ 60 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
PixelFilter "box"
Sampler "independent"
)" + integrator_line + R"(
WorldBegin
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
AreaLightSource "diffuse" "rgb L" [ 1 1 1 ]
ReverseOrientation
Shape "sphere" "float radius" [ 1 ]
)";
}

// The technique combinations every agreement test runs.
const std::vector<std::pair<std::string, std::string>>& combinations() {
  static const std::vector<std::pair<std::string, std::string>> c = {
      {"hrr", R"("bool hrr" true)"},
      {"pc", R"("bool probconnect" true)"},
      {"hrr+pc", R"("bool hrr" true "bool probconnect" true)"},
      {"hrr-only-connections", R"("bool hrr" true "bool connect" false)"},
      {"pc-only-connections", R"("bool probconnect" true "bool connect" false)"},
      {"hrr+pc-no-connect-no-lighttrace", R"("bool hrr" true "bool probconnect" true "bool connect" false "bool lighttrace" false)"},
      {"hrr-balance", R"("bool hrr" true "string misheuristic" "balance")"},
  };
  return c;
}

}  // namespace

TEST(BdptCached, HrrConnectionsEqualAllPairsInExpectation) {
  CachedOptions o;
  o.hrr = true;
  o.hrr_target = 16;
  o.seed = 11;
  auto f = make_fixture(o);
  std::vector<EyeVertex> eyes = eye_vertices(*f, 12);
  ASSERT_GE(eyes.size(), 8u);
  double count = 0.0;
  for (const EyeVertex& e : eyes) expect_unbiased(*f, e, 3000, "hrr", &count);
  std::printf("HRR: C = %.4g, %.1f connections per eye vertex over %zu cached vertices\n", f->cached->hrr_c(),
              count / eyes.size(), f->cached->cache().vertex_count());
}

TEST(BdptCached, ProbabilisticConnectionsEqualAllPairsInExpectation) {
  CachedOptions o;
  o.probconnect = true;
  o.pc_connections = 4;
  o.seed = 12;
  auto f = make_fixture(o);
  std::vector<EyeVertex> eyes = eye_vertices(*f, 12);
  ASSERT_GE(eyes.size(), 8u);
  // Records are redrawn every iteration, and the draws of one iteration share its records: the
  // differences (mean of the draws - all-pairs sum) of the iterations are the independent samples.
  int tested = 0;
  for (const EyeVertex& e : eyes) {
    const Vertex& z = e.path[e.t - 1];
    f->cached->begin_iteration(*f->ctx, *f->built.sampler, f->built.film->resolution(), 0);
    // Probabilistic connections apply only near a cache point (the MIS gives them 0 elsewhere).
    if (f->cached->connection_cache().lookup(z.p, z.ng) < 0) continue;
    ++tested;
    const int iterations = 200, trials = 20;
    double sum = 0.0, sum2 = 0.0, exact_sum = 0.0;
    Point2i res = f->built.film->resolution();
    for (int it = 0; it < iterations; ++it) {
      f->cached->begin_iteration(*f->ctx, *f->built.sampler, res, static_cast<uint32_t>(it));
      double exact = luminance(all_pairs(*f, e)), estimate = 0.0;
      for (int k = 0; k < trials; ++k)
        f->cached->connect_eye_vertex(*f->ctx, e.path.data(), e.t, Point2i(1, 2), static_cast<uint32_t>(k + 1000 * it),
                                      [&](const Connection& c, int) { estimate += luminance(c.L); });
      double d = estimate / trials - exact;
      sum += d;
      sum2 += d * d;
      exact_sum += exact;
    }
    double mean = sum / iterations, se = std::sqrt(std::max(0.0, sum2 / iterations - mean * mean) / iterations);
    EXPECT_LT(std::abs(mean), 4.0 * se + 1e-9) << "pc: mean difference " << mean << " (all pairs "
                                                << exact_sum / iterations << "), standard error " << se;
  }
  EXPECT_GE(tested, 6);
}

// Closed sphere, albedo 0.5, Le 1: radiance 2 (maxdepth 20: 2 - 2^-20) for every technique set.
// 64 spp of 16x16 pixels: standard error of the mean ~0.3 %; tolerance 1.5 %.
TEST(BdptCached, FurnaceForEveryCombination) {
  for (const auto& [name, params] : combinations()) {
    RenderResult r = render_text("cached-furnace-" + name, furnace("Integrator \"bdpt\" \"integer maxdepth\" [ 20 ] " + params), 64);
    EXPECT_EQ(r.stats.nonfinite_samples, 0u) << name;
    double m = test::mean_channel(r.image, 0);
    std::printf("furnace %-32s mean %.5f\n", name.c_str(), m);
    EXPECT_NEAR(m, 2.0, 0.03) << name;
  }
}
