// Solid-angle sampling of the shapes area lights use, against their own pdfs by chi-square: spheres
// seen from outside (cone sampling, including the Taylor branch for cones under 1.5 degrees) and from
// inside (area sampling), and triangles (area sampling converted to solid angle). Every sample's
// direction and distance fields must match its point (direction_fields_match()).
#include "scene/sphere.h"
#include "scene/triangle_mesh.h"
#include "support/chi_square.h"
#include "support/shape_sample_checks.h"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

using namespace penumbra;
using namespace penumbra::test;

namespace {

constexpr int kTests = 6;
const double kAlpha = sidak_alpha(0.01, kTests);

// Nearest intersection of the ray (o, w) with the sphere beyond t = 0, in double precision.
std::optional<Vec3> hit_sphere(const Sphere& s, const Vec3& o, const Vec3& w) {
  glm::dvec3 oc = glm::dvec3(o) - glm::dvec3(s.center()), d(w);
  double b = glm::dot(oc, d), c = glm::dot(oc, oc) - double(s.radius()) * s.radius();
  double disc = b * b - c;
  if (disc < 0) return std::nullopt;
  double t = -b - std::sqrt(disc);
  if (t <= 0) t = -b + std::sqrt(disc);
  if (t <= 0) return std::nullopt;
  return Vec3(glm::dvec3(o) + t * d);
}

ChiSquareResult test_sphere(const Sphere& sphere, const Vec3& ref, double z_min) {
  ShapeSampleContext ctx{ref, Vec3(0.f)};
  int mismatched = 0;
  auto sample = [&](Vec2 u, float) -> std::optional<Vec3> {
    auto s = sphere.sample_solid_angle(ctx, u);
    if (!s) return std::nullopt;
    mismatched += !direction_fields_match(*s, ref);
    return glm::normalize(s->p - ref);
  };
  auto pdf = [&](const Vec3& w) -> double {
    auto p = hit_sphere(sphere, ref, w);
    return p ? sphere.pdf_solid_angle(ctx, w, *p, sphere.normal_at(*p)) : 0.0;
  };
  SphereChart chart;
  chart.z_min = z_min;
  ChiSquareResult r = chi_square_sphere(sample, pdf, 1000000, 40, 80, 17, chart);
  EXPECT_EQ(mismatched, 0) << "samples whose wi or distance does not match their point";
  return r;
}

}  // namespace

TEST(SphereSampling, ConeFromOutsideMatchesPdfChiSquare) {
  Sphere sphere(glm::translate(Mat4(1.f), Vec3(0, 0, 3)), 1.f, false);
  ChiSquareResult r = test_sphere(sphere, Vec3(0.f), 0.9);
  EXPECT_TRUE(r.passes(kAlpha)) << r.summary();
  EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
}

TEST(SphereSampling, TinyConeUsesStableBranchAndMatchesPdfChiSquare) {
  // sin^2(theta_max) = 4e-4 < sin^2(1.5 deg): the Taylor branch.
  Sphere sphere(glm::translate(Mat4(1.f), Vec3(0, 0, 1)), 0.02f, false);
  ChiSquareResult r = test_sphere(sphere, Vec3(0.f), 0.9997);
  EXPECT_TRUE(r.passes(kAlpha)) << r.summary();
  EXPECT_NEAR(r.pdf_integral, 1.0, 1e-2);
}

TEST(SphereSampling, FromInsideSamplesByAreaAndMatchesPdfChiSquare) {
  Sphere sphere(Mat4(1.f), 1.f, true);
  ChiSquareResult r = test_sphere(sphere, Vec3(0.1f, -0.2f, 0.5f), -1.0);
  EXPECT_TRUE(r.passes(kAlpha)) << r.summary();
  EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
}

TEST(SphereSampling, SampledPointsLieOnTheVisibleSurface) {
  Sphere sphere(glm::translate(Mat4(1.f), Vec3(0, 0, 3)), 1.f, false);
  ShapeSampleContext ctx{Vec3(0.f), Vec3(0.f)};
  for (int i = 0; i < 1000; ++i) {
    auto s = sphere.sample_solid_angle(ctx, Vec2((i + 0.5f) / 1000.f, std::fmod(i * 0.618034f, 1.f)));
    ASSERT_TRUE(s);
    EXPECT_NEAR(glm::distance(s->p, sphere.center()), 1.f, 1e-5f);
    EXPECT_LE(glm::dot(s->n, s->p), 1e-4f);  // facing the reference point at the origin
  }
}

namespace {

ChiSquareResult triangle_chi_square(const TriangleMesh& mesh, double z_min) {
  Triangle tri(&mesh, 0);
  ShapeSampleContext ctx{Vec3(0.f), Vec3(0.f)};
  int mismatched = 0;
  auto sample = [&](Vec2 u, float) -> std::optional<Vec3> {
    auto s = tri.sample_solid_angle(ctx, u);
    if (!s) return std::nullopt;
    mismatched += !direction_fields_match(*s, ctx.p);
    return glm::normalize(s->p);
  };
  // Ray-plane intersection and inside test in double precision.
  auto pdf = [&](const Vec3& w) -> double {
    glm::dvec3 a(mesh.P[0]), b(mesh.P[1]), c(mesh.P[2]), d(w);
    glm::dvec3 n = glm::cross(b - a, c - a);
    double denom = glm::dot(n, d);
    if (denom == 0) return 0.0;
    double t = glm::dot(n, a) / denom;
    if (t <= 0) return 0.0;
    glm::dvec3 p = t * d;
    if (glm::dot(glm::cross(b - a, p - a), n) < 0 || glm::dot(glm::cross(c - b, p - b), n) < 0 ||
        glm::dot(glm::cross(a - c, p - c), n) < 0)
      return 0.0;
    return tri.pdf_solid_angle(ctx, w, Vec3(p), mesh.geometric_normal(0, Vec3(1 / 3.f)));
  };
  SphereChart chart;
  chart.z_min = z_min;
  ChiSquareResult r = chi_square_sphere(sample, pdf, 1000000, 40, 80, 23, chart);
  EXPECT_EQ(mismatched, 0) << "samples whose wi or distance does not match their point";
  return r;
}

// Whether the triangle's density seen from the origin is the same towards its centroid and towards a
// point near its first vertex: uniform in solid angle (spherical sampling) or not (by area).
bool uniform_in_solid_angle(const TriangleMesh& mesh) {
  Triangle tri(&mesh, 0);
  ShapeSampleContext ctx{Vec3(0.f), Vec3(0.f)};
  Vec3 n = mesh.geometric_normal(0, Vec3(1 / 3.f));
  Vec3 centroid = (mesh.P[0] + mesh.P[1] + mesh.P[2]) / 3.f, corner = 0.8f * mesh.P[0] + 0.2f * centroid;
  float a = tri.pdf_solid_angle(ctx, glm::normalize(centroid), centroid, n);
  float b = tri.pdf_solid_angle(ctx, glm::normalize(corner), corner, n);
  return std::abs(a - b) <= 1e-4f * a;
}

}  // namespace

// Subtends about 1.1 sr, its front towards the origin: sampled uniformly in solid angle (Arvo's
// spherical triangle sampling).
TEST(TriangleSampling, SphericalSamplingMatchesPdfChiSquare) {
  TriangleMesh mesh;
  mesh.P = {Vec3(-1, -0.5f, 1), Vec3(1.5f, -0.3f, 1.2f), Vec3(0.2f, 1.4f, 0.8f)};
  mesh.indices = {0, 2, 1};  // the winding's normal faces the origin
  ASSERT_TRUE(uniform_in_solid_angle(mesh)) << "the spherical sampler is not the one in use";
  ChiSquareResult r = triangle_chi_square(mesh, 0.3);
  EXPECT_TRUE(r.passes(kAlpha)) << r.summary();
  EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3);
}

// The same triangle seen from behind (its normal faces away from the origin), where a one-sided
// emitter sends nothing: sampled by area, and the pdf makes the same choice.
TEST(TriangleSampling, TriangleSeenFromBehindUsesAreaSamplingChiSquare) {
  TriangleMesh mesh;
  mesh.P = {Vec3(-1, -0.5f, 1), Vec3(1.5f, -0.3f, 1.2f), Vec3(0.2f, 1.4f, 0.8f)};
  mesh.indices = {0, 1, 2};
  ASSERT_FALSE(uniform_in_solid_angle(mesh)) << "seen from behind, the triangle is still sampled spherically";
  ChiSquareResult r = triangle_chi_square(mesh, 0.3);
  EXPECT_TRUE(r.passes(kAlpha)) << r.summary();
  EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3);
}

// Subtends about 5e-5 sr, below the spherical sampler's precision limit: sampled by area.
TEST(TriangleSampling, SmallDistantTriangleFallsBackToAreaSamplingChiSquare) {
  TriangleMesh mesh;
  mesh.P = {Vec3(-0.05f, -0.04f, 10), Vec3(0.06f, -0.03f, 10.2f), Vec3(0.01f, 0.07f, 9.9f)};
  mesh.indices = {0, 1, 2};
  ChiSquareResult r = triangle_chi_square(mesh, std::cos(0.012));
  EXPECT_TRUE(r.passes(kAlpha)) << r.summary();
  EXPECT_NEAR(r.pdf_integral, 1.0, 5e-3);
}

// Subtends about 0.05 sr (area over squared centroid distance 0.05, below the 0.25 where spherical
// sampling pays): sampled by area, and the pdf makes the same choice.
TEST(TriangleSampling, ModerateTriangleUsesAreaSamplingChiSquare) {
  TriangleMesh mesh;
  mesh.P = {Vec3(-0.5f, -0.4f, 3), Vec3(0.6f, -0.3f, 3.2f), Vec3(0.1f, 0.7f, 2.9f)};
  mesh.indices = {0, 1, 2};
  ChiSquareResult r = triangle_chi_square(mesh, std::cos(0.3));
  EXPECT_TRUE(r.passes(kAlpha)) << r.summary();
  EXPECT_NEAR(r.pdf_integral, 1.0, 3e-3);
}

// The check the chi-square tests apply to every sample: it accepts a sample whose fields match and
// rejects the two ways a producer could get them wrong (fields left at zero, a distance 1 % off).
TEST(ShapeSampleFields, CheckRejectsMissingOrWrongFields) {
  Vec3 ref(0.5f, -1.f, 2.f);
  ShapeSample s;
  s.p = Vec3(1.f, 2.f, 3.f);
  s.distance = glm::length(s.p - ref);
  s.wi = (s.p - ref) / s.distance;
  EXPECT_TRUE(direction_fields_match(s, ref));
  ShapeSample unset = s;
  unset.wi = Vec3(0.f);
  unset.distance = 0.f;
  EXPECT_FALSE(direction_fields_match(unset, ref));
  ShapeSample far = s;
  far.distance *= 1.01f;
  EXPECT_FALSE(direction_fields_match(far, ref));
}

// A caller that can use only the front (a one-sided emitter: ShapeSampleContext::front_only) gets
// nothing from behind a flat triangle, with density 0 there, and from the front exactly the samples
// and densities it gets without asking.
TEST(TriangleSampling, FrontOnlyContextGetsNothingFromBehindAndTheSameFromTheFront) {
  TriangleMesh mesh;
  mesh.P = {Vec3(-1, -0.5f, 1), Vec3(1.5f, -0.3f, 1.2f), Vec3(0.2f, 1.4f, 0.8f)};
  for (bool facing_origin : {false, true}) {
    mesh.indices = facing_origin ? std::vector<uint32_t>{0, 2, 1} : std::vector<uint32_t>{0, 1, 2};
    Triangle tri(&mesh, 0);
    const ShapeSampleContext any{Vec3(0.f), Vec3(0.f)}, front{Vec3(0.f), Vec3(0.f), true};
    const Vec3 n = mesh.geometric_normal(0, Vec3(1 / 3.f));
    int sampled = 0;
    for (int i = 0; i < 256; ++i) {
      Vec2 u((i + 0.5f) / 256.f, std::fmod(i * 0.618034f, 1.f));
      std::optional<ShapeSample> a = tri.sample_solid_angle(any, u), f = tri.sample_solid_angle(front, u);
      ASSERT_TRUE(a.has_value());
      const float pdf_any = tri.pdf_solid_angle(any, a->wi, a->p, n), pdf_front = tri.pdf_solid_angle(front, a->wi, a->p, n);
      if (!facing_origin) {
        EXPECT_FALSE(f.has_value()) << "a sample from behind for a caller that wants the front only";
        EXPECT_EQ(pdf_front, 0.f);
        EXPECT_GT(pdf_any, 0.f);
        continue;
      }
      ASSERT_TRUE(f.has_value());
      EXPECT_EQ(f->p, a->p);
      EXPECT_EQ(f->pdf, a->pdf);
      EXPECT_EQ(pdf_front, pdf_any);
      ++sampled;
    }
    EXPECT_EQ(sampled, facing_origin ? 256 : 0);
  }
}
