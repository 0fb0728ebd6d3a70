// Shape "loopsubdiv": Loop subdivision to the limit surface (scene/loop_subdivision.h), checked on
// meshes whose limit is known in part: closed stays closed, planar stays planar, a centrally
// symmetric regular vertex is its own limit, the limit of a tetrahedron lies inside it with its
// symmetry, areas converge with the level; and a scene using it renders and fails where it should.
#include "scene/loop_subdivision.h"
#include "support/command.h"
#include "support/image_stats.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fmt/core.h>

#include <cmath>
#include <regex>
#include <map>

using namespace penumbra;
using ::testing::HasSubstr;

namespace {

const std::vector<Vec3> kTetraP = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
// Outward winding (counter-clockwise seen from outside).
const std::vector<int> kTetraIdx = {0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2};

// A cube of side 2 around the origin, two outward triangles per face.
const std::vector<Vec3> kCubeP = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                  {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
const std::vector<int> kCubeIdx = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                   2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 3, 0, 4, 3, 4, 7};

LoopSurface subdivide(const std::vector<Vec3>& P, const std::vector<int>& idx, int levels) {
  return loop_subdivide(P, idx, levels, FileLoc{}, FileLoc{});
}

// Faces per undirected edge.
std::map<std::pair<int, int>, int> edge_uses(const std::vector<int>& idx) {
  std::map<std::pair<int, int>, int> uses;
  for (size_t f = 0; f < idx.size(); f += 3)
    for (int k = 0; k < 3; ++k) {
      int a = idx[f + k], b = idx[f + (k + 1) % 3];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  return uses;
}

bool closed(const std::vector<int>& idx) {
  for (auto& [e, n] : edge_uses(idx))
    if (n != 2) return false;
  return true;
}

double area(const LoopSurface& s) {
  double a = 0.0;
  for (size_t f = 0; f < s.indices.size(); f += 3) {
    glm::dvec3 p0(s.P[s.indices[f]]), p1(s.P[s.indices[f + 1]]), p2(s.P[s.indices[f + 2]]);
    a += 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
  }
  return a;
}

// A (k+1) x (k+1) grid in z = 0 over [0, k]^2, every cell split along the same diagonal, so every
// interior vertex has valence 6 and a centrally symmetric ring; winding faces +z.
void grid(int k, std::vector<Vec3>* P, std::vector<int>* idx) {
  for (int j = 0; j <= k; ++j)
    for (int i = 0; i <= k; ++i) P->push_back(Vec3(float(i), float(j), 0.f));
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) {
      int a = j * (k + 1) + i, b = a + 1, c = a + k + 1, d = c + 1;
      idx->insert(idx->end(), {a, b, d, a, d, c});
    }
}

}  // namespace

TEST(LoopSubdivision, ClosedMeshesStayClosedOpenOnesDoNot) {
  for (int levels = 0; levels <= 4; ++levels) {
    EXPECT_TRUE(closed(subdivide(kTetraP, kTetraIdx, levels).indices)) << levels;
    EXPECT_TRUE(closed(subdivide(kCubeP, kCubeIdx, levels).indices)) << levels;
  }
  LoopSurface s = subdivide(kTetraP, kTetraIdx, 3);
  EXPECT_EQ(s.indices.size(), kTetraIdx.size() * 64);
  EXPECT_EQ(s.P.size(), s.N.size());
  // Negative control: the tetrahedron without one face has a boundary, at every level.
  std::vector<int> open(kTetraIdx.begin(), kTetraIdx.end() - 3);
  EXPECT_FALSE(closed(subdivide(kTetraP, open, 3).indices));
}

TEST(LoopSubdivision, TetrahedronLimitIsInsideTheHullAndSymmetric) {
  LoopSurface s = subdivide(kTetraP, kTetraIdx, 4);
  // The faces' planes: x . n <= 1/sqrt(3) * ... with n the outward unit normal of each face.
  double max_excess = -1e9, max_radius = 0.0;
  glm::dvec3 mean(0.0);
  for (const Vec3& p : s.P) {
    for (size_t f = 0; f < kTetraIdx.size(); f += 3) {
      glm::dvec3 a(kTetraP[kTetraIdx[f]]), b(kTetraP[kTetraIdx[f + 1]]), c(kTetraP[kTetraIdx[f + 2]]);
      glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
      max_excess = std::max(max_excess, glm::dot(glm::dvec3(p) - a, n));
    }
    max_radius = std::max(max_radius, glm::length(glm::dvec3(p)));
    mean += glm::dvec3(p);
  }
  mean /= double(s.P.size());
  EXPECT_LT(max_excess, 1e-5);
  EXPECT_LT(glm::length(mean), 1e-5);
  // Even vertices keep their indices: 0..3 are the corners' limit points, on the corners' rays at
  // one distance (the tetrahedral symmetry).
  double r0 = glm::length(glm::dvec3(s.P[0]));
  for (int v = 0; v < 4; ++v) {
    glm::dvec3 p(s.P[v]), dir = glm::normalize(glm::dvec3(kTetraP[v]));
    EXPECT_NEAR(glm::length(p), r0, 1e-5);
    EXPECT_LT(glm::length(glm::cross(p, dir)), 1e-5);
    // Limit normal at a corner points along the corner's direction (outward).
    EXPECT_GT(glm::dot(glm::dvec3(s.N[v]), dir), 0.9999);
  }
  // Negative control: an approximating scheme pulls the corners in (|corner| = sqrt 3).
  EXPECT_LT(max_radius, 0.8 * std::sqrt(3.0));
  // Outward normals everywhere (the winding's side).
  for (size_t v = 0; v < s.P.size(); ++v) EXPECT_GT(glm::dot(glm::dvec3(s.N[v]), glm::dvec3(s.P[v])), 0.0) << v;
}

TEST(LoopSubdivision, PlanarGridStaysPlanar) {
  std::vector<Vec3> P;
  std::vector<int> idx;
  grid(4, &P, &idx);
  LoopSurface s = subdivide(P, idx, 3);
  double max_z = 0.0;
  for (const Vec3& p : s.P) max_z = std::max(max_z, double(std::abs(p.z)));
  EXPECT_EQ(max_z, 0.0);
  for (const Vec3& n : s.N) EXPECT_NEAR(n.z, 1.f, 1e-6f);
  // The boundary stays on the square's outline (the boundary rules are curves of the boundary).
  for (const Vec3& p : s.P) {
    EXPECT_GE(p.x, -1e-6f);
    EXPECT_LE(p.x, 4.f + 1e-6f);
  }
  // Negative control: lifting one interior vertex bends the surface.
  P[6].z = 0.5f;
  LoopSurface bent = subdivide(P, idx, 3);
  max_z = 0.0;
  for (const Vec3& p : bent.P) max_z = std::max(max_z, double(std::abs(p.z)));
  EXPECT_GT(max_z, 0.05);
}

TEST(LoopSubdivision, RegularPlanarVertexIsItsOwnLimit) {
  std::vector<Vec3> P;
  std::vector<int> idx;
  grid(4, &P, &idx);
  // Vertex (2, 2): valence 6, ring symmetric about it; with no refinement only the limit mask acts.
  int centre = 2 * 5 + 2;
  LoopSurface s = subdivide(P, idx, 0);
  EXPECT_FLOAT_EQ(s.P[centre].x, 2.f);
  EXPECT_FLOAT_EQ(s.P[centre].y, 2.f);
  // Also after refinement (the vertex keeps its index).
  LoopSurface s3 = subdivide(P, idx, 3);
  EXPECT_NEAR(s3.P[centre].x, 2.f, 1e-5f);
  EXPECT_NEAR(s3.P[centre].y, 2.f, 1e-5f);
  // Negative control: moving a neighbour in the plane moves the limit.
  P[centre + 1].x += 0.5f;
  LoopSurface moved = subdivide(P, idx, 0);
  EXPECT_GT(std::abs(moved.P[centre].x - 2.f), 0.01f);
}

TEST(LoopSubdivision, LimitPositionDoesNotDependOnTheLevel) {
  // An even vertex keeps its index at every level, and its limit point is the same point of the
  // same surface however far the mesh was refined first (cube corners: valences 3 to 6).
  for (const auto& [P, idx] : {std::pair{kTetraP, kTetraIdx}, std::pair{kCubeP, kCubeIdx}}) {
    LoopSurface s0 = subdivide(P, idx, 0);
    for (int levels = 1; levels <= 4; ++levels) {
      LoopSurface s = subdivide(P, idx, levels);
      for (size_t v = 0; v < P.size(); ++v) EXPECT_LT(glm::length(s.P[v] - s0.P[v]), 1e-5f) << levels << " " << v;
    }
    // Negative control: the control vertices themselves are not on the limit surface.
    EXPECT_GT(glm::length(s0.P[0] - P[0]), 0.5f);
  }
}

TEST(LoopSubdivision, AreaConvergesWithLevels) {
  for (const auto& [P, idx] : {std::pair{kTetraP, kTetraIdx}, std::pair{kCubeP, kCubeIdx}}) {
    double a1 = area(subdivide(P, idx, 1)), a2 = area(subdivide(P, idx, 2));
    double a4 = area(subdivide(P, idx, 4)), a5 = area(subdivide(P, idx, 5));
    EXPECT_LT(std::abs(a5 - a4) / a5, 0.01) << a4 << " " << a5;
    // Negative control: the first levels still change it by more (the limit is approached).
    EXPECT_GT(std::abs(a2 - a1) / a2, std::abs(a5 - a4) / a5 * 4.0) << a1 << " " << a2;
    EXPECT_LT(a5, area(LoopSurface{P, {}, idx}));  // the limit of a convex mesh is inside it: less area
  }
}

TEST(LoopSubdivision, BadInputIsLocated) {
  FileLoc loc;
  loc.filename = std::make_shared<const std::string>("x.pbrt");
  loc.line = 3;
  loc.column = 7;
  auto message = [&](std::vector<int> idx, int levels) -> std::string {
    try {
      loop_subdivide(kTetraP, idx, levels, loc, loc);
    } catch (const Error& e) {
      return e.loc().str() + ": " + e.what();
    }
    return "";
  };
  EXPECT_THAT(message({0, 1}, 3), HasSubstr("x.pbrt:3:7: \"indices\" has 2 values"));
  EXPECT_THAT(message({0, 1, 4}, 3), HasSubstr("index 2 (value 4) is out of range"));
  EXPECT_THAT(message(kTetraIdx, -1), HasSubstr("\"levels\" is -1"));
  EXPECT_THAT(message(kTetraIdx, 20), HasSubstr("20 levels would make"));
  EXPECT_EQ(message(kTetraIdx, 2), "");  // negative control
}

TEST(LoopSubdivision, SceneRendersAndErrorsAreLocated) {
  std::string dir = test::temp_dir("loopsubdiv");
  auto scene = [](const std::string& shape) {
    return "LookAt 0 0 6  0 0 0  0 1 0\nCamera \"perspective\"\n"
           "Film \"rgb\" \"integer xresolution\" [ 16 ] \"integer yresolution\" [ 16 ]\nWorldBegin\n"
           "LightSource \"point\" \"point3 from\" [ 0 0 6 ] \"rgb I\" [ 10 10 10 ]\n" +
           shape + "\n";
  };
  std::string ok = test::write_file(dir, "ok.pbrt",
                                    scene("Shape \"loopsubdiv\" \"integer levels\" [ 2 ] \"point3 P\" [ 1 1 1  1 -1 -1  "
                                          "-1 1 -1  -1 -1 1 ] \"integer indices\" [ 0 1 2  0 3 1  0 2 3  1 3 2 ]"));
  auto r = test::run_penumbra({"render", ok, "-o", dir + "/ok.exr", "--spp", "1", "-q"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  std::string bad = test::write_file(dir, "bad.pbrt",
                                     scene("Shape \"loopsubdiv\" \"point3 P\" [ 0 0 0  1 0 0  0 1 0 ] "
                                           "\"integer indices\" [ 0 1 3 ]"));
  r = test::run_penumbra({"render", bad, "-o", dir + "/bad.exr", "--spp", "1", "-q"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("bad.pbrt:6:"));
  EXPECT_THAT(r.err, HasSubstr("index 2 (value 3) is out of range"));
}

// pbrt-v4 (mmp/pbrt-v4 5f7a606) rendered this scene with `pbrt --nthreads 1 --spp 256 --seed 1`:
// mean RGB 0.235534 0.205882 0.177304 (its pixels move more between two seeds than between it and Penumbra).
const char* kPbrtLoopScene = R"(LookAt 0.6 0.8 4  0 0 0  0 1 0
Camera "perspective" "float fov" [ 35 ]
Film "rgb" "integer xresolution" [ 64 ] "integer yresolution" [ 64 ] "string filename" "loop.exr"
Sampler "independent"
Integrator "path" "integer maxdepth" [ 5 ]
WorldBegin
LightSource "point" "point3 from" [ 2 3 4 ] "rgb I" [ 20 20 20 ]
LightSource "infinite" "rgb L" [ 0.2 0.2 0.2 ]
Material "diffuse" "rgb reflectance" [ 0.7 0.6 0.5 ]
AttributeBegin
Scale 1.2 1.2 1.2
Rotate 30 0 1 0
Shape "loopsubdiv" "integer levels" [ 3 ] "point3 P" [ -1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1  -1 -1 1  1 -1 1  1 1 1  -1 1 1 ]
  "integer indices" [ 0 2 1  0 3 2  4 5 6  4 6 7  0 1 5  0 5 4  2 3 7  2 7 6  1 2 6  1 6 5  3 0 4  3 4 7 ]
AttributeEnd
AttributeBegin
Translate 0 -1.6 0
Shape "loopsubdiv" "integer levels" [ 2 ] "point3 P" [ -3 0 -3  0 0 -3  3 0 -3  -3 0 0  0 0.6 0  3 0 0  -3 0 3  0 0 3  3 0 3 ]
  "integer indices" [ 0 3 4  0 4 1  1 4 5  1 5 2  3 6 7  3 7 4  4 7 8  4 8 5 ]
AttributeEnd
)";

TEST(LoopSubdivision, MeanMatchesPbrtV4) {
  std::string dir = test::temp_dir("loopsubdivision-pbrt");
  std::string file = test::write_file(dir, "scene.pbrt", kPbrtLoopScene);
  auto r = test::run_penumbra({"render", file, "-o", dir + "/out.exr", "--spp", "128", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ImageRgb img = read_image(dir + "/out.exr");
  const double pbrt[3] = {0.235534, 0.205882, 0.177304};
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(test::mean_channel(img, c) / pbrt[c], 1.0, 0.01) << c;
  // Negative control: the control meshes themselves (no subdivision) are far off (37 %).
  std::string control = std::regex_replace(kPbrtLoopScene, std::regex(R"(Shape "loopsubdiv" "integer levels" \[ [0-9] \])"),
                                           "Shape \"trianglemesh\"");
  file = test::write_file(dir, "control.pbrt", control);
  r = test::run_penumbra({"render", file, "-o", dir + "/control.exr", "--spp", "128", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GT(std::abs(test::mean_channel(read_image(dir + "/control.exr"), 0) / pbrt[0] - 1.0), 0.05);
}
