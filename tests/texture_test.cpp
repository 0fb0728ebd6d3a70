// The procedural texture plugins and the 2D mappings against closed-form answers. Textures are made
// the way a scene makes them (Texture directives, built by the scene builder), so names, types and
// references to other textures go through the same resolution as in a render.
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "scene/scene_builder.h"

#include <penumbra/plugin.h>
#include <penumbra/texture_mapping.h>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <fmt/core.h>

#include <cmath>

using namespace penumbra;

namespace {

// Textures of a scene made of `directives` (placed after WorldBegin).
struct Textures {
  Registry registry{Registry::default_search_dirs()};
  BuiltScene built;
  explicit Textures(const std::string& directives) {
    SceneDescription d = parse_scene_string("WorldBegin\n" + directives, "textures.pbrt");
    d.film.params.set_int("xresolution", 4);
    d.film.params.set_int("yresolution", 4);
    built = build_scene(d, registry);
  }
  const FloatTexture& f(const std::string& name) const {
    const FloatTexture* t = built.texture_table.find_float(name);
    if (!t) throw std::runtime_error("no float texture " + name);
    return *t;
  }
  const SpectrumTexture& s(const std::string& name) const {
    const SpectrumTexture* t = built.texture_table.find_spectrum(name);
    if (!t) throw std::runtime_error("no spectrum texture " + name);
    return *t;
  }
};

TextureEvalContext at_uv(float u, float v, float dudx = 0.f, float dvdy = 0.f) {
  TextureEvalContext c;
  c.uv = Vec2(u, v);
  c.dudx = dudx;
  c.dvdy = dvdy;
  return c;
}

void expect_rgb_near(const Rgb& got, const Rgb& want, float tol) {
  EXPECT_NEAR(got.r, want.r, tol);
  EXPECT_NEAR(got.g, want.g, tol);
  EXPECT_NEAR(got.b, want.b, tol);
}

}  // namespace

TEST(Textures, ConstantGivesItsValue) {
  Textures t(R"(Texture "f" "float" "constant" "float value" [ 0.3 ]
Texture "s" "spectrum" "constant" "rgb value" [ 0.1 0.2 0.4 ]
Texture "d" "float" "constant")");
  EXPECT_FLOAT_EQ(t.f("f").evaluate(at_uv(0.7f, 0.2f)), 0.3f);
  expect_rgb_near(t.s("s").evaluate(at_uv(0.1f, 0.9f)), Rgb(0.1f, 0.2f, 0.4f), 0.f);
  EXPECT_FLOAT_EQ(t.f("d").evaluate(at_uv(0.f, 0.f)), 1.f);  // pbrt-v4's default value
}

TEST(Textures, FloatAndSpectrumTexturesHaveSeparateNames) {
  Textures t(R"(Texture "x" "float" "constant" "float value" [ 0.25 ]
Texture "x" "spectrum" "constant" "rgb value" [ 0.5 0.5 0.5 ])");
  EXPECT_FLOAT_EQ(t.f("x").evaluate(at_uv(0.f, 0.f)), 0.25f);
  EXPECT_FLOAT_EQ(t.s("x").evaluate(at_uv(0.f, 0.f)).g, 0.5f);
}

TEST(Textures, ScaleMultipliesATextureByAFloatTexture) {
  Textures t(R"(Texture "half" "float" "constant" "float value" [ 0.5 ]
Texture "c" "spectrum" "constant" "rgb value" [ 0.2 0.4 0.8 ]
Texture "sc" "spectrum" "scale" "texture tex" "c" "texture scale" "half"
Texture "fs" "float" "scale" "float tex" [ 3 ] "float scale" [ 0.25 ])");
  expect_rgb_near(t.s("sc").evaluate(at_uv(0.f, 0.f)), Rgb(0.1f, 0.2f, 0.4f), 1e-7f);
  EXPECT_FLOAT_EQ(t.f("fs").evaluate(at_uv(0.f, 0.f)), 0.75f);
}

TEST(Textures, MixWeighsTex2ByAmount) {
  Textures t(R"(Texture "amt" "float" "constant" "float value" [ 0.25 ]
Texture "m" "spectrum" "mix" "rgb tex1" [ 1 0 0 ] "rgb tex2" [ 0 0 1 ] "texture amount" "amt"
Texture "d" "float" "mix")");
  expect_rgb_near(t.s("m").evaluate(at_uv(0.f, 0.f)), Rgb(0.75f, 0.f, 0.25f), 1e-7f);
  EXPECT_FLOAT_EQ(t.f("d").evaluate(at_uv(0.f, 0.f)), 0.5f);  // defaults: 0 and 1, amount 0.5
}

// |n . dir| weighs tex1; dir is given in the directive's space (rotated here from +x to +y).
TEST(Textures, DirectionMixWeighsByTheNormalsAlignment) {
  Textures t(R"(AttributeBegin
Rotate 90 0 0 1
Texture "dm" "float" "directionmix" "float tex1" [ 1 ] "float tex2" [ 0 ] "vector3 dir" [ 1 0 0 ]
AttributeEnd)");
  TextureEvalContext c;
  c.n = Vec3(0.f, std::cos(radians(60.f)), std::sin(radians(60.f)));  // 60 degrees from +y
  EXPECT_NEAR(t.f("dm").evaluate(c), 0.5f, 1e-6f);
  c.n = Vec3(0.f, -1.f, 0.f);
  EXPECT_NEAR(t.f("dm").evaluate(c), 1.f, 1e-6f);
  c.n = Vec3(1.f, 0.f, 0.f);
  EXPECT_NEAR(t.f("dm").evaluate(c), 0.f, 1e-6f);
}

TEST(Textures, BilerpInterpolatesItsCorners) {
  Textures t(R"(Texture "b" "float" "bilerp" "float v00" [ 1 ] "float v10" [ 2 ] "float v01" [ 3 ] "float v11" [ 5 ])");
  float s = 0.25f, u = 0.75f;
  float want = (1 - s) * (1 - u) * 1 + s * (1 - u) * 2 + (1 - s) * u * 3 + s * u * 5;
  EXPECT_NEAR(t.f("b").evaluate(at_uv(s, u)), want, 1e-6f);
  EXPECT_NEAR(t.f("b").evaluate(at_uv(1.f, 1.f)), 5.f, 1e-6f);
}

// Without a footprint the checkerboard is exact: tex1 where floor(s) + floor(t) is even.
TEST(Textures, CheckerboardSquaresAlternate) {
  Textures t(R"(Texture "c" "float" "checkerboard" "float tex1" [ 0.9 ] "float tex2" [ 0.1 ]
    "float uscale" [ 4 ] "float vscale" [ 2 ])");
  EXPECT_FLOAT_EQ(t.f("c").evaluate(at_uv(0.1f, 0.2f)), 0.9f);   // s = 0.4, t = 0.4
  EXPECT_FLOAT_EQ(t.f("c").evaluate(at_uv(0.3f, 0.2f)), 0.1f);   // s = 1.2
  EXPECT_FLOAT_EQ(t.f("c").evaluate(at_uv(0.3f, 0.7f)), 0.9f);   // s = 1.2, t = 1.4
  EXPECT_FLOAT_EQ(t.f("c").evaluate(at_uv(-0.1f, 0.2f)), 0.1f);  // s = -0.4: floor -1
}

// The mean over a region of whole and half squares, by a midpoint rule fine enough to be exact up
// to float rounding (cell edges fall between sample points). A 1 % brighter tex1 would miss by
// 5e-3, far outside the 1e-5 tolerance.
TEST(Textures, CheckerboardMeanOverARegion) {
  Textures t(R"(Texture "c" "float" "checkerboard" "float tex1" [ 1 ] "float tex2" [ 0.2 ])");
  const int n = 400;
  double sum = 0.0;
  // s in [0, 2.5], t in [0, 1]: squares (0,0) (2,0) and half of (2,0)'s row: 1.5 units of tex1, 1 of tex2.
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) sum += t.f("c").evaluate(at_uv(2.5f * (i + 0.5f) / n, (j + 0.5f) / n));
  double mean = sum / (double(n) * n), want = (1.5 * 1.0 + 1.0 * 0.2) / 2.5;
  EXPECT_NEAR(mean, want, 1e-5);
  EXPECT_GT(std::abs(mean * 1.01 - want), 1e-5);  // negative control
}

// With a footprint the pattern is filtered by a triangle of half-width r = 1.5 * footprint: at a
// square's centre with r = 1 along s, 3/4 of the filter's weight lies in the square and 1/8 in each
// neighbour, so the square wave's filtered value is 1/2 and the tex2 weight 1/4.
TEST(Textures, CheckerboardFilteredOverTheFootprint) {
  Textures t(R"(Texture "c" "float" "checkerboard" "float tex1" [ 1 ] "float tex2" [ 0 ])");
  EXPECT_NEAR(t.f("c").evaluate(at_uv(0.5f, 0.5f, 1.f / 1.5f, 0.f)), 0.75f, 1e-6f);
  // A footprint much wider than a square averages the pattern.
  EXPECT_NEAR(t.f("c").evaluate(at_uv(0.5f, 0.5f, 40.f, 40.f)), 0.5f, 0.01f);
}

TEST(Textures, SpectrumCheckerboardOfTextures) {
  Textures t(R"(Texture "red" "spectrum" "constant" "rgb value" [ 1 0 0 ]
Texture "c" "spectrum" "checkerboard" "texture tex1" "red" "rgb tex2" [ 0 0 1 ])");
  expect_rgb_near(t.s("c").evaluate(at_uv(0.5f, 0.5f)), Rgb(1, 0, 0), 0.f);
  expect_rgb_near(t.s("c").evaluate(at_uv(1.5f, 0.5f)), Rgb(0, 0, 1), 0.f);
}

// ---- mappings -----------------------------------------------------------------------------

namespace {

TexCoord2D map_with(const std::string& params_text, const Mat4& to_world, const TextureEvalContext& c) {
  SceneDescription d = parse_scene_string("WorldBegin\nMaterial \"diffuse\" " + params_text, "m.pbrt");
  CreateContext ctx{d.materials[0].params, {}, "", to_world};
  return TextureMapping2D::create(ctx).map(c);
}

// Finite-difference check of a mapping's (s, t) derivatives along dpdx and dpdy.
void expect_derivatives_match(const std::string& params_text, const Mat4& to_world, const Vec3& p) {
  TextureEvalContext c;
  c.p = p;
  c.dpdx = Vec3(0.01f, 0.004f, -0.003f);
  c.dpdy = Vec3(-0.002f, 0.006f, 0.008f);
  TexCoord2D m = map_with(params_text, to_world, c);
  const float h = 0.01f;
  TextureEvalContext cx = c, cy = c;
  cx.p = p + h * c.dpdx;
  cy.p = p + h * c.dpdy;
  Vec2 sx = (map_with(params_text, to_world, cx).st - m.st) / h;
  Vec2 sy = (map_with(params_text, to_world, cy).st - m.st) / h;
  EXPECT_NEAR(m.dsdx, sx.x, 2e-3f * (1.f + std::abs(sx.x)));
  EXPECT_NEAR(m.dtdx, sx.y, 2e-3f * (1.f + std::abs(sx.y)));
  EXPECT_NEAR(m.dsdy, sy.x, 2e-3f * (1.f + std::abs(sy.x)));
  EXPECT_NEAR(m.dtdy, sy.y, 2e-3f * (1.f + std::abs(sy.y)));
}

}  // namespace

TEST(TextureMappings, UvScalesAndOffsets) {
  TextureEvalContext c = at_uv(0.3f, 0.6f, 0.01f, 0.02f);
  c.dudy = 0.005f;
  TexCoord2D m = map_with(R"("float uscale" [ 2 ] "float vscale" [ 3 ] "float udelta" [ 0.1 ] "float vdelta" [ -0.5 ])",
                          Mat4(1.f), c);
  EXPECT_NEAR(m.st.x, 2 * 0.3f + 0.1f, 1e-6f);
  EXPECT_NEAR(m.st.y, 3 * 0.6f - 0.5f, 1e-6f);
  EXPECT_NEAR(m.dsdx, 0.02f, 1e-7f);
  EXPECT_NEAR(m.dsdy, 0.01f, 1e-7f);
  EXPECT_NEAR(m.dtdy, 0.06f, 1e-7f);
}

// pbrt-v4's spherical mapping: s = theta / pi, t = phi / 2pi in texture space (here translated).
TEST(TextureMappings, SphericalAroundTheTextureSpaceOrigin) {
  Mat4 to_world = glm::translate(Mat4(1.f), Vec3(1.f, 2.f, 3.f));
  TextureEvalContext c;
  c.p = Vec3(1.f, 2.f, 3.f) + 2.f * Vec3(0.f, 1.f, 1.f) / std::sqrt(2.f);  // theta 45, phi 90 degrees
  TexCoord2D m = map_with(R"("string mapping" "spherical")", to_world, c);
  EXPECT_NEAR(m.st.x, 0.25f, 1e-6f);
  EXPECT_NEAR(m.st.y, 0.25f, 1e-6f);
  expect_derivatives_match(R"("string mapping" "spherical")", to_world, Vec3(0.3f, 2.4f, 3.2f));
}

TEST(TextureMappings, CylindricalAroundZ) {
  TextureEvalContext c;
  c.p = Vec3(0.f, -1.f, 0.3f);  // atan2(-1, 0) = -pi/2
  TexCoord2D m = map_with(R"("string mapping" "cylindrical")", Mat4(1.f), c);
  EXPECT_NEAR(m.st.x, 0.25f, 1e-6f);
  EXPECT_NEAR(m.st.y, 0.3f, 1e-6f);
  expect_derivatives_match(R"("string mapping" "cylindrical")", Mat4(1.f), Vec3(0.4f, -0.7f, 0.2f));
}

TEST(TextureMappings, PlanarProjectsOntoItsAxes) {
  TextureEvalContext c;
  c.p = Vec3(0.3f, 5.f, 0.7f);
  const char* params = R"("string mapping" "planar" "vector3 v1" [ 1 0 0 ] "vector3 v2" [ 0 0 2 ] "float udelta" [ 0.1 ] "float vdelta" [ 0.2 ])";
  TexCoord2D m = map_with(params, Mat4(1.f), c);
  EXPECT_NEAR(m.st.x, 0.4f, 1e-6f);
  EXPECT_NEAR(m.st.y, 1.6f, 1e-6f);
  expect_derivatives_match(params, Mat4(1.f), c.p);
}

TEST(TextureMappings, UnknownMappingIsALocatedError) {
  try {
    map_with(R"("string mapping" "cubic")", Mat4(1.f), TextureEvalContext{});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.loc().line, 2);
    EXPECT_EQ(e.loc().column, 20);
    EXPECT_NE(std::string(e.what()).find("unknown texture mapping 'cubic'; available: uv, spherical, cylindrical, planar"),
              std::string::npos);
  }
}
