// Alpha cut-outs on shapes (pbrt-v4's "float alpha" / "texture alpha"): renders of a black quad in
// front of an emitter that fills the view, shadows through cut-out blockers, and emitters whose own
// alpha cuts them out of light sampling.
#include "render/render_session.h"
#include "scene/alpha_cutout.h"
#include "support/command.h"
#include "support/image_stats.h"

#include <gtest/gtest.h>

#include <fmt/core.h>

#include <cmath>

using namespace penumbra;

namespace {

// An orthographic camera sees [-1, 1]^2 of the plane z = 0, where a black quad with uv 0..1 over
// exactly that square carries `alpha`; behind it (z = 1) a larger emitter of radiance 1 faces the
// camera. A box filter and one bounce: every sample is 1 (the emitter) or 0 (the quad).
std::string front_quad(const std::string& alpha, const std::string& textures, int res, int spp,
                       const std::string& shape = "") {
  return fmt::format(R"(LookAt 0 0 -5  0 0 0  0 1 0
Camera "orthographic"
Film "rgb" "integer xresolution" [ {0} ] "integer yresolution" [ {0} ]
PixelFilter "box"
Sampler "independent" "integer pixelsamples" [ {1} ]
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
{2}
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 1 1 1 ]
  Shape "trianglemesh" "point3 P" [ -3 -3 1  -3 3 1  3 3 1  3 -3 1 ] "integer indices" [ 0 1 2  0 2 3 ]
AttributeEnd
Material "diffuse" "rgb reflectance" [ 0 0 0 ]
{3}
)",
                     res, spp, textures,
                     shape.empty() ? "Shape \"trianglemesh\" \"point3 P\" [ -1 -1 0  1 -1 0  1 1 0  -1 1 0 ] "
                                     "\"integer indices\" [ 0 1 2  0 2 3 ] \"point2 uv\" [ 0 0  1 0  1 1  0 1 ] " + alpha
                                   : shape + " " + alpha);
}

ImageRgb render_text(const std::string& name, const std::string& text, uint32_t seed = 7) {
  std::string dir = test::temp_dir(name);
  RenderSettings s;
  s.scene_file = test::write_file(dir, "scene.pbrt", text);
  s.output = dir + "/out.exr";
  s.quiet = true;
  s.seed = seed;
  return render(s).image;
}

}  // namespace

TEST(AlphaCutout, HashIsDeterministicAndUniform) {
  Vec3 o(0.1f, 0.2f, 0.3f), d(0.f, 0.f, 1.f);
  EXPECT_EQ(alpha_hash(o, d, 5), alpha_hash(o, d, 5));
  EXPECT_NE(alpha_hash(o, d, 5), alpha_hash(o, d, 6));
  int below = 0, n = 100000;
  for (int i = 0; i < n; ++i) below += alpha_hash(Vec3(i * 1e-3f, 0.f, 0.f), d, 0) < 0.3f;
  EXPECT_NEAR(below / double(n), 0.3, 4.0 * std::sqrt(0.3 * 0.7 / n));
}

// Alpha 0: every sample sees the emitter, so every pixel is exactly 1 (an opaque quad: exactly 0).
// The same through an alpha texture that is 0 everywhere (the filter path rather than dropping the shape),
// on a sphere and a disk as well as on a mesh.
TEST(AlphaCutout, ZeroAlphaIsInvisible) {
  const char* zero = "Texture \"zero\" \"float\" \"constant\" \"float value\" [ 0 ]";
  ImageRgb a = render_text("alpha-zero", front_quad("\"float alpha\" [ 0 ]", "", 16, 4));
  EXPECT_EQ(test::max_abs_pixel_deviation(a, 1.0), 0.f);
  ImageRgb t = render_text("alpha-zero-tex", front_quad("\"texture alpha\" \"zero\"", zero, 16, 4));
  EXPECT_EQ(test::max_abs_pixel_deviation(t, 1.0), 0.f);
  ImageRgb sphere = render_text("alpha-zero-sphere", front_quad("\"texture alpha\" \"zero\"", zero, 16, 4,
                                                                "Shape \"sphere\" \"float radius\" [ 0.9 ]"));
  EXPECT_EQ(test::max_abs_pixel_deviation(sphere, 1.0), 0.f);
  ImageRgb disk = render_text("alpha-zero-disk", front_quad("\"texture alpha\" \"zero\"", zero, 16, 4,
                                                            "Shape \"disk\" \"float radius\" [ 2 ]"));
  EXPECT_EQ(test::max_abs_pixel_deviation(disk, 1.0), 0.f);
  ImageRgb opaque = render_text("alpha-one", front_quad("\"float alpha\" [ 1 ]", "", 16, 4));  // control
  EXPECT_EQ(test::max_abs_pixel_deviation(opaque, 0.0), 0.f);
}

// Alpha 0.5: each sample sees the emitter with probability 0.5, decided by its ray's hash, so the image
// mean of N = 64 x 64 x 64 Bernoulli(0.5) samples has a standard deviation 0.5 / sqrt(N) = 9.8e-4, 0.20 %
// of 0.5. The tolerance is 4 of those (0.78 %); alpha 0.51 (2 % more emitter) fails it.
TEST(AlphaCutout, HalfAlphaShowsHalfTheEmitter) {
  const double n = 64.0 * 64.0 * 64.0, tol = 4.0 * 0.5 / std::sqrt(n);
  ImageRgb half = render_text("alpha-half", front_quad("\"float alpha\" [ 0.5 ]", "", 64, 64));
  EXPECT_NEAR(test::mean_channel(half, 0), 0.5, tol);
  ImageRgb tex = render_text("alpha-half-tex",
                             front_quad("\"texture alpha\" \"h\"", "Texture \"h\" \"float\" \"constant\" \"float value\" [ 0.5 ]", 64, 64));
  EXPECT_NEAR(test::mean_channel(tex, 0), 0.5, tol);
  // The same through the intersection callbacks of a disk (covering the view) and the filters of a
  // sphere of radius 0.9 (covering f = pi 0.81 / 4 of the view, seen through its two layers, which
  // decide independently: 0.5^2 of the emitter behind it, 1 - 0.75 f in all).
  ImageRgb disk = render_text("alpha-half-disk", front_quad("\"float alpha\" [ 0.5 ]", "", 64, 64,
                                                            "Shape \"disk\" \"float radius\" [ 2 ]"));
  EXPECT_NEAR(test::mean_channel(disk, 0), 0.5, tol);
  ImageRgb sphere = render_text("alpha-half-sphere", front_quad("\"float alpha\" [ 0.5 ]", "", 64, 64,
                                                                "Shape \"sphere\" \"float radius\" [ 0.9 ]"));
  EXPECT_NEAR(test::mean_channel(sphere, 0), 1.0 - 0.75 * Pi * 0.81 / 4.0, tol);
  ImageRgb control = render_text("alpha-half-control", front_quad("\"float alpha\" [ 0.49 ]", "", 64, 64));
  EXPECT_GT(std::abs(test::mean_channel(control, 0) - 0.5), tol);
}

// A 3 x 3 checkerboard alpha (uscale = vscale = 3 over the visible square) with tex1 = 0 on the squares
// where floor(s) + floor(t) is even: 5 of the 9 squares are cut out, and the emitter fills 5 / 9 of the
// image. Alpha is point-sampled (no footprint), so the only noise is where square edges cross pixels
// (63 x 63 pixels: 21 per square, so none do). A board of tex1 = 1 (the complement) shows 4 / 9.
TEST(AlphaCutout, CheckerboardAlphaGivesTheCheckerFraction) {
  auto board = [](int tex1) {
    return fmt::format("Texture \"c\" \"float\" \"checkerboard\" \"float uscale\" [ 3 ] \"float vscale\" [ 3 ] "
                       "\"float tex1\" [ {} ] \"float tex2\" [ {} ]",
                       tex1, 1 - tex1);
  };
  ImageRgb a = render_text("alpha-checks", front_quad("\"texture alpha\" \"c\"", board(0), 63, 4));
  EXPECT_NEAR(test::mean_channel(a, 0), 5.0 / 9.0, 1e-6);
  ImageRgb b = render_text("alpha-checks-complement", front_quad("\"texture alpha\" \"c\"", board(1), 63, 4));
  EXPECT_NEAR(test::mean_channel(b, 0), 4.0 / 9.0, 1e-6);
}

namespace {

// A diffuse floor (the default material, reflectance 0.5) lit by a distant light straight down, seen
// from above, with a black 4 x 4 blocker between them whose shadow covers the floor's middle.
std::string shadow_scene(const std::string& blocker_alpha) {
  return fmt::format(R"(LookAt 0 0 10  0 0 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" [ 32 ]
Sampler "independent" "integer pixelsamples" [ 4 ]
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
LightSource "distant" "point3 from" [ 0 0 1 ] "point3 to" [ 0 0 0 ] "rgb L" [ 3 3 3 ]
Texture "zero" "float" "constant" "float value" [ 0 ]
Texture "one" "float" "constant" "float value" [ 1 ]
Shape "trianglemesh" "point3 P" [ -5 -5 0  5 -5 0  5 5 0  -5 5 0 ] "integer indices" [ 0 1 2  0 2 3 ]
Material "diffuse" "rgb reflectance" [ 0 0 0 ]
{}
)",
                     blocker_alpha.empty() ? ""
                                           : "Shape \"trianglemesh\" \"point3 P\" [ -2 -2 2  2 -2 2  2 2 2  -2 2 2 ] "
                                             "\"integer indices\" [ 0 1 2  0 2 3 ] " + blocker_alpha);
}

}  // namespace

// A blocker cut out everywhere (alpha texture 0) casts no shadow: the image is the one without it, bit
// for bit (the camera sees the floor through it too: the same rays, the same random numbers). An opaque
// blocker (alpha texture 1) darkens it.
TEST(AlphaCutout, ShadowsPassThroughCutOuts) {
  ImageRgb none = render_text("alpha-shadow-none", shadow_scene(""));
  ImageRgb cut = render_text("alpha-shadow-cut", shadow_scene("\"texture alpha\" \"zero\""));
  ImageRgb opaque = render_text("alpha-shadow-opaque", shadow_scene("\"texture alpha\" \"one\""));
  ASSERT_GT(test::mean_channel(none, 0), 0.1);
  EXPECT_EQ(none.pixels, cut.pixels);
  EXPECT_LT(test::mean_channel(opaque, 0), 0.9 * test::mean_channel(none, 0));
}

namespace {

// A diffuse floor lit only by a 2 x 2 two-sided emitter above it (out of the camera's view), whose
// shape carries `emitter_alpha`; or, for the references, by `emitter_shapes` instead. maxdepth 1:
// the image is the floor's direct light, which every integrator finds in its own way (path: light
// samples and hits, with MIS; bdpt and lighttracing: also emitted paths; sppm: photons).
std::string emitter_scene(const std::string& integrator, const std::string& textures, const std::string& emitter_alpha,
                          const std::string& emitter_shapes = "", float L = 4.f) {
  std::string shapes = emitter_shapes.empty()
                           ? "Shape \"trianglemesh\" \"point3 P\" [ -1 -1 2  1 -1 2  1 1 2  -1 1 2 ] \"integer indices\" "
                             "[ 0 1 2  0 2 3 ] \"point2 uv\" [ 0 0  1 0  1 1  0 1 ] " + emitter_alpha
                           : emitter_shapes;
  return fmt::format(R"(LookAt 0 -4 1.2  0 0 0  0 0 1
Camera "perspective" "float fov" [ 30 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
PixelFilter "box"
Sampler "independent" "integer pixelsamples" [ {} ]
Integrator "{}" "integer maxdepth" [ 1 ] {}
WorldBegin
{}
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -4 -4 0  4 -4 0  4 4 0  -4 4 0 ] "integer indices" [ 0 1 2  0 2 3 ]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ {} {} {} ] "bool twosided" [ true ]
  {}
AttributeEnd
)",
                     integrator == "lighttracing" ? 4096 : 512, integrator, integrator == "sppm" ? "\"integer photonsperiteration\" [ 20000 ]" : "", textures, L, L,
                     L, shapes);
}

test::SeedMean render_over_seeds(const std::string& name, const std::string& text, int runs = 4) {
  return test::mean_over_seeds(runs, [&](int seed) {
    return test::mean_channel(render_text(fmt::format("{}-{}", name, seed), text, seed), 1);
  });
}

// The 4 of 9 squares of the checkerboard below that stay (floor(s) + floor(t) odd), as quads.
std::string kept_squares() {
  std::string out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      if ((i + j) % 2 == 0) continue;
      float x0 = -1.f + 2.f * i / 3.f, x1 = -1.f + 2.f * (i + 1) / 3.f;
      float y0 = -1.f + 2.f * j / 3.f, y1 = -1.f + 2.f * (j + 1) / 3.f;
      out += fmt::format("Shape \"trianglemesh\" \"point3 P\" [ {0} {2} 2  {1} {2} 2  {1} {3} 2  {0} {3} 2 ] "
                         "\"integer indices\" [ 0 1 2  0 2 3 ]\n  ",
                         x0, x1, y0, y1);
    }
  return out;
}

}  // namespace

// Alpha on an emitter (pbrt-v4 cuts its emission out of light sampling as well as out of hits):
// a 3 x 3 checkerboard alpha lights the floor as the 4 squares it keeps do, and a constant alpha
// of 0.5 as half the radiance does, in every integrator. Image means of 4 seeds each; tolerance 4
// standard errors of the difference, measured from the spread, asserted below 1.5 % of the mean;
// 2 % more or less light is rejected.
TEST(AlphaCutout, EmittersAreCutOutOfLightSamplingToo) {
  const std::string board = "Texture \"c\" \"float\" \"checkerboard\" \"float uscale\" [ 3 ] \"float vscale\" [ 3 ] "
                            "\"float tex1\" [ 0 ] \"float tex2\" [ 1 ]";
  test::SeedMean squares = render_over_seeds("emitter-squares", emitter_scene("path", "", "", kept_squares()));
  test::SeedMean halved = render_over_seeds("emitter-halved", emitter_scene("path", "", "", "", 2.f));
  for (const char* integrator : {"path", "bdpt", "lighttracing", "sppm"}) {
    for (auto [what, alpha, textures, reference] :
         {std::tuple{"checkerboard", "\"texture alpha\" \"c\"", board, squares},
          std::tuple{"alpha 0.5", "\"float alpha\" [ 0.5 ]", std::string(), halved}}) {
      test::SeedMean cut = render_over_seeds(fmt::format("emitter-{}-{}", integrator, what == std::string("alpha 0.5")),
                                     emitter_scene(integrator, textures, alpha));
      double tol = 4.0 * std::hypot(cut.standard_error, reference.standard_error);
      fmt::print("{} {}: {:.5f} against {:.5f} ({:+.2f} %), tolerance {:.2f} %\n", integrator, what, cut.mean,
                 reference.mean, 100.0 * (cut.mean / reference.mean - 1.0), 100.0 * tol / reference.mean);
      EXPECT_NEAR(cut.mean, reference.mean, tol) << integrator << ", " << what;
      EXPECT_LT(tol, 0.015 * reference.mean) << integrator << ", " << what << ": a 1.5 % bias would pass";
      EXPECT_GT(std::abs(1.02 * cut.mean - reference.mean), tol) << integrator << ", " << what;
      EXPECT_GT(std::abs(0.98 * cut.mean - reference.mean), tol) << integrator << ", " << what;
    }
  }
}
