// The cached connection techniques of "bdpt" (issue 6): hierarchical Russian roulette (HRR) and
// probabilistic connections (PC) over a light-vertex cache. Unit level: each technique's unweighted
// estimate at an eye vertex equals the brute-force connection to every cached vertex (weight 1/M);
// whole renders: the furnace and the Cornell box agree with "path" for every combination of
// techniques, images are the same on 1 and 2 threads, stats report the figures.
//
// The test links the bidirectional library (libs/bidirectional) that the plugins link, so the weights
// and estimates checked are the ones the plugins compute.
#include "subpath.h"
#include "light_cache.h"
#include "hrr.h"
#include "prob_connect.h"
#include "connect_cached.h"

#include "parser/scene_description.h"
#include "registry/registry.h"
#include "render/render_session.h"
#include "scene/scene_builder.h"
#include "support/bundled_scenes.h"
#include "support/command.h"
#include "support/image_stats.h"

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
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
      {"hrr", R"("bool hrr" true "float hrrmaxalpha" 1)"},
      {"pc", R"("bool probconnect" true)"},
      {"hrr+pc", R"("bool hrr" true "float hrrmaxalpha" 1 "bool probconnect" true)"},
      {"hrr-only-connections", R"("bool hrr" true "float hrrmaxalpha" 1 "bool connect" false)"},
      {"pc-only-connections", R"("bool probconnect" true "bool connect" false)"},
      {"hrr+pc-no-connect-no-lighttrace", R"("bool hrr" true "float hrrmaxalpha" 1 "bool probconnect" true "bool connect" false "bool lighttrace" false)"},
      {"hrr-power", R"("bool hrr" true "float hrrmaxalpha" 1 "string misheuristic" "power")"},
      {"hrr+pc-no-nextevent", R"("bool hrr" true "float hrrmaxalpha" 1 "bool probconnect" true "bool nextevent" false)"},
      {"hrr-glossy-only", R"("bool hrr" true "float hrrmaxalpha" 0.3)"},
  };
  return c;
}

}  // namespace

TEST(BdptCached, HrrConnectionsEqualAllPairsInExpectation) {
  CachedOptions o;
  o.hrr = true;
  o.hrr_max_alpha = 1.0;  // every eye vertex of the diffuse box
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

// Closed sphere, albedo 0.5, Le 1: radiance Le sum_{k<=10} 0.5^k = 1.99902 for every technique set
// (9 sets: each cached technique alone and together, with regular connections, next-event estimation
// or light tracing switched off, balance heuristic, HRR at glossy vertices only).
// 32 spp of 16x16 pixels: standard error of the mean ~0.4 %; tolerance 1.5 %.
TEST(BdptCached, FurnaceForEveryCombination) {
  for (const auto& [name, params] : combinations()) {
    RenderResult r = render_text("cached-furnace-" + name, furnace("Integrator \"bdpt\" \"integer maxdepth\" [ 10 ] \"integer hrrconnections\" [ 16 ] " + params), 32);
    EXPECT_EQ(r.stats.nonfinite_samples, 0u) << name;
    double m = test::mean_channel(r.image, 0);
    std::printf("furnace %-32s mean %.5f\n", name.c_str(), m);
    EXPECT_NEAR(m, 1.99902, 0.03) << name;
  }
}

namespace {

// The Cornell box with a box filter (splats land in one pixel) and the given Integrator line.
std::string cornell_box(const std::string& name, const std::string& integrator_line) {
  return test::cornell_box_copy("cached-cornell-" + name, integrator_line, true);
}

RenderResult render_file(const std::string& file, int spp, int seed, int threads = 0) {
  RenderSettings s;
  s.scene_file = file;
  s.spp = spp;
  s.resolution = std::make_pair(32, 32);
  s.seed = static_cast<uint32_t>(seed);
  s.threads = threads;
  s.quiet = true;
  return render(s);
}

double region_mean(const ImageRgb& img, int y0) {
  double sum = 0.0;
  for (int y = y0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < 3; ++c) sum += img.pixels[3 * (static_cast<size_t>(y) * img.width + x) + c];
  return sum / (3.0 * img.width * (img.height - y0));
}

}  // namespace

namespace {

// Mean and standard error of the per-pixel difference a - b (channels averaged) over rows y0.. of
// the pixels of block (bx, by) of 8x8 (bx < 0: the whole region).
struct Difference {
  double mean = 0.0, standard_error = 0.0;
};
Difference difference(const ImageRgb& a, const ImageRgb& b, int y0, int bx = -1, int by = -1) {
  double sum = 0.0, sum2 = 0.0;
  int n = 0;
  for (int y = std::max(y0, by < 0 ? 0 : by * 8); y < (by < 0 ? a.height : (by + 1) * 8); ++y)
    for (int x = bx < 0 ? 0 : bx * 8; x < (bx < 0 ? a.width : (bx + 1) * 8); ++x) {
      double d = 0.0;
      for (int c = 0; c < 3; ++c) {
        size_t i = 3 * (static_cast<size_t>(y) * a.width + x) + c;
        d += (a.pixels[i] - b.pixels[i]) / 3.0;
      }
      sum += d;
      sum2 += d * d;
      ++n;
    }
  Difference r;
  if (n < 2) return r;
  r.mean = sum / n;
  r.standard_error = std::sqrt(std::max(0.0, (sum2 - n * r.mean * r.mean) / (n - 1)) / n);
  return r;
}

}  // namespace

// Cornell box, 32x32, rows 6-31 (below the light): path at 1024 spp against bdpt with the cached
// techniques at 120 spp (360 without next-event estimation, whose noise is 1.7x higher: at 48 spp 4
// standard errors were 1.1 % and 1.9 % of the mean, too wide to see a 1 % bias; 96 and 288 sufficed
// until bdpt's Russian roulette started at the first bounce, whose shorter paths are noisier per
// sample and cheaper). The tolerances come from the noise of the renders compared, measured at the
// spp rendered: the standard error of the mean per-pixel difference (pixels are independent but for
// light tracing's splats). The region mean and every 4x4 block must agree within 4 standard errors,
// and the region's 4 standard errors must be below 1 % of its mean, so a 1 % bias would fail.
TEST(BdptCached, CornellBoxAgreesWithPathForEveryCombination) {
  RenderResult path = render_file(cornell_box("path", "Integrator \"path\" \"integer maxdepth\" [ 8 ]"), 1024, 1);
  double reference = region_mean(path.image, 6);
  for (const auto& [name, params] : combinations()) {
    std::string line = "Integrator \"bdpt\" \"integer maxdepth\" [ 8 ] \"integer hrrconnections\" [ 8 ] " + params;
    int spp = name.find("no-nextevent") != std::string::npos ? 360 : 120;
    RenderResult r = render_file(cornell_box(name, line), spp, 2);
    EXPECT_EQ(r.stats.nonfinite_samples, 0u) << name;
    Difference whole = difference(r.image, path.image, 6);
    double worst_z = 0.0;
    for (int by = 0; by < 4; ++by)
      for (int bx = 0; bx < 4; ++bx) {
        Difference d = difference(r.image, path.image, 6, bx, by);
        if (d.standard_error > 0.0) worst_z = std::max(worst_z, std::abs(d.mean) / d.standard_error);
      }
    std::printf("cornell %-32s mean %+.3f %% of path's (4 standard errors %.3f %%), worst block %.2f standard errors, %.2f s\n",
                name.c_str(), 100 * whole.mean / reference, 400 * whole.standard_error / reference, worst_z,
                r.stats.seconds);
    EXPECT_LT(std::abs(whole.mean), 4.0 * whole.standard_error) << name;
    EXPECT_LT(4.0 * whole.standard_error, 0.01 * reference) << name << ": a 1 % bias would pass";
    EXPECT_LT(worst_z, 4.0) << name;
  }
}

// One iteration's cache, BVH, records and traversals do not depend on the thread count.
TEST(BdptCached, ImagesAreBitIdenticalOnOneAndTwoThreads) {
  std::string file = cornell_box("threads", "Integrator \"bdpt\" \"integer maxdepth\" [ 5 ] \"bool hrr\" true \"float hrrmaxalpha\" 1 "
                                            "\"bool probconnect\" true \"integer hrrconnections\" [ 8 ]");
  RenderResult one = render_file(file, 4, 3, 1), two = render_file(file, 4, 3, 2);
  ASSERT_EQ(one.image.pixels.size(), two.image.pixels.size());
  EXPECT_EQ(0, std::memcmp(one.image.pixels.data(), two.image.pixels.data(), one.image.pixels.size() * sizeof(float)));
}

// The render stats carry the figures the benchmark reports, and the structures built are named.
TEST(BdptCached, StatsReportConnectionsAndBvhFigures) {
  std::string file = cornell_box("stats", "Integrator \"bdpt\" \"integer maxdepth\" [ 5 ] \"bool hrr\" true \"float hrrmaxalpha\" 1 "
                                          "\"bool probconnect\" true \"integer hrrconnections\" [ 8 ]");
  RenderResult r = render_file(file, 2, 1);
  std::map<std::string, double> stats(r.stats.integrator_stats.begin(), r.stats.integrator_stats.end());
  for (const char* key : {"hrr_c", "hrr_connections_per_eye_vertex", "light_vertex_bvh_build_seconds",
                          "light_vertex_bvh_bytes_per_vertex", "light_vertices_per_iteration",
                          "pc_connections_per_eye_vertex", "pc_cache_points"})
    EXPECT_TRUE(stats.count(key)) << key;
  EXPECT_EQ(stats["light_paths_per_iteration"], 32.0 * 32.0);
  // Calibrated to 8 connections per eye vertex on the pilot: the render's mean is of that order.
  EXPECT_GT(stats["hrr_connections_per_eye_vertex"], 4.0);
  EXPECT_LT(stats["hrr_connections_per_eye_vertex"], 16.0);
  // probconnections (4) draws at every eye vertex that has a cache point, none elsewhere: at most 4,
  // and on the closed box the pilot's cache points cover the visible surfaces, so at least 90 % of
  // the eye vertices find one.
  std::printf("pc connections per eye vertex %.4f\n", stats["pc_connections_per_eye_vertex"]);
  EXPECT_LE(stats["pc_connections_per_eye_vertex"], 4.0);
  EXPECT_GE(stats["pc_connections_per_eye_vertex"], 0.9 * 4.0);
  auto has = [&](const char* s) {
    return std::find(r.stats.structures_built.begin(), r.stats.structures_built.end(), s) != r.stats.structures_built.end();
  };
  EXPECT_TRUE(has("light_vertex_bvh"));
  EXPECT_TRUE(has("light_vertex_cache"));
  RenderResult plain = render_file(cornell_box("stats-plain", "Integrator \"bdpt\""), 1, 1);
  EXPECT_TRUE(plain.stats.integrator_stats.empty());
  EXPECT_EQ(std::count(plain.stats.structures_built.begin(), plain.stats.structures_built.end(), "light_vertex_bvh"), 0);
}

// Every bundled scene, rendered with both cached techniques on (and with HRR alone at glossy eye
// vertices only): no NaN, no Inf, no discarded sample.
TEST(BdptCached, NoNonFiniteValuesOnBundledScenes) {
  std::vector<std::string> files = test::bundled_scene_files();
  ASSERT_GE(files.size(), 6u);
  const std::vector<std::vector<ParamOverride>> settings = {
      {{"hrr", "true", "test"}, {"hrrmaxalpha", "1", "test"}, {"probconnect", "true", "test"}, {"hrrconnections", "8", "test"}},
      {{"hrr", "true", "test"}, {"hrrmaxalpha", "0.3", "test"}, {"connect", "false", "test"}},
  };
  for (const std::string& file : files)
    for (const auto& params : settings) {
      RenderSettings s;
      s.scene_file = file;
      s.integrator = "bdpt";
      s.integrator_params = params;
      s.spp = 2;
      s.resolution = std::make_pair(24, 24);
      s.seed = 1;
      s.quiet = true;
      RenderResult r = render(s);
      EXPECT_EQ(r.stats.nonfinite_samples, 0u) << file;
      EXPECT_EQ(test::count_nonfinite(r.image), 0) << file;
      int negative = 0;
      for (float v : r.image.pixels) negative += v < 0.f;
      EXPECT_EQ(negative, 0) << file;
    }
}
