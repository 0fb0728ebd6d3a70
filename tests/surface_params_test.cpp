// Located errors for bump maps, normal maps and alpha cut-outs, and what the plugins no longer declare.
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "scene/scene_builder.h"
#include "support/scene_errors.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

using namespace penumbra;
using ::testing::HasSubstr;

namespace {


const char* kQuad = "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  1 1 0 ]";
const char* kChecks = "Texture \"checks\" \"spectrum\" \"checkerboard\"\n";
const char* kRamp = "Texture \"ramp\" \"float\" \"bilerp\"\n";

}  // namespace

TEST(SurfaceDetailErrors, AlphaOutsideZeroOne) {
  EXPECT_THAT(test::scene_build_error(std::string(kQuad) + " \"float alpha\" [ 1.5 ]\n"),
              HasSubstr("scene.pbrt:2:57: error: alpha must be in [0, 1], got 1.5"));
  EXPECT_THAT(test::scene_build_error("Shape \"sphere\" \"float alpha\" [ -0.1 ]\n"),
              HasSubstr("scene.pbrt:2:16: error: alpha must be in [0, 1], got -0.1"));
}

TEST(SurfaceDetailErrors, SpectrumTextureAsAlpha) {
  EXPECT_THAT(test::scene_build_error(std::string(kChecks) + kQuad + " \"texture alpha\" \"checks\"\n"),
              HasSubstr("scene.pbrt:3:57: error: parameter 'alpha' needs a float texture, but 'checks' is a spectrum "
                        "texture (defined at scene.pbrt:2:1)"));
}

TEST(SurfaceDetailErrors, UndefinedTextures) {
  EXPECT_THAT(test::scene_build_error(std::string(kQuad) + " \"texture alpha\" \"nope\"\n"),
              HasSubstr("scene.pbrt:2:57: error: float texture 'nope' is not defined"));
  EXPECT_THAT(test::scene_build_error("Material \"diffuse\" \"texture displacement\" \"nope\"\n" + std::string(kQuad) + "\n"),
              HasSubstr("scene.pbrt:2:20: error: float texture 'nope' is not defined"));
  EXPECT_THAT(test::scene_build_error(std::string(kChecks) + "Material \"conductor\" \"texture displacement\" \"checks\"\n"),
              HasSubstr("scene.pbrt:3:22: error: parameter 'displacement' needs a float texture, but 'checks' is a "
                        "spectrum texture"));
}

TEST(SurfaceDetailErrors, BadDisplacementAndNormalMapTypes) {
  EXPECT_THAT(test::scene_build_error("Material \"diffuse\" \"rgb displacement\" [ 1 1 1 ]\n"),
              HasSubstr("scene.pbrt:2:20: error: parameter 'displacement' must have type 'float' or 'texture', not 'rgb'"));
  EXPECT_THAT(test::scene_build_error("Material \"diffuse\" \"float normalmap\" [ 1 ]\n"),
              HasSubstr("scene.pbrt:2:20: error: parameter 'normalmap' must have type 'string', not 'float'"));
  EXPECT_THAT(test::scene_build_error("Material \"diffuse\" \"string normalmap\" \"missing.png\"\n"),
              HasSubstr("scene.pbrt:2:20: error: cannot read the normal map"));
}

TEST(SurfaceDetailErrors, MixOfABumpedMaterial) {
  EXPECT_THAT(test::scene_build_error(std::string(kRamp) +
                          "MakeNamedMaterial \"a\" \"string type\" \"diffuse\" \"texture displacement\" \"ramp\"\n"
                          "MakeNamedMaterial \"b\" \"string type\" \"diffuse\"\n"
                          "Material \"mix\" \"string materials\" [ \"a\" \"b\" ]\n"),
              HasSubstr("scene.pbrt:5:16: error: material 'a' has a bump or normal map: mixing it is not supported"));
}

// Every BSDF plugin takes "displacement" and "normalmap" now (the core strips them before the plugin's
// table is checked), and the shapes take "alpha".
TEST(SurfaceDetailErrors, EveryMaterialAcceptsTheCoreParameters) {
  for (const char* m : {"diffuse", "conductor", "dielectric", "coateddiffuse", "coatedconductor", "disney",
                        "diffusetransmission"}) {
    SCOPED_TRACE(m);
    EXPECT_EQ(test::scene_build_error(std::string(kRamp) + "Material \"" + m + "\" \"texture displacement\" \"ramp\"\n" + kQuad +
                          " \"float alpha\" [ 0.5 ]\n"),
              "");
  }
}

namespace {

// A quad in z = 0 whose uv is rotated by 45 degrees, seen head-on.
SurfaceInteraction rotated_uv_hit(const std::string& material) {
  Registry registry(Registry::default_search_dirs());
  SceneDescription d = parse_scene_string("LookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n" + material +
                                              "\nShape \"trianglemesh\" \"point3 P\" [ -1 -1 0  1 -1 0  1 1 0  -1 1 0 ]"
                                              " \"integer indices\" [ 0 1 2  0 2 3 ] \"point2 uv\" [ 0.5 0  1 0.5  0.5 1  0 0.5 ]\n",
                                          "frame.pbrt");
  BuiltScene b = build_scene(d, registry);
  auto si = b.scene->intersect(Ray{Vec3(0.1f, 0.2f, -5.f), Vec3(0.f, 0.f, 1.f)});
  EXPECT_TRUE(si.has_value());
  return si.value_or(SurfaceInteraction{});
}

}  // namespace

// Anisotropic roughness is oriented by dp/du, as in pbrt-v4: the frame's s is u's direction on the
// surface, (1, -1, 0) / sqrt 2 here (u = 0 at (-1, 1), 1 at (1, -1)). An isotropic material keeps the normal-only frame, whose s is (1, 0, 0)
// on this quad (the control: it is 45 degrees away).
TEST(SurfaceDetailFrames, AnisotropicMaterialsGetTheDpduFrame) {
  const Vec3 u_dir = glm::normalize(Vec3(1.f, -1.f, 0.f));
  for (const char* m : {"Material \"conductor\" \"float uroughness\" [ 0.1 ] \"float vroughness\" [ 0.4 ]",
                        "Material \"coatedconductor\" \"float conductor.uroughness\" [ 0.1 ]",
                        "Material \"disney\" \"float anisotropic\" [ 0.5 ]"}) {
    SCOPED_TRACE(m);
    SurfaceInteraction si = rotated_uv_hit(m);
    EXPECT_NEAR(glm::dot(si.shading.s, u_dir), 1.f, 1e-6f);
    EXPECT_NEAR(glm::length(si.shading.t - glm::cross(si.shading.n, si.shading.s)), 0.f, 1e-6f);
  }
  SurfaceInteraction iso = rotated_uv_hit("Material \"conductor\" \"float roughness\" [ 0.1 ]");
  EXPECT_LT(glm::dot(iso.shading.s, u_dir), 0.8f);
}
