// Bump maps (pbrt-v4's "texture displacement" on a material): the core tilts the shading normal by the
// displacement's finite-difference derivatives, for every material alike.
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "scene/scene_builder.h"
#include "scene/surface_detail.h"

#include <gtest/gtest.h>

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

using namespace penumbra;

namespace {

// A flat quad 4 x 4 in z = 0 with uv 0..1 (dp/du = (4, 0, 0), dp/dv = (0, 4, 0)) seen head-on, whose
// material is bumped by d = a u: a bilerp texture with v10 = v11 = a is exactly linear in u, so the
// finite difference is exact whatever its step.
BuiltScene ramp_quad(Registry& registry, float a, const std::string& material = "diffuse") {
  SceneDescription d = parse_scene_string(fmt::format(R"(LookAt 0 0 -5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 90 ]
Film "rgb" "integer xresolution" [ 100 ] "integer yresolution" [ 100 ]
WorldBegin
Texture "ramp" "float" "bilerp" "float v00" [ 0 ] "float v10" [ {} ] "float v01" [ 0 ] "float v11" [ {} ]
Material "{}" "texture displacement" "ramp"
Shape "trianglemesh" "point3 P" [ -2 -2 0  2 -2 0  2 2 0  -2 2 0 ] "integer indices" [ 0 1 2  0 2 3 ]
    "point2 uv" [ 0 0  1 0  1 1  0 1 ]
)",
                                                      a, a, material),
                                          "ramp.pbrt");
  return build_scene(d, registry);
}

// dp/du' = (4, 0, 0) + a ng and dp/dv' = (0, 4, 0), ng = (0, 0, s): their cross product (-4 a s^2, 0,
// 16 s) / |.| flipped to ng's side is (-a, 0, 4 s) / sqrt(a^2 + 16): tilted by atan(a / |dp/du|) = atan(a / 4)
// away from +u.
Vec3 expected_ramp_normal(float a, float s) { return Vec3(-a, 0.f, 4.f * s) / std::sqrt(a * a + 16.f); }

float max_diff(const Vec3& x, const Vec3& y) {
  Vec3 d = glm::abs(x - y);
  return std::max({d.x, d.y, d.z});
}

}  // namespace

TEST(BumpMap, LinearRampTiltsTheNormalByAtanOfTheSlope) {
  Registry registry(Registry::default_search_dirs());
  for (const char* material : {"diffuse", "conductor", "coateddiffuse"}) {
    SCOPED_TRACE(material);
    for (float a : {0.5f, 2.f}) {
      BuiltScene b = ramp_quad(registry, a, material);
      for (Vec2 xy : {Vec2(0.f), Vec2(0.7f, -0.3f)}) {
        auto si = b.scene->intersect(Ray{Vec3(xy, -5.f), Vec3(0.f, 0.f, 1.f)});
        ASSERT_TRUE(si.has_value());
        float s = si->ng.z > 0.f ? 1.f : -1.f;
        Vec3 want = expected_ramp_normal(a, s);
        EXPECT_LT(max_diff(si->ns, want), 1e-4f) << si->ns.x << " " << si->ns.z;
        EXPECT_NEAR(std::acos(glm::dot(si->ns, si->ng)), std::atan(a / 4.f), 1e-4f);
        // The frame: n is the bumped normal, s the bumped dp/du's direction (4, 0, a s) / |.|.
        EXPECT_LT(max_diff(si->shading.n, want), 1e-6f);
        EXPECT_LT(max_diff(si->shading.s, Vec3(4.f, 0.f, a * s) / std::sqrt(16.f + a * a)), 1e-4f);
        EXPECT_LT(max_diff(si->shading.t, glm::cross(si->shading.n, si->shading.s)), 1e-6f);
        // Negative control: a slope 2 % steeper is outside the tolerance.
        EXPECT_GT(max_diff(si->ns, expected_ramp_normal(1.02f * a, s)), 1e-4f);
      }
    }
  }
}

TEST(BumpMap, WithoutDisplacementTheNormalAndTangentAreTheSurfaces) {
  Registry registry(Registry::default_search_dirs());
  BuiltScene b = ramp_quad(registry, 0.f);
  auto si = b.scene->intersect(Ray{Vec3(0.1f, 0.2f, -5.f), Vec3(0.f, 0.f, 1.f)});
  ASSERT_TRUE(si.has_value());
  EXPECT_LT(max_diff(si->ns, si->ng), 1e-6f);
  EXPECT_LT(max_diff(si->shading.s, Vec3(1.f, 0.f, 0.f)), 1e-6f);  // along dp/du
}

namespace {

// d(u, v) = A sin(2 pi k u) + B v, evaluated in double and rounded once.
class SineBump final : public FloatTexture {
 public:
  SineBump(double amplitude, double k, double b) : a_(amplitude), k_(k), b_(b) {}
  float evaluate(const TextureEvalContext& ctx) const override {
    return static_cast<float>(a_ * std::sin(2.0 * M_PI * k_ * double(ctx.uv.x)) + b_ * double(ctx.uv.y));
  }
  double slope_u(double u) const { return a_ * 2.0 * M_PI * k_ * std::cos(2.0 * M_PI * k_ * u); }

 private:
  double a_, k_, b_;
};

}  // namespace

// On a flat patch (n = z, dp/du = (L, 0, 0), dp/dv = (0, L, 0)) the bumped normal is
// (-d_u, -d_v L / L, L) / |.| with d_u = dd/du = 2 pi k A cos(2 pi k u) and d_v = B, up to the forward
// difference's error: its step du = (|du/dx| + |du/dy|) / 2 = 1e-4 gives a truncation error of at most
// du / 2 max|d''| = 0.5e-4 (2 pi k)^2 A = 2.0e-5 for A = 0.01, k = 1, and float rounding of d (half an
// ulp of values below 0.03, 9.3e-10, twice, over du) adds 1.9e-5: 4e-5 on the slope, and on the normal at
// most that over L = 1. The tolerance is 5e-5; a 2 % larger amplitude (slope off by up to 1.3e-3) fails it.
TEST(BumpMap, SinusoidalBumpFollowsTheAnalyticDerivative) {
  const float L = 1.f;
  ShadingGeometry g{Vec3(0.f, 0.f, 1.f), Vec3(L, 0.f, 0.f), Vec3(0.f, L, 0.f)};
  SineBump bump(0.01, 1.0, 0.003), steeper(0.0102, 1.0, 0.003);
  auto normal_of = [&](const SineBump& tex, float u) {
    TextureEvalContext ctx;
    ctx.p = Vec3(u * L, 0.3f * L, 0.f);
    ctx.n = g.n;
    ctx.uv = Vec2(u, 0.3f);
    ctx.dudx = 1.5e-4f, ctx.dudy = -0.5e-4f;  // du = 1e-4
    ctx.dvdx = 0.f, ctx.dvdy = 2e-4f;         // dv = 1e-4
    Vec3 dpdu, dpdv;
    bump_map(TexturedFloat(&tex), ctx, g, &dpdu, &dpdv);
    return glm::normalize(glm::cross(dpdu, dpdv));
  };
  float worst = 0.f, control_best = 1.f;
  for (int i = 0; i < 16; ++i) {
    float u = (i + 0.25f) / 16.f;
    double du = bump.slope_u(u), dv = 0.003;
    Vec3 want = glm::normalize(Vec3(float(-du * L / L), float(-dv), L));
    worst = std::max(worst, max_diff(normal_of(bump, u), want));
    if (std::abs(std::cos(2.0 * M_PI * u)) > 0.5)
      control_best = std::min(control_best, max_diff(normal_of(steeper, u), want));
  }
  EXPECT_LT(worst, 5e-5f);
  EXPECT_GT(control_best, 5e-5f);
}

// With no footprint (du/dx ... zero) the step is pbrt-v4's 0.0005 in u and v.
TEST(BumpMap, ZeroFootprintUsesTheDefaultStep) {
  struct Step final : public FloatTexture {
    float evaluate(const TextureEvalContext& ctx) const override { return ctx.uv.x >= 0.50049f ? 1.f : 0.f; }
  } step;
  ShadingGeometry g{Vec3(0.f, 0.f, 1.f), Vec3(1.f, 0.f, 0.f), Vec3(0.f, 1.f, 0.f)};
  TextureEvalContext ctx;
  ctx.uv = Vec2(0.5f, 0.5f);
  Vec3 dpdu, dpdv;
  bump_map(TexturedFloat(&step), ctx, g, &dpdu, &dpdv);
  EXPECT_NEAR(dpdu.z, 1.f / 0.0005f, 1.f);  // the shifted lookup at u + 0.0005 saw the step
  EXPECT_EQ(dpdv.z, 0.f);
}

// A sphere bumped by a constant keeps its normals (pbrt-v4's d dn/du terms scale dp/du and dp/dv
// alike); its frame's s follows dp/du (the direction of growing phi).
TEST(BumpMap, SphereFrameFollowsDpdu) {
  Registry registry(Registry::default_search_dirs());
  SceneDescription d = parse_scene_string(R"(LookAt 0 -5 0  0 0 0  0 0 1
Camera "perspective"
WorldBegin
Texture "bumps" "float" "constant" "float value" [ 0.01 ]
Material "diffuse" "texture displacement" "bumps"
Shape "sphere" "float radius" [ 1 ]
)",
                                          "sphere.pbrt");
  BuiltScene b = build_scene(d, registry);
  auto si = b.scene->intersect(Ray{Vec3(0.f, -5.f, 0.3f), Vec3(0.f, 1.f, 0.f)});
  ASSERT_TRUE(si.has_value());
  // At (x ~ 0, y < 0) dp/du = 2 pi (-y, x, 0) points along +x.
  EXPECT_GT(si->shading.s.x, 0.99f);
  EXPECT_LT(max_diff(si->ns, si->ng), 1e-5f);
}

// A mesh with normals: pbrt-v4 bumps its shading geometry, dp/du made orthogonal to the interpolated
// normal ns (ss = dp/du - (dp/du . ns) ns) and dp/dv = ns x ss. With N = (0.6, 0, 0.8) everywhere and
// d = a u: ss = (4, 0, 0) - 2.4 ns = (2.56, 0, -1.92), ts = ns x ss = (0, 3.2, 0), and the bumped normal
// is normalize((ss + a ns) x ts), on ng's side. Bumping the triangle's own dp/du, dp/dv along ns instead
// gives a normal more than 0.1 away: the control.
TEST(BumpMap, MeshWithNormalsBumpsItsShadingFrame) {
  Registry registry(Registry::default_search_dirs());
  const float a = 0.5f;
  SceneDescription d = parse_scene_string(fmt::format(R"(LookAt 0 0 -5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 90 ]
WorldBegin
Texture "ramp" "float" "bilerp" "float v00" [ 0 ] "float v10" [ {0} ] "float v01" [ 0 ] "float v11" [ {0} ]
Material "diffuse" "texture displacement" "ramp"
Shape "trianglemesh" "point3 P" [ -2 -2 0  2 -2 0  2 2 0  -2 2 0 ] "integer indices" [ 0 1 2  0 2 3 ]
    "point2 uv" [ 0 0  1 0  1 1  0 1 ] "normal N" [ 0.6 0 0.8  0.6 0 0.8  0.6 0 0.8  0.6 0 0.8 ]
)",
                                                      a),
                                          "n.pbrt");
  BuiltScene b = build_scene(d, registry);
  auto si = b.scene->intersect(Ray{Vec3(0.2f, 0.1f, -5.f), Vec3(0.f, 0.f, 1.f)});
  ASSERT_TRUE(si.has_value());
  const Vec3 ns(0.6f, 0.f, 0.8f), ss(2.56f, 0.f, -1.92f), ts = glm::cross(ns, ss);
  EXPECT_LT(max_diff(ts, Vec3(0.f, 3.2f, 0.f)), 1e-6f);
  Vec3 want = glm::normalize(glm::cross(ss + a * ns, ts));
  if (glm::dot(want, si->ng) < 0.f) want = -want;
  EXPECT_LT(max_diff(si->ns, want), 1e-4f);
  Vec3 naive = glm::normalize(glm::cross(Vec3(4.f, 0.f, 0.f) + a * ns, Vec3(0.f, 4.f, 0.f)));
  if (glm::dot(naive, si->ng) < 0.f) naive = -naive;
  EXPECT_GT(max_diff(si->ns, naive), 0.1f);
}
