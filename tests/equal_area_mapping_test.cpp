// The equal-area octahedral map (penumbra/equal_area.h): known points, round trips to
// 1e-5, equal solid angle per cell of the square (exactly, as spherical polygons, and statistically,
// by a chi-square test of the histogram of uniform directions), and the border wrap; each property
// with a negative control (a map 1-2 % off equal area, a wrong wrap) that fails.
#include <penumbra/equal_area.h>

#include <penumbra/sampling.h>

#include "support/chi_square.h"
#include "support/pcg32.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <functional>
#include <vector>

namespace penumbra {
namespace {

using SquareToSphere = std::function<Vec3(Vec2)>;
using SphereToSquare = std::function<Vec2(const Vec3&)>;

constexpr int kChiSquareTests = 1;

double distance(const Vec3& a, const Vec3& b) { return glm::length(glm::dvec3(a) - glm::dvec3(b)); }

// A map 1 % off equal area: the square is warped by p + 0.01 sin(2 pi p) / (2 pi) on both axes
// before the true map, so cell areas are off by up to 2 %.
Vec2 warp_one_percent(Vec2 p) {
  return p + 0.01f * Vec2(std::sin(2.f * Pi * p.x), std::sin(2.f * Pi * p.y)) / (2.f * Pi);
}

TEST(EqualAreaMapping, KnownPointsOfTheOctahedron) {
  struct Case {
    Vec2 p;
    Vec3 d;
  };
  const float h = std::sqrt(0.5f);
  for (const Case& c : {Case{{0.5f, 0.5f}, {0, 0, 1}},     // centre: zenith
                        Case{{0.f, 0.f}, {0, 0, -1}},      // corners: nadir
                        Case{{1.f, 1.f}, {0, 0, -1}},
                        Case{{1.f, 0.5f}, {1, 0, 0}},      // mid-edges of the square: the horizon's axes
                        Case{{0.5f, 1.f}, {0, 1, 0}},
                        Case{{0.f, 0.5f}, {-1, 0, 0}},
                        Case{{0.5f, 0.f}, {0, -1, 0}},
                        Case{{0.75f, 0.75f}, {h, h, 0}},   // diamond edge midpoints: the horizon at 45 degrees
                        Case{{0.25f, 0.75f}, {-h, h, 0}}}) {
    Vec3 d = equal_area_square_to_sphere(c.p);
    EXPECT_LT(distance(d, c.d), 1e-6) << c.p.x << "," << c.p.y << " -> " << d.x << " " << d.y << " " << d.z;
  }
  // z = 1 - r^2 inside the diamond: r = 1/2 (a point halfway to the diamond's edge) is z = 3/4.
  EXPECT_NEAR(equal_area_square_to_sphere({0.75f, 0.5f}).z, 0.75f, 1e-6f);
  EXPECT_NEAR(equal_area_square_to_sphere({1.f, 0.75f}).z, -0.75f, 1e-6f);
}

TEST(EqualAreaMapping, RoundTripsSphereToSquareToSphereTo1e5) {
  test::Pcg32 rng(3);
  double worst = 0.0;
  auto check = [&](Vec3 d) {
    d = glm::normalize(d);
    Vec2 p = equal_area_sphere_to_square(d);
    ASSERT_TRUE(p.x >= 0.f && p.x <= 1.f && p.y >= 0.f && p.y <= 1.f) << p.x << " " << p.y;
    worst = std::max(worst, distance(equal_area_square_to_sphere(p), d));
  };
  for (int i = 0; i < 1'000'000; ++i) check(sample_uniform_sphere(Vec2(rng.next_float(), rng.next_float())));
  // Axes, poles, the equator and directions a hair away from the poles, where 1 - |z| cancels.
  for (Vec3 d : {Vec3(0, 0, 1), Vec3(0, 0, -1), Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0),
                 Vec3(1, 1, 0), Vec3(-1, 1, 0), Vec3(1e-4f, 2e-4f, 1), Vec3(-3e-4f, 1e-5f, -1), Vec3(1e-6f, 0, 1),
                 Vec3(0, -1e-6f, -1), Vec3(0.3f, -0.2f, 1e-7f), Vec3(0.3f, -0.2f, -1e-7f)})
    check(d);
  std::printf("[ measured ] worst round-trip error %.3g\n", worst);
  EXPECT_LT(worst, 1e-5);
}

TEST(EqualAreaMapping, RoundTripsSquareToSphereToSquareTo1e5) {
  test::Pcg32 rng(4);
  double worst = 0.0;
  for (int i = 0; i < 1'000'000; ++i) {
    Vec2 p(rng.next_float(), rng.next_float());
    Vec2 q = equal_area_sphere_to_square(equal_area_square_to_sphere(p));
    worst = std::max(worst, static_cast<double>(glm::length(p - q)));
  }
  std::printf("[ measured ] worst round-trip error %.3g\n", worst);
  EXPECT_LT(worst, 1e-5);
}

// Uniform directions, mapped to the square and histogrammed over 8 x 8 equal cells, must fill them
// equally: the expected count per cell is N/64, tested by chi-square. 1M samples put 15625 in a cell
// (standard deviation 0.8 %), so the 1 % warp (cells off by up to 2 %) fails by far.
test::ChiSquareResult cell_histogram_chi_square(const SphereToSquare& to_square) {
  constexpr int kCells = 8, kSamples = 1'000'000;
  std::vector<double> observed(kCells * kCells, 0.0), expected(kCells * kCells, double(kSamples) / (kCells * kCells));
  test::Pcg32 rng(11);
  for (int i = 0; i < kSamples; ++i) {
    Vec2 p = to_square(sample_uniform_sphere(Vec2(rng.next_float(), rng.next_float())));
    int x = std::clamp(static_cast<int>(p.x * kCells), 0, kCells - 1);
    int y = std::clamp(static_cast<int>(p.y * kCells), 0, kCells - 1);
    observed[y * kCells + x] += 1.0;
  }
  return test::chi_square_from_counts(observed, expected, kSamples);
}

TEST(EqualAreaMapping, EqualCellsOfTheSquareCoverEqualSolidAngles) {
  test::ChiSquareResult r = cell_histogram_chi_square([](const Vec3& d) { return equal_area_sphere_to_square(d); });
  std::printf("[ chi2     ] equal-area cells: %s\n", r.summary().c_str());
  EXPECT_TRUE(r.passes(test::sidak_alpha(0.01, kChiSquareTests))) << r.summary();

  // Negative control: the inverse of the 1 %-warped map (found by fixed-point iteration, which
  // converges since the warp moves points by at most 0.16 %).
  test::ChiSquareResult bad = cell_histogram_chi_square([](const Vec3& d) {
    Vec2 target = equal_area_sphere_to_square(d), p = target;
    for (int k = 0; k < 20; ++k) p = target - (warp_one_percent(p) - p);
    return p;
  });
  std::printf("[ chi2     ] 1 %% warped cells (must fail): %s\n", bad.summary().c_str());
  EXPECT_LT(bad.p_value, 1e-6) << bad.summary();
}

// Exact area per cell: the solid angle of the region a cell maps to, as the spherical polygon
// through 64 mapped points per cell edge (a fan of triangles from the cell centre's direction, each
// by Van Oosterom and Strackee's formula, in double). Every one of 16 x 16 cells must be 4 pi / 256.
double spherical_triangle_solid_angle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  double numerator = glm::dot(a, glm::cross(b, c));
  double denominator = 1.0 + glm::dot(a, b) + glm::dot(b, c) + glm::dot(c, a);
  return 2.0 * std::atan2(numerator, denominator);
}

double worst_cell_solid_angle_error(const SquareToSphere& f) {
  constexpr int kCells = 16, kPerEdge = 64;
  const double expected = 4.0 * 3.14159265358979323846 / (kCells * kCells);
  double worst = 0.0;
  for (int cy = 0; cy < kCells; ++cy)
    for (int cx = 0; cx < kCells; ++cx) {
      // The cell's boundary, counter-clockwise in the square.
      std::vector<Vec2> loop;
      auto corner = [&](int i, int j) { return Vec2(float(cx + i) / kCells, float(cy + j) / kCells); };
      const Vec2 corners[5] = {corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1), corner(0, 0)};
      for (int e = 0; e < 4; ++e)
        for (int k = 0; k < kPerEdge; ++k) loop.push_back(glm::mix(corners[e], corners[e + 1], float(k) / kPerEdge));
      glm::dvec3 centre = glm::normalize(glm::dvec3(f(corner(0, 0) + Vec2(0.5f / kCells))));
      double omega = 0.0;
      for (size_t k = 0; k < loop.size(); ++k)
        omega += spherical_triangle_solid_angle(centre, glm::normalize(glm::dvec3(f(loop[k]))),
                                                glm::normalize(glm::dvec3(f(loop[(k + 1) % loop.size()]))));
      worst = std::max(worst, std::abs(std::abs(omega) / expected - 1.0));
    }
  return worst;
}

TEST(EqualAreaMapping, EveryCellOfTheSquareHasExactlyItsShareOfTheSphere) {
  double worst = worst_cell_solid_angle_error(equal_area_square_to_sphere);
  std::printf("[ measured ] worst relative error of a cell's solid angle: %.3g\n", worst);
  EXPECT_LT(worst, 1e-4);
  double bad = worst_cell_solid_angle_error([](Vec2 p) { return equal_area_square_to_sphere(warp_one_percent(p)); });
  std::printf("[ measured ] same for the 1 %% warped map (must exceed 1e-2): %.3g\n", bad);
  EXPECT_GT(bad, 1e-2);
}

// A point just outside the square, wrapped, must continue the map across the border: each edge of
// the square is a half-meridian of the lower hemisphere (y = 0 for the edges u = 0 and u = 1, x = 0
// for v = 0 and v = 1), and a step eps across the edge must cross that meridian's plane to a
// direction about as far from the border as the step inside it. Clamping instead stays on the
// border; mirroring without the fold lands back on the inside point.
int border_points_continued(const std::function<Vec2(Vec2)>& wrap) {
  constexpr float eps = 1e-3f;
  int good = 0;
  // Points along each edge, avoiding its midpoint (on the horizon, where the inside step is along
  // the meridian's plane itself).
  for (int k = 0; k < 40; ++k) {
    float t = (k + 0.5f) / 40.f;
    struct Edge {
      Vec2 q, out;
      Vec3 plane_normal;
    };
    for (const Edge& e : {Edge{{0.f, t}, {-1, 0}, {0, 1, 0}}, Edge{{1.f, t}, {1, 0}, {0, 1, 0}},
                          Edge{{t, 0.f}, {0, -1}, {1, 0, 0}}, Edge{{t, 1.f}, {0, 1}, {1, 0, 0}}}) {
      Vec3 border = equal_area_square_to_sphere(e.q);
      Vec3 inside = equal_area_square_to_sphere(e.q - eps * e.out);
      Vec3 outside = equal_area_square_to_sphere(wrap(e.q + eps * e.out));
      double step_in = distance(inside, border), step_out = distance(outside, border);
      bool crosses = glm::dot(inside, e.plane_normal) * glm::dot(outside, e.plane_normal) < 0.f;
      if (crosses && step_out > 0.5 * step_in && step_out < 2.0 * step_in) ++good;
    }
  }
  return good;
}

TEST(EqualAreaMapping, WrapContinuesTheMapAcrossTheBorder) {
  EXPECT_EQ(border_points_continued(wrap_equal_area_square), 4 * 40);
  EXPECT_EQ(border_points_continued([](Vec2 p) { return glm::clamp(p, Vec2(0.f), Vec2(1.f)); }), 0);
  EXPECT_EQ(border_points_continued([](Vec2 p) {
              if (p.x < 0.f) p.x = -p.x;
              if (p.x > 1.f) p.x = 2.f - p.x;
              if (p.y < 0.f) p.y = -p.y;
              if (p.y > 1.f) p.y = 2.f - p.y;
              return p;
            }),
            0);
  // Points inside are unchanged; a corner wraps across both edges.
  EXPECT_EQ(wrap_equal_area_square(Vec2(0.3f, 0.7f)), Vec2(0.3f, 0.7f));
  Vec2 c = wrap_equal_area_square(Vec2(-0.1f, -0.2f));
  EXPECT_NEAR(c.x, 0.9f, 1e-6f);
  EXPECT_NEAR(c.y, 0.8f, 1e-6f);
}

}  // namespace
}  // namespace penumbra
