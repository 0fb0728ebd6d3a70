// pbrt-v4's disk and cylinder (core/src/scene/quadrics.h): intersections against points placed on
// the surface independently (under rotation, translation and non-uniform scale; partial shapes miss
// where they should), world-space areas against closed forms, orientation and uv, area sampling seen
// as solid-angle sampling by chi-square (with the pdf's integral, which a 2 % error fails), and area
// lights whose irradiance is known in closed form.
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "render/render_session.h"
#include "scene/quadrics.h"
#include "scene/scene_builder.h"
#include "support/chi_square.h"
#include "support/shape_sample_checks.h"
#include "support/command.h"
#include "support/image_stats.h"
#include "support/pcg32.h"

#include <penumbra/sampling.h>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <cstdio>

using namespace penumbra;
using namespace penumbra::test;

namespace {

constexpr int kChiTests = 3;
const double kAlpha = sidak_alpha(0.01, kChiTests);
constexpr double kPi = 3.14159265358979323846;

// Rotation, translation and a non-uniform scale.
Mat4 skewed_transform() {
  Mat4 m = glm::translate(Mat4(1.f), Vec3(0.3f, -0.2f, 1.5f));
  m = glm::rotate(m, 0.7f, glm::normalize(Vec3(1, 2, 3)));
  return glm::scale(m, Vec3(1.5f, 0.8f, 1.2f));
}

Vec3 apply(const Mat4& m, const glm::dvec3& p) { return Vec3(m * Vec4(Vec3(p), 1.f)); }

}  // namespace

// Rays from random origins aimed at random points of the surface (chosen in object space by the test,
// moved to world space) hit at t = 1 (the direction is the unnormalised segment), for rays at least
// 3 degrees off the surface (closer to grazing, the target's own float rounding moves t by more);
// points in the hole, beyond phimax or beyond zmax are missed.
TEST(QuadricShapes, RaysHitWherePointsWerePlacedAndMissTheGaps) {
  const Mat4 m = skewed_transform();
  Disk disk(m, false, 0.25f, 1.f, 0.4f, 270.f);
  Cylinder cylinder(m, false, 0.7f, -0.5f, 0.8f, 300.f);
  Pcg32 rng(9);
  double worst = 0.0;
  glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(m)));
  auto grazing = [&](const Vec3& d, const glm::dvec3& n_obj) {
    return std::abs(glm::dot(glm::normalize(d), glm::normalize(normal_matrix * Vec3(n_obj)))) < 0.05f;
  };
  for (int i = 0; i < 20000; ++i) {
    double phi = rng.next_float() * 270.0 / 180.0 * kPi, r = 0.4 + 0.6 * rng.next_float();
    Vec3 target = apply(m, {r * std::cos(phi), r * std::sin(phi), 0.25});
    Vec3 o = target + 3.f * Vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f);
    if (!grazing(target - o, {0, 0, 1})) {
      auto t = disk.intersect(Ray{o, target - o}, 0.f, Infinity);
      ASSERT_TRUE(t) << i;
      worst = std::max(worst, std::abs(double(*t) - 1.0));
      // The same ray, stopped short of the disk, misses.
      EXPECT_FALSE(disk.intersect(Ray{o, target - o}, 0.f, 0.999f));
    }

    // Cylinder: an origin on the outward side of the target's tangent plane sees it first.
    double z = -0.5 + 1.3 * rng.next_float();
    phi = rng.next_float() * 300.0 / 180.0 * kPi;
    glm::dvec3 p_obj(0.7 * std::cos(phi), 0.7 * std::sin(phi), z);
    target = apply(m, p_obj);
    Vec3 outward = apply(m, p_obj * glm::dvec3(1.5, 1.5, 1.0) + glm::dvec3(0, 0, rng.next_float() - 0.5f));
    if (grazing(target - outward, {p_obj.x, p_obj.y, 0.0})) continue;
    auto t = cylinder.intersect(Ray{outward, target - outward}, 0.f, Infinity);
    ASSERT_TRUE(t) << i;
    worst = std::max(worst, std::abs(double(*t) - 1.0));
  }
  std::printf("[ measured ] worst |t - 1|: %.3g\n", worst);
  EXPECT_LT(worst, 1e-5);

  // Gaps: the annulus's hole, the missing sector (phi in (270, 360) degrees), and past zmax.
  Vec3 above(apply(m, {0, 0, 2})), hole(apply(m, {0.1, 0.1, 0.25})), sector(apply(m, {0.5, -0.3, 0.25}));
  EXPECT_FALSE(disk.intersect(Ray{above, hole - above}, 0.f, Infinity));
  EXPECT_FALSE(disk.intersect(Ray{above, sector - above}, 0.f, Infinity));
  Vec3 side(apply(m, {3, 0.2, 0.9})), past_top(apply(m, {0, 0.2, 0.9}));
  EXPECT_FALSE(cylinder.intersect(Ray{side, past_top - side}, 0.f, Infinity));
  // Looking through the missing sector (phi in (300, 360) degrees) at the far wall from outside.
  Vec3 gap_origin(apply(m, {2.0, -0.6, 0.0})), far_wall(apply(m, {-0.7, 0.0, 0.0}));
  auto t = cylinder.intersect(Ray{gap_origin, far_wall - gap_origin}, 0.f, Infinity);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 1.0, 1e-5);
}

// Texture footprints need dp/du and dp/dv: two hits a small step apart on the surface (found by
// tracing rays, not from the shape's formulas) differ by dpdu du + dpdv dv to first order. A 2 %
// error in either derivative would leave a residual of about 1e-2 relative; the exact ones leave the
// float rounding of the hits.
TEST(QuadricShapes, UvDerivativesMatchFiniteDifferencesOfHits) {
  const Mat4 m = skewed_transform();
  Disk disk(m, false, 0.25f, 1.f, 0.4f, 270.f);
  Cylinder cylinder(m, false, 0.7f, -0.5f, 0.8f, 300.f);
  Pcg32 rng(17);
  double worst = 0.0, worst_biased_u = 0.0, worst_biased_v = 0.0;
  auto check = [&](const Quadric& q, const glm::dvec3& a_obj, const glm::dvec3& b_obj, const glm::dvec3& eye_obj) {
    Vec3 eye = apply(m, eye_obj), a = apply(m, a_obj), b = apply(m, b_obj);
    auto ta = q.intersect(Ray{eye, a - eye}, 0.f, Infinity), tb = q.intersect(Ray{eye, b - eye}, 0.f, Infinity);
    ASSERT_TRUE(ta && tb);
    Quadric::Surface sa = q.surface_at(Ray{eye, a - eye}, *ta), sb = q.surface_at(Ray{eye, b - eye}, *tb);
    Vec2 duv = sb.uv - sa.uv;
    // The mean of both ends' derivatives (trapezoid rule) leaves a residual of second order in the step.
    Vec3 predicted = 0.5f * ((sa.dpdu + sb.dpdu) * duv.x + (sa.dpdv + sb.dpdv) * duv.y), actual = sb.p - sa.p;
    auto residual = [&](float su, float sv) {
      Vec3 p = 0.5f * ((sa.dpdu + sb.dpdu) * (su * duv.x) + (sa.dpdv + sb.dpdv) * (sv * duv.y));
      return double(glm::length(p - actual) / glm::length(actual));
    };
    worst = std::max(worst, double(glm::length(predicted - actual) / glm::length(actual)));
    worst_biased_u = std::max(worst_biased_u, residual(1.02f, 1.f));  // negative controls: 2 % off
    worst_biased_v = std::max(worst_biased_v, residual(1.f, 1.02f));
  };
  for (int i = 0; i < 200; ++i) {
    double phi = rng.next_float() * 4.0, r = 0.5 + 0.4 * rng.next_float();
    double dphi = 0.01 * (rng.next_float() - 0.5), dr = 0.01 * (rng.next_float() - 0.5);
    check(disk, {r * std::cos(phi), r * std::sin(phi), 0.25},
          {(r + dr) * std::cos(phi + dphi), (r + dr) * std::sin(phi + dphi), 0.25}, {0.1, 0.2, 2.0});
    double z = -0.3 + rng.next_float(), dz = 0.01 * (rng.next_float() - 0.5);
    phi = rng.next_float() * 5.0;
    check(cylinder, {0.7 * std::cos(phi), 0.7 * std::sin(phi), z},
          {0.7 * std::cos(phi + dphi), 0.7 * std::sin(phi + dphi), z + dz},
          {2.0 * std::cos(phi), 2.0 * std::sin(phi), z});
  }
  std::printf("[ measured ] worst relative residual of dpdu du + dpdv dv: %.3g (2 %% off in u: %.3g, in v: %.3g)\n",
              worst, worst_biased_u, worst_biased_v);
  EXPECT_LT(worst, 2e-3);
  EXPECT_GT(worst_biased_u, 2e-3);
  EXPECT_GT(worst_biased_v, 2e-3);
}

// Areas against closed forms: a disk's area scales by the product of its plane's two stretches, a
// cylinder's lateral area by the stretch along z times that of its circumference (Ramanujan's
// ellipse perimeter for an uneven cross-section, which also makes its area sampling non-uniform).
TEST(QuadricShapes, WorldAreasMatchClosedForms) {
  Mat4 rot_trans = glm::rotate(glm::translate(Mat4(1.f), Vec3(1, 2, 3)), 1.1f, glm::normalize(Vec3(1, -1, 2)));
  Disk annulus(glm::scale(rot_trans, Vec3(2.f)), false, 0.5f, 1.f, 0.5f, 90.f);
  EXPECT_NEAR(annulus.area(), 4.0 * 0.25 * kPi * (1.0 - 0.25), 1e-5);
  Disk stretched(glm::scale(rot_trans, Vec3(2.f, 3.f, 7.f)), false, 0.f, 1.f, 0.f, 360.f);
  EXPECT_NEAR(stretched.area(), 6.0 * kPi, 1e-4);
  Cylinder tall(glm::scale(rot_trans, Vec3(2.f, 2.f, 3.f)), false, 0.5f, -1.f, 1.f, 180.f);
  EXPECT_NEAR(tall.area(), 0.5 * kPi * 2.0 * 2.0 * 3.0, 1e-4);
  EXPECT_TRUE(tall.area_is_uniform());
  Cylinder elliptic(glm::scale(rot_trans, Vec3(2.f, 1.f, 1.f)), false, 1.f, 0.f, 1.f, 360.f);
  double a = 2.0, b = 1.0, h = (a - b) * (a - b) / ((a + b) * (a + b));
  double perimeter = kPi * (a + b) * (1.0 + 3.0 * h / (10.0 + std::sqrt(4.0 - 3.0 * h)));
  EXPECT_NEAR(elliptic.area(), perimeter, 1e-4 * perimeter);
  EXPECT_FALSE(elliptic.area_is_uniform());
}

namespace {

// Direction sampling from `ref` against the pdf. The pdf of a direction sums the densities of every
// point of the shape along it (a ray can cross a cylinder twice), found with the shape's intersect().
ChiSquareResult test_solid_angle_sampling(const Quadric& q, const Vec3& ref, double pdf_scale = 1.0) {
  ShapeSampleContext ctx{ref, Vec3(0.f)};
  int mismatched = 0;
  auto sample = [&](Vec2 u, float) -> std::optional<Vec3> {
    auto s = q.sample_solid_angle(ctx, u);
    if (!s) return std::nullopt;
    mismatched += !direction_fields_match(*s, ref);
    return glm::normalize(s->p - ref);
  };
  auto pdf = [&](const Vec3& w) -> double {
    double sum = 0.0;
    float t_min = 0.f;
    for (int k = 0; k < 2; ++k) {
      auto t = q.intersect(Ray{ref, w}, t_min, Infinity);
      if (!t) break;
      Quadric::Surface s = q.surface_at(Ray{ref, w}, *t);
      sum += q.pdf_solid_angle(ctx, w, s.p, s.n);
      t_min = *t * (1.f + 1e-5f);
    }
    return pdf_scale * sum;
  };
  SphereChart chart;  // the default 6 levels of refinement find the shapes' edges inside cells
  ChiSquareResult r = chi_square_sphere(sample, pdf, 1000000, 40, 80, 23, chart);
  EXPECT_EQ(mismatched, 0) << "samples whose wi or distance does not match their point (ShapeSample)";
  return r;
}

}  // namespace

// The solid angle a shape covers, counted with multiplicity (a ray can cross a cylinder twice), two
// independent ways: the mean of 1 / pdf over the shape's solid-angle samples, and 4 pi times the mean
// number of crossings of uniformly distributed directions (found by the shape's intersect()). Both
// use jittered 300 x 300 grids of random numbers; 16 independent replicas give the standard errors.
// Returns the ratio and its standard error.
struct Moment {
  double ratio, sigma;
};
Moment solid_angle_moment(const Quadric& q, const Vec3& ref, double pdf_scale = 1.0) {
  constexpr int kGrid = 300, kReplicas = 16;
  ShapeSampleContext ctx{ref, Vec3(0.f)};
  Pcg32 rng(31);
  std::vector<double> by_pdf(kReplicas, 0.0), by_rays(kReplicas, 0.0);
  for (int r = 0; r < kReplicas; ++r)
    for (int i = 0; i < kGrid; ++i)
      for (int j = 0; j < kGrid; ++j) {
        Vec2 u((i + rng.next_float()) / kGrid, (j + rng.next_float()) / kGrid);
        auto s = q.sample_solid_angle(ctx, u);
        by_pdf[r] += s ? 1.0 / (pdf_scale * s->pdf) : 0.0;
        Vec3 w = sample_uniform_sphere(Vec2((i + rng.next_float()) / kGrid, (j + rng.next_float()) / kGrid));
        float t_min = 0.f;
        for (int hits = 0; hits < 2; ++hits) {
          auto t = q.intersect(Ray{ref, w}, t_min, Infinity);
          if (!t) break;
          by_rays[r] += 4.0 * kPi;
          t_min = *t * (1.f + 1e-5f);
        }
      }
  auto mean_and_error = [&](std::vector<double>& v) {
    double m = 0.0, m2 = 0.0;
    for (double& x : v) {
      x /= double(kGrid) * kGrid;
      m += x / kReplicas;
    }
    for (double x : v) m2 += (x - m) * (x - m);
    return std::pair{m, std::sqrt(m2 / (kReplicas - 1) / kReplicas)};
  };
  auto [a, sa] = mean_and_error(by_pdf);
  auto [b, sb] = mean_and_error(by_rays);
  return {a / b, a / b * std::sqrt(sa * sa / (a * a) + sb * sb / (b * b))};
}

// Solid-angle sampling, two ways. Chi-square against the pdf needs smooth outlines in direction space
// (the harness integrates the pdf over each cell from interior points, and a partial shape's corner
// can put a sliver of samples where none of them look): a whole cylinder seen from inside. The moment
// test takes any shape: an annulus sector under the skewed transform, a cylinder sector from outside
// (rays crossing it twice), each within 4 standard errors; the pdf 2 % off fails it.
TEST(QuadricShapes, SolidAngleSamplingMatchesPdfByChiSquareAndMoments) {
  Mat4 m = glm::rotate(glm::translate(Mat4(1.f), Vec3(0.2f, 0.f, 1.f)), 0.4f, Vec3(1, 0, 0));
  Cylinder cylinder(m, false, 0.8f, -0.6f, 0.9f, 360.f);
  ChiSquareResult c = test_solid_angle_sampling(cylinder, apply(m, {0.1, -0.2, 0.1}));
  std::printf("[ chi2     ] cylinder from inside: %s\n", c.summary().c_str());
  EXPECT_TRUE(c.passes(kAlpha)) << c.summary();
  EXPECT_NEAR(c.pdf_integral, 1.0, 2e-3);

  Disk annulus(skewed_transform(), false, 0.25f, 1.f, 0.4f, 270.f);
  Cylinder sector(m, false, 0.8f, -0.6f, 0.9f, 200.f);
  struct Case {
    const char* name;
    const Quadric* shape;
    Vec3 ref;
  };
  for (const Case& k : {Case{"annulus sector", &annulus, Vec3(0.1f, 0.2f, -0.5f)},
                        Case{"cylinder sector from outside", &sector, apply(m, {2.0, 0.5, 0.3})}}) {
    Moment good = solid_angle_moment(*k.shape, k.ref), bad = solid_angle_moment(*k.shape, k.ref, 1.02);
    std::printf("[ measured ] %s: E[1/pdf] / (4 pi E[crossings]) = %.5f +- %.5f; pdf 2 %% high: %.5f\n", k.name,
                good.ratio, good.sigma, bad.ratio);
    EXPECT_LT(std::abs(good.ratio - 1.0), 4.0 * good.sigma) << k.name;
    EXPECT_GT(std::abs(bad.ratio - 1.0), 4.0 * bad.sigma) << k.name;
  }
}

// By area, on partial shapes: sampled points moved back to object space, as (fraction of r^2 between
// the radii, fraction of phimax) on an annulus sector and (fraction of the height, fraction of
// phimax) on a cylinder sector, must be uniform on the unit square.
TEST(QuadricShapes, PartialShapesAreSampledUniformlyByArea) {
  const Mat4 m = skewed_transform();
  const glm::mat4 to_object = glm::inverse(m);
  Disk disk(m, false, 0.25f, 1.f, 0.4f, 270.f);
  Cylinder cylinder(m, false, 0.7f, -0.5f, 0.8f, 300.f);
  auto phi_of = [](const Vec3& p) {
    double phi = std::atan2(p.y, p.x);
    return phi < 0 ? phi + 2 * kPi : phi;
  };
  auto disk_params = [&](Vec2 u, float) -> std::optional<Vec2> {
    Vec3 p = Vec3(to_object * Vec4(disk.sample_area(u).p, 1.f));
    double r2 = double(p.x) * p.x + double(p.y) * p.y;
    return Vec2(float((r2 - 0.16) / (1.0 - 0.16)), float(phi_of(p) / (1.5 * kPi)));
  };
  auto cylinder_params = [&](Vec2 u, float) -> std::optional<Vec2> {
    Vec3 p = Vec3(to_object * Vec4(cylinder.sample_area(u).p, 1.f));
    return Vec2(float((p.z + 0.5) / 1.3), float(phi_of(p) / (300.0 / 180.0 * kPi)));
  };
  auto uniform = [](const Vec2&) { return 1.0; };
  for (auto [name, sampler] : {std::pair<const char*, PlaneSampler>{"annulus sector", disk_params},
                               std::pair<const char*, PlaneSampler>{"cylinder sector", cylinder_params}}) {
    ChiSquareResult r = chi_square_plane(sampler, uniform, 200000, 20, 20, 5);
    std::printf("[ chi2     ] %s: %s\n", name, r.summary().c_str());
    EXPECT_TRUE(r.passes(kAlpha)) << name << ": " << r.summary();
  }
  // Negative control: r uniform instead of r^2 (a common mistake) is far from uniform by area.
  auto wrong = [&](Vec2 u, float) -> std::optional<Vec2> {
    double r = 0.4 + 0.6 * u.x;
    return Vec2(float((r * r - 0.16) / (1.0 - 0.16)), u.y);
  };
  EXPECT_LT(chi_square_plane(wrong, uniform, 200000, 20, 20, 5).p_value, 1e-6);
}

namespace {

// Mean of an 8x8 render looking straight at the point at the origin of a diffuse floor (reflectance
// 0.5, direct light only) through a 2-degree field of view: (0.5 / pi) E.
double floor_radiance(const std::string& light_block, const std::string& name) {
  std::string scene = R"(
LookAt 0 0 0.3  0 0 0  0 1 0
Camera "perspective" "float fov" [ 2 ]
Film "rgb" "integer xresolution" [ 8 ] "integer yresolution" [ 8 ]
PixelFilter "box"
Sampler "sobol" "integer pixelsamples" [ 1024 ]
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "disk" "float radius" [ 0.05 ]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 1 1 1 ]
)" + light_block + "\nAttributeEnd\n";
  RenderSettings s;
  s.scene_file = write_file(temp_dir(name), "scene.pbrt", scene);
  s.quiet = true;
  RenderResult r = render(s);
  EXPECT_EQ(count_nonfinite(r.image), 0);
  return mean_channel(r.image, 1);
}

}  // namespace

// Irradiance at the floor's centre in closed form: an annulus (radii r1 < r2) a height h above,
// facing down, gives E = pi L (r2^2 / (h^2 + r2^2) - r1^2 / (h^2 + r1^2)); from the axis of a
// cylinder of radius R rising a height H above the floor, emitting inwards, E = pi L H^2 / (H^2 + R^2)
// (the directions from theta = atan(R / H) to the horizon). The image is (0.5 / pi) E up to its
// variation across the 2-degree view (below 1e-4 here). Tolerance 1 %; the pixel estimates' spread
// puts the mean's standard error near 0.1 %.
TEST(QuadricShapes, DiskAndCylinderAreaLightsGiveClosedFormIrradiance) {
  double annulus = floor_radiance("Translate 0 0 1\nReverseOrientation\nShape \"disk\" \"float radius\" [ 1 ] "
                                  "\"float innerradius\" [ 0.5 ]",
                                  "quadric-annulus");
  double annulus_expected = 0.5 * (1.0 / 2.0 - 0.25 / 1.25);
  double cylinder = floor_radiance("ReverseOrientation\nShape \"cylinder\" \"float radius\" [ 1 ] \"float zmin\" [ 0 ] "
                                   "\"float zmax\" [ 2 ]",
                                   "quadric-cylinder");
  double cylinder_expected = 0.5 * 4.0 / 5.0;
  std::printf("[ measured ] annulus %.5f (expected %.5f), cylinder %.5f (expected %.5f)\n", annulus, annulus_expected,
              cylinder, cylinder_expected);
  EXPECT_NEAR(annulus / annulus_expected, 1.0, 0.01);
  EXPECT_NEAR(cylinder / cylinder_expected, 1.0, 0.01);
  // Negative control: facing away (no ReverseOrientation), a one-sided disk lights nothing.
  EXPECT_EQ(floor_radiance("Translate 0 0 1\nShape \"disk\" \"float radius\" [ 1 ]", "quadric-away"), 0.0);
}

// The scene builder: uv and orientation at a hit through Embree, and located errors for bad
// parameters and for an unevenly stretched cylinder area light.
TEST(QuadricShapes, SceneBuilderTracesThemAndReportsBadInput) {
  Registry registry(Registry::default_search_dirs());
  SceneDescription d = parse_scene_string(R"(WorldBegin
AttributeBegin
  Translate 0 0 2
  ReverseOrientation
  Shape "disk" "float radius" [ 2 ] "float innerradius" [ 1 ]
AttributeEnd
Shape "cylinder" "float radius" [ 0.5 ] "float zmin" [ -1 ] "float zmax" [ 1 ]
)");
  BuiltScene b = build_scene(d, registry);
  // Down onto the annulus at radius 1.5 on the +y side: phi = 90 degrees, v = (2 - 1.5) / (2 - 1).
  auto hit = b.scene->intersect(Ray{Vec3(0, 1.5f, 5), Vec3(0, 0, -1)});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->p.z, 2.f, 1e-6f);
  EXPECT_NEAR(hit->ng.z, -1.f, 1e-6f);  // reversed: faces down
  EXPECT_NEAR(hit->uv.x, 0.25f, 1e-5f);
  EXPECT_NEAR(hit->uv.y, 0.5f, 1e-5f);
  // From the -x side the cylinder at phi = 180 degrees, z = 0.5; straight down the axis, through the
  // annulus's hole and the open cylinder, nothing.
  hit = b.scene->intersect(Ray{Vec3(-3, 0, 0.5f), Vec3(1, 0, 0)});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->p.x, -0.5f, 1e-6f);
  EXPECT_NEAR(hit->ng.x, -1.f, 1e-6f);  // outward
  EXPECT_NEAR(hit->uv.x, 0.5f, 1e-5f);
  EXPECT_NEAR(hit->uv.y, 0.75f, 1e-5f);
  EXPECT_FALSE(b.scene->intersect(Ray{Vec3(0, 0, 5), Vec3(0, 0, -1)}));
  EXPECT_TRUE(b.scene->occluded(Ray{Vec3(-3, 0, 0.5f), Vec3(1, 0, 0), 10.f}));

  std::string dir = temp_dir("quadric-errors");
  auto expect_error = [&](const std::string& shape, const std::string& where, const std::string& what) {
    std::string scene = "Camera \"perspective\"\nWorldBegin\n" + shape + "\n";
    auto r = run_penumbra({"render", write_file(dir, "scene.pbrt", scene), "-o", dir + "/o.exr", "-q"});
    EXPECT_EQ(r.exit_code, 1) << shape;
    EXPECT_NE(r.err.find("scene.pbrt:" + where + ": error:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
  };
  expect_error("Shape \"disk\" \"float innerradius\" [ 2 ]", "3:14", "innerradius must be in [0, radius)");
  expect_error("Shape \"cylinder\" \"float zmin\" [ 1 ] \"float zmax\" [ 1 ]", "3:37", "zmin and zmax must differ");
  expect_error("Shape \"disk\" \"float phimax\" [ 400 ]", "3:14", "phimax must be in (0, 360]");
  expect_error("Scale 2 1 1\nAreaLightSource \"diffuse\"\nShape \"cylinder\"", "5:1", "stretches its cross-section");
}
