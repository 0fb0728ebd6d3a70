// pbrt-v4's simpler materials: "diffusetransmission" (a plugin), "mix" and "interface" (built by the
// core: scene/composite_materials.h). Sampling against pdf (chi-square through the harness), white
// furnace against the closed-form albedo with 2 % negative controls, and whole renders for the
// scene-level behaviour (interface surfaces are invisible, mixes average their materials).
#include "render/render_session.h"
#include "scene/mix_bsdf.h"
#include "support/bsdf_harness.h"
#include "support/command.h"
#include "support/image_stats.h"

#include <penumbra/error.h>

#include <fmt/core.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace penumbra {
namespace {

using test::make_bsdf;
using test::spherical_direction;
using ::testing::HasSubstr;

constexpr int kSamples = 200'000;

const Vec3 kViews[] = {spherical_direction(0.9f, 0.3f), spherical_direction(0.4f, 2.f), spherical_direction(0.1f, 4.f),
                       spherical_direction(-0.7f, 1.f)};

void expect_sampling_matches_pdf(const Bsdf& bsdf, const std::string& what, uint64_t seed) {
  const double alpha = test::sidak_alpha(0.01, 4 * int(std::size(kViews)));
  for (const Vec3& wo : kViews) {
    test::ChiSquareResult r = test::bsdf_chi_square(bsdf, wo, kSamples, seed++);
    EXPECT_TRUE(r.passes(alpha)) << what << " at cos " << wo.z << ": " << r.summary();
  }
}

// Furnace: the BSDF's own sampling estimates the directional albedo; it must equal `expected` within
// 4 standard errors, and the same estimate scaled by 0.98 or 1.02 must not.
void expect_albedo(const Bsdf& bsdf, Rgb expected, const std::string& what) {
  for (const Vec3& wo : kViews) {
    test::AlbedoEstimate a = test::albedo_estimate(bsdf, wo, kSamples, 5);
    EXPECT_EQ(a.non_finite, 0);
    for (int c = 0; c < 3; ++c) {
      double tol = 4.0 * a.standard_error[c] + 1e-6;
      EXPECT_NEAR(a.mean[c], expected[c], tol) << what << " channel " << c << " at cos " << wo.z;
      EXPECT_GT(std::abs(0.98 * a.mean[c] - expected[c]), tol) << what << ": a 2 % bias would pass";
      EXPECT_GT(std::abs(1.02 * a.mean[c] - expected[c]), tol) << what << ": a 2 % bias would pass";
    }
  }
}

// ---- diffusetransmission -----------------------------------------------------------------------

TEST(DiffuseTransmission, SamplingMatchesPdf) {
  auto even = make_bsdf("diffusetransmission", "");
  auto mostly_through = make_bsdf("diffusetransmission", R"("rgb reflectance" [0.1 0.2 0.05] "rgb transmittance" [0.7 0.5 0.9])");
  expect_sampling_matches_pdf(*even, "defaults", 1);
  expect_sampling_matches_pdf(*mostly_through, "R < T", 101);
}

TEST(DiffuseTransmission, AlbedoIsReflectancePlusTransmittance) {
  auto b = make_bsdf("diffusetransmission", R"("rgb reflectance" [0.1 0.2 0.05] "rgb transmittance" [0.7 0.5 0.9])");
  expect_albedo(*b, Rgb(0.8f, 0.7f, 0.95f), "diffusetransmission");
  auto scaled = make_bsdf("diffusetransmission", R"("rgb reflectance" [0.4 0.4 0.4] "rgb transmittance" [0.2 0.4 0.6] "float scale" 0.5)");
  expect_albedo(*scaled, Rgb(0.3f, 0.4f, 0.5f), "diffusetransmission scale 0.5");
}

TEST(DiffuseTransmission, ReflectsOnTheSideOfWoAndTransmitsToTheOther) {
  auto b = make_bsdf("diffusetransmission", R"("rgb reflectance" [0.3 0.3 0.3] "rgb transmittance" [0.6 0.6 0.6])");
  ShadingContext ctx;
  Vec3 up(0.f, 0.f, 1.f), down(0.f, 0.f, -1.f);
  EXPECT_FLOAT_EQ(b->f(up, up, ctx).g, 0.3f * InvPi);
  EXPECT_FLOAT_EQ(b->f(up, down, ctx).g, 0.6f * InvPi);
  EXPECT_FLOAT_EQ(b->f(down, down, ctx).g, 0.3f * InvPi);
  EXPECT_THROW(make_bsdf("diffusetransmission", R"("rgb transmittance" [1.2 0.5 0.5])"), Error);
}

// ---- mix -------------------------------------------------------------------------------------------

TEST(Mix, SamplingMatchesPdf) {
  auto diffuse = make_bsdf("diffuse", R"("rgb reflectance" [0.8 0.8 0.8])");
  auto rough_metal = make_bsdf("conductor", R"("float roughness" [0.1])");
  auto glass = make_bsdf("dielectric", R"("float roughness" [0.2])");
  auto mirror = make_bsdf("conductor", R"("float roughness" [0])");
  expect_sampling_matches_pdf(MixBsdf(*diffuse, *rough_metal, 0.3f), "diffuse + rough conductor", 201);
  expect_sampling_matches_pdf(MixBsdf(*glass, *diffuse, 0.6f), "rough glass + diffuse", 301);
  // With a delta lobe, its share of the samples (amount) is "no sample" for the histogram.
  expect_sampling_matches_pdf(MixBsdf(*diffuse, *mirror, 0.25f), "diffuse + mirror", 401);
}

TEST(Mix, AlbedoIsTheAmountWeightedAverage) {
  auto diffuse = make_bsdf("diffuse", R"("rgb reflectance" [0.8 0.6 0.4])");
  auto sheet = make_bsdf("diffusetransmission", R"("rgb reflectance" [0.2 0.1 0.3] "rgb transmittance" [0.4 0.2 0.6])");
  // A smooth conductor with eta 1, k 1e4 reflects 1 - O(1e-8) at every angle.
  auto mirror = make_bsdf("conductor", R"("rgb eta" [1 1 1] "rgb k" [1e4 1e4 1e4])");
  expect_albedo(MixBsdf(*diffuse, *sheet, 0.3f), 0.7f * Rgb(0.8f, 0.6f, 0.4f) + 0.3f * Rgb(0.6f, 0.3f, 0.9f),
                "diffuse + diffusetransmission");
  expect_albedo(MixBsdf(*diffuse, *mirror, 0.25f), 0.75f * Rgb(0.8f, 0.6f, 0.4f) + 0.25f * Rgb(1.f),
                "diffuse + mirror");
}

// ---- Scene level: mix and interface through the scene builder --------------------------------------

// A unit-radiance sky above a plane seen from straight above, so each pixel is (albedo / pi) * pi = albedo.
std::string furnace_scene(const std::string& materials, const std::string& plane_material, const std::string& extra = "") {
  return fmt::format(R"(
LookAt 0 0 1  0 0 0  0 1 0
Camera "perspective" "float fov" [ 10 ]
Film "rgb" "integer xresolution" [ 8 ] "integer yresolution" [ 8 ]
PixelFilter "box"
Sampler "independent" "integer pixelsamples" [ 256 ]
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ]
{}
{}
Shape "trianglemesh" "point3 P" [ -100 -100 0  100 -100 0  100 100 0  -100 100 0 ] "integer indices" [ 0 1 2 0 2 3 ]
{}
)",
                     materials, plane_material, extra);
}

RenderResult render_text(const std::string& name, const std::string& text) {
  RenderSettings s;
  s.scene_file = test::write_file(test::temp_dir(name), "scene.pbrt", text);
  s.quiet = true;
  return render(s);
}

TEST(Mix, SceneMixAveragesTwoNamedMaterialsByAmount) {
  std::string named = R"(
MakeNamedMaterial "red" "string type" "diffuse" "rgb reflectance" [ 0.8 0.1 0.1 ]
MakeNamedMaterial "blue" "string type" "diffuse" "rgb reflectance" [ 0.1 0.1 0.8 ]
MakeNamedMaterial "both" "string type" "mix" "string materials" [ "red" "blue" ] "float amount" 0.25)";
  RenderResult r = render_text("mix-scene", furnace_scene(named, "NamedMaterial \"both\""));
  Rgb expected = 0.75f * Rgb(0.8f, 0.1f, 0.1f) + 0.25f * Rgb(0.1f, 0.1f, 0.8f);
  for (int c = 0; c < 3; ++c) {
    double se = test::standard_error_of_mean(r.image, c);
    EXPECT_NEAR(test::mean_channel(r.image, c), expected[c], 4 * se + 1e-6) << c;
    EXPECT_GT(std::abs(0.98 * test::mean_channel(r.image, c) - expected[c]), 4 * se) << c;
  }
}

TEST(Interface, InterfaceSurfacesLetRaysThrough) {
  // A sphere of "interface" around the camera must not change the image of the plane.
  std::string sphere = R"(AttributeBegin
Material "interface"
Translate 0 0 1
Shape "sphere" "float radius" 0.5
AttributeEnd)";
  RenderResult with = render_text("interface", furnace_scene("", "Material \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]", sphere));
  RenderResult without = render_text("no-interface", furnace_scene("", "Material \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]"));
  for (int c = 0; c < 3; ++c) EXPECT_EQ(test::mean_channel(with.image, c), test::mean_channel(without.image, c));
  EXPECT_NEAR(test::mean_channel(with.image, 1), 0.5, 4 * test::standard_error_of_mean(with.image, 1));
  // Negative control: the same sphere as a diffuse surface does change it.
  std::string opaque = sphere;
  opaque.replace(opaque.find("\"interface\""), 11, "\"diffuse\"");
  RenderResult blocked = render_text("opaque", furnace_scene("", "Material \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]", opaque));
  EXPECT_GT(std::abs(test::mean_channel(blocked.image, 1) - 0.5), 0.05);
}

std::string load_error(const std::string& name, const std::string& world) {
  std::string text = "WorldBegin\n" + world + "\nShape \"sphere\"\n";
  RenderSettings s;
  s.scene_file = test::write_file(test::temp_dir(name), "scene.pbrt", text);
  s.quiet = true;
  try {
    render(s);
  } catch (const Error& e) { return e.formatted(); }
  return "(no error)";
}

TEST(Mix, ErrorsAreLocated) {
  EXPECT_THAT(load_error("mix-undefined", R"(MakeNamedMaterial "a" "string type" "diffuse"
Material "mix" "string materials" [ "a" "b" ])"),
              HasSubstr("scene.pbrt:3:16: error: named material 'b' is not defined"));
  EXPECT_THAT(load_error("mix-one", R"(MakeNamedMaterial "a" "string type" "diffuse"
Material "mix" "string materials" [ "a" ])"),
              HasSubstr("scene.pbrt:3:16: error: material 'mix' needs \"string materials\" with two named materials"));
  EXPECT_THAT(load_error("mix-amount", R"(MakeNamedMaterial "a" "string type" "diffuse"
Material "mix" "string materials" [ "a" "a" ] "float amount" 2)"),
              HasSubstr("scene.pbrt:3:47: error: amount must be in [0, 1]"));
  EXPECT_THAT(load_error("mix-cycle", R"(MakeNamedMaterial "a" "string type" "mix" "string materials" [ "a" "a" ])"),
              HasSubstr("error: this mix material contains itself"));
  EXPECT_THAT(load_error("interface-light", R"(Material "interface"
AreaLightSource "diffuse")"),
              HasSubstr("error: an area light on a shape with material 'interface' is not supported"));
}

}  // namespace
}  // namespace penumbra
