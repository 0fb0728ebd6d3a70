// Stochastic progressive photon mapping: the hashed visible-point grid against brute force, the
// radius/flux update against a hand-computed sequence, photon energy conservation in a closed box,
// and whole renders: convergence to the path tracer on the Cornell box, the furnace's analytic value
// and depth series, determinism, extreme radii and the structures it reports.
#include "../plugins/integrators/sppm/photon_tracer.h"
#include "../plugins/integrators/sppm/visible_point.h"
#include "../plugins/integrators/sppm/visible_point_grid.h"

#include "parser/scene_description.h"
#include "registry/registry.h"
#include "render/render_session.h"
#include "scene/scene_builder.h"
#include "support/bundled_scenes.h"
#include "support/command.h"
#include "support/image_stats.h"

#include <penumbra/rng.h>

#include <gtest/gtest.h>

#include <fmt/core.h>

#include <algorithm>
#include <regex>

using namespace penumbra;
using namespace penumbra::sppm;

namespace {

// relMSE = mean (I - R)^2 / (R^2 + 0.01) over pixels and channels (docs/algorithms.md, "Image error metrics").
double rel_mse(const ImageRgb& img, const ImageRgb& ref) {
  double sum = 0;
  for (size_t i = 0; i < img.pixels.size(); ++i) {
    double d = img.pixels[i] - ref.pixels[i];
    sum += d * d / (ref.pixels[i] * ref.pixels[i] + 0.01);
  }
  return sum / img.pixels.size();
}

RenderResult render_text(const std::string& name, const std::string& text, int threads = 0, int spp = 0,
                         int seed = -1, Point2i res = Point2i(0)) {
  std::string dir = test::temp_dir(name);
  RenderSettings s;
  s.scene_file = test::write_file(dir, "scene.pbrt", text);
  s.quiet = true;
  s.threads = threads;
  if (spp > 0) s.spp = spp;
  if (seed >= 0) s.seed = static_cast<uint32_t>(seed);
  if (res.x > 0) s.resolution = std::make_pair(res.x, res.y);
  return render(s);
}

// The bundled Cornell box with its Integrator line replaced, in a temporary folder (it includes
// unit-cube.pbrt from beside it).
std::string cornell_with_integrator(const std::string& name, const std::string& integrator_line) {
  return test::cornell_box_copy(name, integrator_line);
}

ImageRgb render_cornell(const std::string& scene_file, int spp, uint32_t seed, int threads = 0) {
  RenderSettings s;
  s.scene_file = scene_file;
  s.spp = spp;
  s.seed = seed;
  s.threads = threads;
  s.resolution = std::make_pair(32, 32);
  s.quiet = true;
  RenderResult r = render(s);
  EXPECT_EQ(r.stats.nonfinite_samples, 0u);
  return r.image;
}

// Mean below the top quarter of the image, where the light is: walls, floor and blocks.
double mean_below_light(const ImageRgb& img) {
  double sum = 0;
  int n = 0;
  for (int y = img.height / 4; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x, ++n)
      for (int c = 0; c < 3; ++c) sum += img.pixels[3 * (y * img.width + x) + c];
  return sum / (3.0 * n);
}

std::vector<uint32_t> grid_query(const VisiblePointGrid& grid, const Vec3& q) {
  std::vector<uint32_t> found;
  grid.for_each_within(q, [&](uint32_t i) { found.push_back(i); });
  std::sort(found.begin(), found.end());
  return found;
}

std::vector<uint32_t> brute_force(const std::vector<Vec3>& p, const std::vector<float>& r, const Vec3& q) {
  std::vector<uint32_t> found;
  for (uint32_t i = 0; i < p.size(); ++i) {
    Vec3 d = p[i] - q;
    if (r[i] > 0.f && glm::dot(d, d) <= r[i] * r[i]) found.push_back(i);
  }
  return found;
}

Vec3 random_in_box(Pcg32& rng, Vec3 lo, Vec3 hi) {
  return lo + (hi - lo) * Vec3(rng.next_float(), rng.next_float(), rng.next_float());
}

}  // namespace

// Points straddle the origin (negative cell coordinates in world space), radii vary by 100x, and some
// points are absent (r = 0). Every query returns exactly the brute-force set, without duplicates, both
// at random places and at points placed inside a chosen disk (near its rim, where a missing cell
// would show). A second build over other points reuses the arrays.
TEST(SppmGrid, QueriesReturnExactlyThePointsWithinTheirRadius) {
  Pcg32 rng(1, 2);
  VisiblePointGrid grid;
  for (int round = 0; round < 3; ++round) {
    const int n = 2000;
    std::vector<Vec3> p(n);
    std::vector<float> r(n);
    for (int i = 0; i < n; ++i) {
      p[i] = random_in_box(rng, Vec3(-3.f, -2.f, -5.f), Vec3(2.f, 3.f, -1.f));
      r[i] = rng.next_float() < 0.1f ? 0.f : 0.01f + (round == 2 ? 1.f : 0.2f) * rng.next_float() * rng.next_float();
    }
    grid.build(p, r);
    for (int k = 0; k < 4000; ++k) {
      Vec3 q = random_in_box(rng, Vec3(-3.5f, -2.5f, -5.5f), Vec3(2.5f, 3.5f, -0.5f));
      ASSERT_EQ(grid_query(grid, q), brute_force(p, r, q)) << "round " << round << " query " << k;
    }
    for (int i = 0; i < n; ++i) {
      if (r[i] == 0.f) {
        continue;
      }
      Vec3 dir = glm::normalize(random_in_box(rng, Vec3(-1.f), Vec3(1.f)) + Vec3(1e-6f));
      Vec3 q = p[i] + dir * (r[i] * (0.999f - 0.2f * rng.next_float()));
      std::vector<uint32_t> found = grid_query(grid, q);
      ASSERT_TRUE(std::binary_search(found.begin(), found.end(), static_cast<uint32_t>(i))) << "point " << i;
      ASSERT_EQ(found, brute_force(p, r, q));
    }
  }
}

// A radius far larger than the points' spread gives a handful of cells; a radius far smaller than the spread
// caps the cells per axis; an empty set answers nothing. All stay exact.
TEST(SppmGrid, ExtremeRadiiStayExactAndBounded) {
  Pcg32 rng(3, 4);
  std::vector<Vec3> p(500);
  for (Vec3& x : p) x = random_in_box(rng, Vec3(-1.f), Vec3(1.f));
  VisiblePointGrid grid;

  std::vector<float> huge(p.size(), 1e6f);
  grid.build(p, huge);
  // The box of the disks is about 2r wide and cells are r wide.
  for (int k = 0; k < 3; ++k) EXPECT_LE(grid.resolution()[k], 3);
  EXPECT_EQ(grid_query(grid, Vec3(0.f)).size(), p.size());

  std::vector<Vec3> spread = p;
  spread[0] = Vec3(-1e5f, 0.f, 0.f);
  spread[1] = Vec3(1e5f, 0.f, 0.f);
  std::vector<float> tiny(p.size(), 1e-4f);
  grid.build(spread, tiny);
  EXPECT_LE(grid.resolution().x, VisiblePointGrid::kMaxCellsPerAxis);
  EXPECT_LE(grid.node_count(), 27 * p.size());
  for (size_t i = 0; i < p.size(); ++i) {
    std::vector<uint32_t> found = grid_query(grid, spread[i] + Vec3(0.f, 5e-5f, 0.f));
    ASSERT_EQ(found, brute_force(spread, tiny, spread[i] + Vec3(0.f, 5e-5f, 0.f)));
  }

  std::vector<float> none(p.size(), 0.f);
  grid.build(p, none);
  EXPECT_TRUE(grid_query(grid, Vec3(0.f)).empty());
}

// Hand-computed with alpha = 2/3, r0 = 1:
//   pass 1: M = 3, Phi = 6  -> N = 2, (r'/r)^2 = 2/3, r = sqrt(2/3), tau = 6 * 2/3 = 4
//   pass 2: M = 0           -> unchanged
//   pass 3: M = 6, Phi = 3  -> N = 2 + 4 = 6, (r'/r)^2 = 6/8, r = sqrt(1/2), tau = (4 + 3) * 3/4 = 5.25
// Estimate after 3 iterations of 10 photons with Ld summed to 0.9: 0.9/3 + 5.25 / (30 pi / 2).
TEST(SppmUpdate, RadiusAndFluxFollowTheHandComputedSequence) {
  const double alpha = 2.0 / 3.0;
  PixelStatistics s;
  s.radius = 1.0;
  const double phi1[3] = {6, 6, 6}, zero[3] = {0, 0, 0}, phi3[3] = {3, 0, 1.5};
  update_statistics(s, 3, phi1, alpha);
  EXPECT_NEAR(s.N, 2.0, 1e-12);
  EXPECT_NEAR(s.radius, std::sqrt(2.0 / 3.0), 1e-12);
  EXPECT_NEAR(s.tau[0], 4.0, 1e-12);
  update_statistics(s, 0, zero, alpha);
  EXPECT_NEAR(s.N, 2.0, 1e-12);
  EXPECT_NEAR(s.radius, std::sqrt(2.0 / 3.0), 1e-12);
  update_statistics(s, 6, phi3, alpha);
  EXPECT_NEAR(s.N, 6.0, 1e-12);
  EXPECT_NEAR(s.radius, std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(s.tau[0], 5.25, 1e-12);
  EXPECT_NEAR(s.tau[1], 4.0 * 0.75, 1e-12);
  EXPECT_NEAR(s.tau[2], 5.5 * 0.75, 1e-12);
  for (double& v : s.Ld) v = 0.9;
  Rgb L = pixel_estimate(s, 3, 30);
  EXPECT_NEAR(L[0], 0.3 + 5.25 / (30 * Pi * 0.5), 1e-6);
}

// Deposits are integers: the sum of a set of fluxes does not depend on the order they arrive in.
TEST(SppmUpdate, AccumulatorSumIsIndependentOfOrder) {
  Pcg32 rng(5, 6);
  std::vector<Rgb> v(1000);
  for (Rgb& x : v) x = Rgb(rng.next_float(), 1e-6f * rng.next_float(), 1e3f * rng.next_float());
  double inv_q = 1.0 / photon_quantum(10.0);
  PhotonAccumulator a, b;
  for (const Rgb& x : v) a.add(x, inv_q);
  for (auto it = v.rbegin(); it != v.rend(); ++it) b.add(*it, inv_q);
  double sum = 0;
  for (const Rgb& x : v) sum += x[0];
  for (int c = 0; c < 3; ++c) EXPECT_EQ(a.phi[c].load(), b.phi[c].load());
  EXPECT_NEAR(a.phi[0].load() / inv_q, sum, 1e-9 * sum);
  EXPECT_EQ(a.M.load(), 1000);
}

// A closed box of albedo 1/2 with a light inside: every photon hits a wall, so the flux arriving at
// depth d (photons' beta summed, over the number shot) is the light's power times (1/2)^d. The point
// light (power 4 pi I) checks the emission weight without a cosine; the small sphere light (power
// pi A L, diffuse itself, so it reflects like the walls) checks it with one. Roulette keeps every
// surviving photon's luminance at the power, so the tolerance is binomial: 4 standard deviations of
// the count of photons reaching depth d.
TEST(SppmPhotons, FluxInClosedBoxIsPowerTimesAlbedoSeries) {
  const char* lights[] = {
      R"(LightSource "point" "rgb I" [ 2 2 2 ] "point3 from" [ 0.1 -0.2 0.3 ])",
      R"(AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 3 3 3 ]
  Translate 0.2 0.1 -0.3
  Shape "sphere" "float radius" [ 0.2 ]
AttributeEnd)"};
  for (const char* light : lights) {
    std::string text = fmt::format(R"(
Camera "perspective"
Film "rgb" "integer xresolution" [ 4 ] "integer yresolution" [ 4 ]
WorldBegin
{}
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1  -1 -1 1  1 -1 1  1 1 1  -1 1 1 ]
  "integer indices" [ 0 2 1  0 3 2  4 5 6  4 6 7  0 1 5  0 5 4  3 7 6  3 6 2  0 4 7  0 7 3  1 2 6  1 6 5 ]
)",
                                   light);
    SceneDescription d = parse_scene_string(text);
    Registry registry(Registry::default_search_dirs());
    BuiltScene built = build_scene(d, registry);
    const Scene& scene = *built.scene;
    ASSERT_EQ(scene.lights().size(), 1u);
    double power = luminance(scene.lights()[0]->power());

    const int n = 200000, max_depth = 6;
    std::vector<double> flux(max_depth, 0.0);
    for (int k = 0; k < n; ++k) {
      Pcg32 rng = photon_rng(9, 0, k);
      trace_photon(scene, rng, max_depth, nullptr, [&](const SurfaceInteraction&, const Vec3&, const Rgb& beta, int depth) {
        flux[depth] += luminance(beta);
      });
    }
    for (int depth = 0; depth < max_depth; ++depth) {
      double expected = power * std::pow(0.5, depth);
      double p = std::pow(0.5, depth), sigma = power * std::sqrt(p * (1 - p) / n);
      EXPECT_NEAR(flux[depth] / n, expected, 4 * sigma + 1e-4 * expected) << light << " depth " << depth;
    }
  }
}

// Reference: path, 1024 spp at 32x32 (its own seed). sppm with radius 0.1 (about 1.1 pixel
// footprints), 1024 photons per iteration, separate renders with one seed. Measured relMSE at
// 4/16/64/128 iterations: 0.097, 0.032, 0.010, 0.0062 (path at 128 spp: 0.0060). Asserted: each
// checkpoint below the one before, the last below 0.015, and the mean below the light within 2 % of
// the reference's.
TEST(Sppm, ConvergesToPathTracerOnCornellBox) {
  std::string path_scene = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt";
  ImageRgb ref = render_cornell(path_scene, 1024, 1000);
  std::string sppm_scene = cornell_with_integrator("cornell-sppm", R"(Integrator "sppm" "integer maxdepth" [ 8 ] "float radius" [ 0.1 ])");
  double previous = 1e9;
  ImageRgb last;
  for (int iterations : {4, 16, 64, 128}) {
    last = render_cornell(sppm_scene, iterations, 1);
    EXPECT_EQ(test::count_nonfinite(last), 0);
    double e = rel_mse(last, ref);
    std::printf("sppm %3d iterations: relMSE %.5f\n", iterations, e);
    EXPECT_LT(e, previous) << iterations << " iterations";
    previous = e;
  }
  EXPECT_LT(previous, 0.015);
  EXPECT_NEAR(mean_below_light(last), mean_below_light(ref), 0.02 * mean_below_light(ref));
}

namespace {

// The path integrator test's furnace: the camera inside a sphere of albedo a that emits Le, so
// L = Le sum_{k=0..D} a^k. On a sphere, the cap cut out by a ball of radius r centred on the surface
// has area pi r^2 exactly (Archimedes), and the irradiance is uniform, so the density estimate has no
// bias to speak of even with a wide radius.
std::string sppm_furnace(float albedo, int maxdepth) {
  return fmt::format(R"(
LookAt 0 0 0  0 0 1  0 1 0
Camera "perspective" "float fov" [ 60 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ] "string filename" [ "furnace.exr" ]
PixelFilter "box"
Sampler "independent" "integer pixelsamples" [ 32 ]
Integrator "sppm" "integer maxdepth" [ {} ] "float radius" [ 0.1 ] "integer photonsperiteration" [ 4096 ]
WorldBegin
Material "diffuse" "rgb reflectance" [ {} {} {} ]
AreaLightSource "diffuse" "rgb L" [ 1 1 1 ]
ReverseOrientation
Shape "sphere" "float radius" [ 1 ]
)",
                     maxdepth, albedo, albedo, albedo);
}

}  // namespace

// Depth convention shared with "path": maxdepth D gives exactly sum_{k=0..D} a^k (a = 1/2). In the
// furnace the photon density is uniform, so the density estimate has no bias to add. 8 independent
// seeds of 32 iterations each; the mean of their image means within 4 standard errors (from their
// spread) of the series, and that tolerance tells D from D - 1 and D + 1 (up to D = 5; at 40 the
// next term is 2^-41).
TEST(Sppm, FurnaceMatchesTruncatedSeriesAtEveryDepth) {
  auto series = [](int depth) {
    double sum = 0.0;
    for (int k = 0; k <= depth; ++k) sum += std::pow(0.5, k);
    return sum;
  };
  const int runs = 8;
  for (int depth : {0, 1, 2, 5, 40}) {
    double sum = 0.0, sum2 = 0.0;
    for (int seed = 1; seed <= runs; ++seed) {
      RenderResult r = render_text(fmt::format("sppm-furnace{}", depth), sppm_furnace(0.5f, depth), 0, 32, seed);
      EXPECT_EQ(r.stats.nonfinite_samples, 0u);
      double m = test::mean_channel(r.image, 1);
      sum += m;
      sum2 += m * m;
    }
    double mean = sum / runs, var = std::max(0.0, (sum2 - runs * mean * mean) / (runs - 1));
    double tol = 4.0 * std::sqrt(var / runs) + 1e-6;
    EXPECT_NEAR(mean, series(depth), tol) << "maxdepth " << depth;
    if (depth <= 5) {
      EXPECT_GT(std::abs(mean - series(depth + 1)), tol) << "maxdepth " << depth << " vs " << depth + 1;
      if (depth > 0) {
        EXPECT_GT(std::abs(mean - series(depth - 1)), tol) << "maxdepth " << depth << " vs " << depth - 1;
      }
    }
  }
}

// Same seed: the same image bit for bit, with 1 or 2 threads (photon deposits are integer sums, so
// their order does not matter); another seed changes it.
TEST(Sppm, SameSeedGivesBitIdenticalImagesAcrossThreadCounts) {
  std::string scene = cornell_with_integrator("cornell-det", R"(Integrator "sppm" "integer maxdepth" [ 5 ] "float radius" [ 0.1 ])");
  ImageRgb one = render_cornell(scene, 8, 3, 1);
  ImageRgb two = render_cornell(scene, 8, 3, 2);
  ImageRgb again = render_cornell(scene, 8, 3, 2);
  EXPECT_EQ(one.pixels, two.pixels);
  EXPECT_EQ(two.pixels, again.pixels);
  ImageRgb other = render_cornell(scene, 8, 4, 2);
  EXPECT_NE(two.pixels, other.pixels);
}

// A radius below a pixel's footprint (1e-4 in a 2-unit box) and one far beyond the scene (1e6, capped
// to the diagonal) finish promptly with finite images whose means are in the right range.
TEST(Sppm, ExtremeRadiiFinishWithFiniteImages) {
  std::string path_scene = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt";
  ImageRgb ref = render_cornell(path_scene, 64, 7);
  for (const char* radius : {"0.0001", "1000000"}) {
    std::string scene = cornell_with_integrator(std::string("cornell-r") + radius,
                                                fmt::format(R"(Integrator "sppm" "float radius" [ {} ])", radius));
    RenderSettings s;
    s.scene_file = scene;
    s.spp = 8;
    s.resolution = std::make_pair(32, 32);
    s.quiet = true;
    RenderResult r = render(s);
    EXPECT_EQ(r.stats.nonfinite_samples, 0u) << radius;
    EXPECT_EQ(test::count_nonfinite(r.image), 0) << radius;
    EXPECT_LT(r.stats.seconds, 10.0) << radius;
    double m = mean_below_light(r.image), m_ref = mean_below_light(ref);
    EXPECT_GT(m, 0.5 * m_ref) << radius;
    EXPECT_LT(m, 2.0 * m_ref) << radius;
  }
}

TEST(Sppm, ReportsVisiblePointGridOnlyForSppm) {
  std::string scene = cornell_with_integrator("cornell-structures", R"(Integrator "sppm")");
  RenderSettings s;
  s.scene_file = scene;
  s.spp = 1;
  s.resolution = std::make_pair(8, 8);
  s.quiet = true;
  std::vector<std::string> sppm = render(s).stats.structures_built;
  EXPECT_NE(std::find(sppm.begin(), sppm.end(), "visible_point_grid"), sppm.end());
  s.integrator = "path";
  std::vector<std::string> path = render(s).stats.structures_built;
  EXPECT_EQ(std::find(path.begin(), path.end(), "visible_point_grid"), path.end());
}

// The pbrt-v4 water caustic names "sppm" with its own radius and maxdepth: it renders as written.
TEST(Sppm, PbrtV4WaterCausticRendersUnchanged) {
  RenderSettings s;
  s.scene_file = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/pbrt-v4/water-caustic/scene-v4.pbrt";
  s.spp = 2;
  s.resolution = std::make_pair(32, 32);
  s.quiet = true;
  RenderResult r = render(s);
  EXPECT_EQ(r.stats.integrator, "sppm");
  EXPECT_EQ(r.stats.nonfinite_samples, 0u);
  EXPECT_EQ(test::count_nonfinite(r.image), 0);
  EXPECT_GT(test::mean_channel(r.image, 1), 0.0);
}

namespace {

// Floor, back wall and a red side wall around a corner, lit by one light; maxdepth 4.
std::string corner_scene(const std::string& integrator, const std::string& light) {
  std::string params = integrator == "sppm" ? R"("float radius" [ 0.05 ] "integer photonsperiteration" [ 8192 ])" : "";
  return fmt::format(R"(
LookAt 1.5 1.2 2.5  0 0.3 0  0 1 0
Camera "perspective" "float fov" [ 50 ]
Film "rgb" "integer xresolution" [ 24 ] "integer yresolution" [ 24 ]
PixelFilter "box"
Sampler "independent" "integer pixelsamples" [ 64 ]
Integrator "{}" "integer maxdepth" [ 4 ] {}
WorldBegin
{}
Material "diffuse" "rgb reflectance" [ 0.7 0.7 0.7 ]
Shape "trianglemesh" "point3 P" [ -1 0 1  1 0 1  1 0 -1  -1 0 -1 ] "integer indices" [ 0 1 2 0 2 3 ]
Shape "trianglemesh" "point3 P" [ -1 0 -1  1 0 -1  1 1.5 -1  -1 1.5 -1 ] "integer indices" [ 0 1 2 0 2 3 ]
Material "diffuse" "rgb reflectance" [ 0.7 0.2 0.2 ]
Shape "trianglemesh" "point3 P" [ -1 0 1  -1 0 -1  -1 1.5 -1  -1 1.5 1 ] "integer indices" [ 0 1 2 0 2 3 ]
)",
                     integrator, params, light);
}

}  // namespace

// Photons leave every kind of light (sample_le with its own emission weight): the image mean agrees
// with path's (1024 spp) under a point, spot, distant, uniform environment and spherical area light.
// Measured ratios of the means: 0.994 to 1.003; asserted within 2 % per channel.
TEST(Sppm, AgreesWithPathForEveryLightType) {
  const char* lights[] = {
      R"(LightSource "point" "rgb I" [ 2 2 2 ] "point3 from" [ 0.3 1.2 0.5 ])",
      R"(LightSource "spot" "rgb I" [ 4 4 4 ] "point3 from" [ 0.5 1.5 1 ] "point3 to" [ 0 0 0 ] "float coneangle" [ 30 ])",
      R"(LightSource "distant" "rgb L" [ 2 2 2 ] "point3 from" [ 1 2 1.5 ] "point3 to" [ 0 0 0 ])",
      R"(LightSource "infinite" "rgb L" [ 0.5 0.5 0.5 ])",
      // Out of the camera's view: a few antialiased pixels of an emitter would dominate the mean.
      R"(AttributeBegin AreaLightSource "diffuse" "rgb L" [ 20 20 20 ] Translate 0.8 1.8 1.5
         Shape "sphere" "float radius" [ 0.1 ] AttributeEnd)"};
  int k = 0;
  for (const char* light : lights) {
    ++k;
    RenderResult path = render_text(fmt::format("corner-path{}", k), corner_scene("path", light), 0, 1024, 5);
    RenderResult sppm = render_text(fmt::format("corner-sppm{}", k), corner_scene("sppm", light), 0, 64, 6);
    EXPECT_EQ(sppm.stats.nonfinite_samples, 0u);
    std::printf("light %d: sppm/path mean %.4f\n", k, test::mean_channel(sppm.image, 1) / test::mean_channel(path.image, 1));
    for (int c = 0; c < 3; ++c) {
      double expected = test::mean_channel(path.image, c);
      EXPECT_NEAR(test::mean_channel(sppm.image, c), expected, 0.02 * expected) << light << " channel " << c;
    }
  }
}
