// Located errors for bump maps, normal maps and alpha cut-outs, and what the plugins no longer declare.
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "scene/scene_builder.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

using namespace penumbra;
using ::testing::HasSubstr;

namespace {

std::string build_error(const std::string& world) {
  Registry registry(Registry::default_search_dirs());
  try {
    SceneDescription d = parse_scene_string("WorldBegin\n" + world, "scene.pbrt");
    build_scene(d, registry);
  } catch (const Error& e) {
    return e.formatted();
  }
  return "no error";
}

const char* kQuad = "Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  1 0 0  1 1 0 ]";
const char* kChecks = "Texture \"checks\" \"spectrum\" \"checkerboard\"\n";
const char* kRamp = "Texture \"ramp\" \"float\" \"bilerp\"\n";

}  // namespace

TEST(SurfaceDetailErrors, AlphaOutsideZeroOne) {
  EXPECT_THAT(build_error(std::string(kQuad) + " \"float alpha\" [ 1.5 ]\n"),
              HasSubstr("scene.pbrt:2:57: error: alpha must be in [0, 1], got 1.5"));
  EXPECT_THAT(build_error("Shape \"sphere\" \"float alpha\" [ -0.1 ]\n"),
              HasSubstr("scene.pbrt:2:16: error: alpha must be in [0, 1], got -0.1"));
}

TEST(SurfaceDetailErrors, SpectrumTextureAsAlpha) {
  EXPECT_THAT(build_error(std::string(kChecks) + kQuad + " \"texture alpha\" \"checks\"\n"),
              HasSubstr("scene.pbrt:3:57: error: parameter 'alpha' needs a float texture, but 'checks' is a spectrum "
                        "texture (defined at scene.pbrt:2:1)"));
}

TEST(SurfaceDetailErrors, UndefinedTextures) {
  EXPECT_THAT(build_error(std::string(kQuad) + " \"texture alpha\" \"nope\"\n"),
              HasSubstr("scene.pbrt:2:57: error: float texture 'nope' is not defined"));
  EXPECT_THAT(build_error("Material \"diffuse\" \"texture displacement\" \"nope\"\n" + std::string(kQuad) + "\n"),
              HasSubstr("scene.pbrt:2:20: error: float texture 'nope' is not defined"));
  EXPECT_THAT(build_error(std::string(kChecks) + "Material \"conductor\" \"texture displacement\" \"checks\"\n"),
              HasSubstr("scene.pbrt:3:22: error: parameter 'displacement' needs a float texture, but 'checks' is a "
                        "spectrum texture"));
}

TEST(SurfaceDetailErrors, BadDisplacementAndNormalMapTypes) {
  EXPECT_THAT(build_error("Material \"diffuse\" \"rgb displacement\" [ 1 1 1 ]\n"),
              HasSubstr("scene.pbrt:2:20: error: parameter 'displacement' must have type 'float' or 'texture', not 'rgb'"));
  EXPECT_THAT(build_error("Material \"diffuse\" \"float normalmap\" [ 1 ]\n"),
              HasSubstr("scene.pbrt:2:20: error: parameter 'normalmap' must have type 'string', not 'float'"));
  EXPECT_THAT(build_error("Material \"diffuse\" \"string normalmap\" \"missing.png\"\n"),
              HasSubstr("scene.pbrt:2:20: error: cannot read the normal map"));
}

TEST(SurfaceDetailErrors, AlphaOnAnAreaLight) {
  EXPECT_THAT(build_error("AreaLightSource \"diffuse\"\n" + std::string(kQuad) + " \"float alpha\" [ 0.5 ]\n"),
              HasSubstr("scene.pbrt:3:57: error: alpha on a shape with an area light is not supported"));
}

TEST(SurfaceDetailErrors, MixOfABumpedMaterial) {
  EXPECT_THAT(build_error(std::string(kRamp) +
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
    EXPECT_EQ(build_error(std::string(kRamp) + "Material \"" + m + "\" \"texture displacement\" \"ramp\"\n" + kQuad +
                          " \"float alpha\" [ 0.5 ]\n"),
              "no error");
  }
}
