// Shape "bilinearmesh" as a tessellation (scene/bilinear_patches.h): planar patches are the two
// triangles a trianglemesh would give (equal renders), twisted ones have the bilinear surface's area
// and stay within the stated distance of it; uv as pbrt-v4 defines them; located errors.
#include "render/render_session.h"
#include "scene/bilinear_patches.h"
#include "support/command.h"
#include "support/image_stats.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fmt/core.h>

#include <cmath>
#include <random>

using namespace penumbra;
using ::testing::HasSubstr;

namespace {

// The hyperbolic paraboloid z = u v over the unit square.
const std::vector<Vec3> kTwisted = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 1}};

TessellatedPatches tessellate(const std::vector<Vec3>& P, const std::vector<int>& idx = {},
                              const std::vector<Vec2>& uv = {}, const std::vector<Vec3>& N = {}) {
  return tessellate_bilinear_patches(P, idx, uv, N, FileLoc{}, FileLoc{}, FileLoc{}, FileLoc{});
}

glm::dvec3 patch(const std::vector<Vec3>& c, double u, double v) {
  return (1 - u) * (1 - v) * glm::dvec3(c[0]) + u * (1 - v) * glm::dvec3(c[1]) + (1 - u) * v * glm::dvec3(c[2]) +
         u * v * glm::dvec3(c[3]);
}

double exact_area(const std::vector<Vec3>& c, int steps) {
  glm::dvec3 a = glm::dvec3(c[1]) - glm::dvec3(c[0]), b = glm::dvec3(c[2]) - glm::dvec3(c[0]);
  glm::dvec3 t = glm::dvec3(c[0]) - glm::dvec3(c[1]) - glm::dvec3(c[2]) + glm::dvec3(c[3]);
  double sum = 0.0, h = 1.0 / steps;
  for (int j = 0; j < steps; ++j)
    for (int i = 0; i < steps; ++i) {
      double u = (i + 0.5) * h, v = (j + 0.5) * h;
      sum += glm::length(glm::cross(a + v * t, b + u * t));
    }
  return sum * h * h;
}

double area(const std::vector<Vec3>& P, const std::vector<int>& idx) {
  double s = 0.0;
  for (size_t f = 0; f < idx.size(); f += 3)
    s += 0.5 * glm::length(glm::cross(glm::dvec3(P[idx[f + 1]] - P[idx[f]]), glm::dvec3(P[idx[f + 2]] - P[idx[f]])));
  return s;
}

// Distance from x to the patch: Newton on the closest-point conditions from (u, v).
double distance_to_patch(const std::vector<Vec3>& c, glm::dvec3 x, double u, double v) {
  glm::dvec3 a = glm::dvec3(c[1]) - glm::dvec3(c[0]), b = glm::dvec3(c[2]) - glm::dvec3(c[0]);
  glm::dvec3 t = glm::dvec3(c[0]) - glm::dvec3(c[1]) - glm::dvec3(c[2]) + glm::dvec3(c[3]);
  for (int it = 0; it < 20; ++it) {
    glm::dvec3 f = patch(c, u, v) - x, pu = a + v * t, pv = b + u * t;
    double gu = glm::dot(f, pu), gv = glm::dot(f, pv);
    double huu = glm::dot(pu, pu), hvv = glm::dot(pv, pv), huv = glm::dot(pu, pv) + glm::dot(f, t);
    double det = huu * hvv - huv * huv;
    if (std::abs(det) < 1e-300) break;
    u -= (hvv * gu - huv * gv) / det;
    v -= (huu * gv - huv * gu) / det;
  }
  return glm::length(patch(c, u, v) - x);
}

// Largest distance to the patch of random points on the triangles.
double max_deviation(const std::vector<Vec3>& c, const std::vector<Vec3>& P, const std::vector<Vec2>& uv,
                     const std::vector<int>& idx) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double worst = 0.0;
  for (size_t f = 0; f < idx.size(); f += 3)
    for (int k = 0; k < 20; ++k) {
      double r1 = U(rng), r2 = U(rng);
      if (r1 + r2 > 1) r1 = 1 - r1, r2 = 1 - r2;
      double b0 = 1 - r1 - r2;
      glm::dvec3 x = b0 * glm::dvec3(P[idx[f]]) + r1 * glm::dvec3(P[idx[f + 1]]) + r2 * glm::dvec3(P[idx[f + 2]]);
      glm::dvec2 st = b0 * glm::dvec2(uv[idx[f]]) + r1 * glm::dvec2(uv[idx[f + 1]]) + r2 * glm::dvec2(uv[idx[f + 2]]);
      worst = std::max(worst, distance_to_patch(c, x, st.x, st.y));
    }
  return worst;
}

ImageRgb render_text(const std::string& name, const std::string& text) {
  std::string dir = test::temp_dir(name);
  RenderSettings s;
  s.scene_file = test::write_file(dir, "scene.pbrt", text);
  s.output = dir + "/out.exr";
  s.quiet = true;
  s.seed = 11;
  s.threads = 1;
  return render(s).image;
}

std::string quad_scene(const std::string& shape) {
  return fmt::format(R"(LookAt 0.3 -0.4 4  0 0 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 24 ] "integer yresolution" [ 24 ]
Sampler "independent" "integer pixelsamples" [ 4 ]
WorldBegin
LightSource "point" "point3 from" [ 1 1 3 ] "rgb I" [ 10 10 10 ]
Texture "checks" "spectrum" "checkerboard" "float uscale" [ 2 ] "float vscale" [ 2 ]
  "rgb tex1" [ 0.8 0.2 0.1 ] "rgb tex2" [ 0.1 0.3 0.9 ]
Material "diffuse" "texture reflectance" "checks"
{}
)",
                     shape);
}

}  // namespace

TEST(BilinearPatches, GridSizeFollowsTheTwist) {
  EXPECT_EQ(bilinear_grid_size(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 1, 0), Vec3(2, 1, 0)), 1);  // rectangle
  EXPECT_EQ(bilinear_grid_size(Vec3(0, 0, 0), Vec3(2, 0, 1), Vec3(0, 1, 3), Vec3(2, 1, 4)), 1);  // parallelogram
  int n = bilinear_grid_size(kTwisted[0], kTwisted[1], kTwisted[2], kTwisted[3]);
  EXPECT_GT(n, 1);
  EXPECT_LE(n, 64);
  float tol = kBilinearTolerance * std::sqrt(3.f);
  EXPECT_LE(bilinear_deviation_bound(kTwisted[0], kTwisted[1], kTwisted[2], kTwisted[3], n), tol);
  EXPECT_GT(bilinear_deviation_bound(kTwisted[0], kTwisted[1], kTwisted[2], kTwisted[3], n - 1), tol);  // smallest
}

TEST(BilinearPatches, TwistedPatchHasTheBilinearArea) {
  TessellatedPatches t = tessellate(kTwisted);
  double exact = exact_area(kTwisted, 2000);
  EXPECT_NEAR(exact, 1.2808, 1e-3);  // integral of sqrt(1 + u^2 + v^2) over the unit square
  double a = area(t.P, t.indices);
  EXPECT_LT(std::abs(a - exact) / exact, 1e-3) << a << " " << exact;
  // Negative control: two triangles (no tessellation) are 10 % off.
  EXPECT_GT(std::abs(area(kTwisted, {0, 1, 3, 0, 3, 2}) - exact) / exact, 0.05);
}

TEST(BilinearPatches, PointsStayWithinTheStatedDeviation) {
  TessellatedPatches t = tessellate(kTwisted);
  int n = bilinear_grid_size(kTwisted[0], kTwisted[1], kTwisted[2], kTwisted[3]);
  double bound = bilinear_deviation_bound(kTwisted[0], kTwisted[1], kTwisted[2], kTwisted[3], n);
  double dev = max_deviation(kTwisted, t.P, t.uv, t.indices);
  EXPECT_LE(dev, bound * 1.0001 + 1e-6) << dev << " " << bound;
  EXPECT_GT(dev, 0.1 * bound);  // the bound is not loose by orders of magnitude
  RecordProperty("deviation", std::to_string(dev) + " of bound " + std::to_string(bound));
  // Negative control: the two-triangle version strays past that bound.
  std::vector<Vec2> uv = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
  EXPECT_GT(max_deviation(kTwisted, kTwisted, uv, {0, 1, 3, 0, 3, 2}), 10 * bound);
}

TEST(BilinearPatches, UvAtCornersAsPbrtDefines) {
  for (bool given : {false, true}) {
    std::vector<Vec2> uv = {{0.5f, 0.5f}, {0.7f, 0.5f}, {0.5f, 0.9f}, {0.8f, 1.f}};
    TessellatedPatches t = tessellate(kTwisted, {0, 1, 2, 3}, given ? uv : std::vector<Vec2>{});
    if (!given) uv = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
    int found = 0;
    for (size_t i = 0; i < t.P.size(); ++i)
      for (int k = 0; k < 4; ++k)
        if (t.P[i] == kTwisted[k]) {
          EXPECT_EQ(t.uv[i], uv[k]) << k;
          ++found;
        }
    EXPECT_EQ(found, 4);
    // In between: grid vertex (i, j) is the patch point at (u, v) = (i, j) / n with the corners'
    // uv interpolated bilinearly there.
    int n = bilinear_grid_size(kTwisted[0], kTwisted[1], kTwisted[2], kTwisted[3]);
    ASSERT_EQ(t.P.size(), size_t((n + 1) * (n + 1)));
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        double u = double(i) / n, v = double(j) / n;
        size_t k = size_t(j * (n + 1) + i);
        EXPECT_LT(glm::length(glm::dvec3(t.P[k]) - patch(kTwisted, u, v)), 1e-6);
        glm::dvec2 expect = (1 - u) * (1 - v) * glm::dvec2(uv[0]) + u * (1 - v) * glm::dvec2(uv[1]) +
                            (1 - u) * v * glm::dvec2(uv[2]) + u * v * glm::dvec2(uv[3]);
        EXPECT_LT(glm::length(glm::dvec2(t.uv[k]) - expect), 1e-6);
      }
  }
  // Negative control: with p10 and p01 swapped, the point at kTwisted[1] is the patch's p01: uv (0, 1).
  TessellatedPatches s = tessellate(kTwisted, {0, 2, 1, 3});
  for (size_t i = 0; i < s.P.size(); ++i)
    if (s.P[i] == kTwisted[1]) {
      EXPECT_EQ(s.uv[i], Vec2(0, 1));
    }
}

TEST(BilinearPatches, NormalsAreInterpolated) {
  std::vector<Vec3> N = {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  TessellatedPatches t = tessellate(kTwisted, {}, {}, N);
  ASSERT_EQ(t.N.size(), t.P.size());
  EXPECT_EQ(t.N.front(), N[0]);
  EXPECT_EQ(t.N.back(), N[3]);
  EXPECT_TRUE(tessellate(kTwisted).N.empty());  // none given, none made up
}

TEST(BilinearPatches, PlanarQuadRendersLikeTwoTriangles) {
  std::string P = "\"point3 P\" [ -1 -1 0  1 -1 0  -1 1 0  1 1 0 ]";
  ImageRgb patch_img = render_text("bilinear-planar", quad_scene("Shape \"bilinearmesh\" " + P + " \"integer indices\" [ 0 1 2 3 ]"));
  ImageRgb tri_img = render_text("bilinear-tris", quad_scene("Shape \"trianglemesh\" " + P +
                                                            " \"integer indices\" [ 0 1 3  0 3 2 ] \"point2 uv\" [ 0 0  1 0  0 1  1 1 ]"));
  ASSERT_EQ(patch_img.pixels.size(), tri_img.pixels.size());
  double mean = 0.0;
  for (float v : patch_img.pixels) mean += v;
  EXPECT_GT(mean, 0.0);
  EXPECT_EQ(patch_img.pixels, tri_img.pixels);
  // Negative control: the triangles with u mirrored show the checks mirrored.
  ImageRgb mirrored = render_text("bilinear-mirrored", quad_scene("Shape \"trianglemesh\" " + P +
                                                                 " \"integer indices\" [ 0 1 3  0 3 2 ] \"point2 uv\" [ 1 0  0 0  1 1  0 1 ]"));
  EXPECT_NE(patch_img.pixels, mirrored.pixels);
}

TEST(BilinearPatches, BadInputIsLocated) {
  std::string dir = test::temp_dir("bilinear-bad");
  auto run = [&](const std::string& name, const std::string& shape) {
    std::string file = test::write_file(dir, name + ".pbrt", quad_scene(shape));
    return test::run_penumbra({"render", file, "-o", dir + "/" + name + ".exr", "--spp", "1", "-q"});
  };
  std::string P = "\"point3 P\" [ -1 -1 0  1 -1 0  -1 1 0  1 1 0.5 ]";
  auto r = run("count", "Shape \"bilinearmesh\" " + P + " \"integer indices\" [ 0 1 2 3 0 ]");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("count.pbrt:10:"));
  EXPECT_THAT(r.err, HasSubstr("\"indices\" has 5 values, not a multiple of 4"));
  r = run("range", "Shape \"bilinearmesh\" " + P + " \"integer indices\" [ 0 1 2 4 ]");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("range.pbrt:10:"));
  EXPECT_THAT(r.err, HasSubstr("index 3 (value 4) is out of range: the mesh has 4 vertices"));
  r = run("uv", "Shape \"bilinearmesh\" " + P + " \"point2 uv\" [ 0 0  1 1 ]");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("\"uv\" has 2 values for 4 vertices"));
  // Negative control: the same patch with good indices (and none: one patch of four points) renders.
  EXPECT_EQ(run("ok", "Shape \"bilinearmesh\" " + P + " \"integer indices\" [ 0 1 2 3 ]").exit_code, 0);
  EXPECT_EQ(run("one", "Shape \"bilinearmesh\" " + P).exit_code, 0);
}

// pbrt-v4 (mmp/pbrt-v4 5f7a606) rendered this scene with `pbrt --nthreads 1 --spp 256 --seed 1`:
// mean RGB 0.224578 0.224524 0.224546 (its pixels move more between two seeds than between it and Penumbra).
const char* kPbrtBilinearScene = R"(LookAt 0.5 -2 3  0 0 0  0 0 1
Camera "perspective" "float fov" [ 45 ]
Film "rgb" "integer xresolution" [ 64 ] "integer yresolution" [ 64 ] "string filename" "bil.exr"
Sampler "independent"
Integrator "path" "integer maxdepth" [ 5 ]
WorldBegin
LightSource "point" "point3 from" [ 1 -1 3 ] "rgb I" [ 10 10 10 ]
LightSource "infinite" "rgb L" [ 0.2 0.2 0.2 ]
Texture "checks" "spectrum" "checkerboard" "float uscale" [ 4 ] "float vscale" [ 4 ] "rgb tex1" [ 0.8 0.8 0.8 ] "rgb tex2" [ 0.2 0.2 0.2 ]
Material "diffuse" "texture reflectance" "checks"
Shape "bilinearmesh" "point3 P" [ -1 -1 0  1 -1 0  -1 1 0  1 1 1.5  -1 -1 0  -1 1 0  -1.8 -1 -0.5  -1.5 1.2 0.3 ]
  "integer indices" [ 0 1 2 3  6 4 7 5 ]
)";

TEST(BilinearPatches, MeanMatchesPbrtV4) {
  std::string dir = test::temp_dir("bilinearpatches-pbrt");
  std::string file = test::write_file(dir, "scene.pbrt", kPbrtBilinearScene);
  auto r = test::run_penumbra({"render", file, "-o", dir + "/out.exr", "--spp", "128", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ImageRgb img = read_image(dir + "/out.exr");
  const double pbrt[3] = {0.224578, 0.224524, 0.224546};
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(test::mean_channel(img, c) / pbrt[c], 1.0, 0.01) << c;
  // Negative control: each patch as its two corner triangles (same uv) is 2 % off.
  std::string flat = kPbrtBilinearScene;
  auto replace = [&](const std::string& from, const std::string& to) {
    size_t at = flat.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    flat.replace(at, from.size(), to);
  };
  replace("Shape \"bilinearmesh\"", "Shape \"trianglemesh\" \"point2 uv\" [ 0 0  1 0  0 1  1 1  1 0  1 1  0 0  0 1 ]");
  replace("[ 0 1 2 3  6 4 7 5 ]", "[ 0 1 3  0 3 2  6 4 5  6 5 7 ]");
  file = test::write_file(dir, "flat.pbrt", flat);
  r = test::run_penumbra({"render", file, "-o", dir + "/flat.exr", "--spp", "128", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GT(std::abs(test::mean_channel(read_image(dir + "/flat.exr"), 0) / pbrt[0] - 1.0), 0.015);
}
