// The scene builder on the real pbrt-v4 scenes: their geometry (trianglemesh and binary PLY meshes)
// loads today even where their materials arrive later; only what a scene names is built.
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "scene/scene_builder.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

using namespace penumbra;

namespace {

std::string scene_path(const std::string& name) {
  return std::string(PENUMBRA_SOURCE_DIR) + "/scenes/pbrt-v4/" + name + "/scene-v4.pbrt";
}

// Replaces materials and plugins the foundation does not have yet by diffuse ones, keeping geometry.
BuiltScene build_with_diffuse_materials(const std::string& name, Registry& registry) {
  SceneDescription d = parse_scene_file(scene_path(name));
  for (auto& m : d.materials) {
    m.type = "diffuse";
    m.params = ParamSet{};
  }
  d.integrator.type = "path";
  d.integrator.params = ParamSet{};
  d.sampler.type = "independent";
  d.sampler.params = ParamSet{};
  d.film.params.set_int("xresolution", 8);
  d.film.params.set_int("yresolution", 8);
  return build_scene(d, registry);
}

Registry builtin_registry() { return Registry(Registry::default_search_dirs()); }

}  // namespace

TEST(SceneBuilder, VeachBidirGeometryLoadsFromBinaryPly) {
  Registry registry = builtin_registry();
  BuiltScene s = build_with_diffuse_materials("veach-bidir", registry);
  EXPECT_GT(s.scene->triangle_count(), 1000u);
  EXPECT_EQ(s.scene->lights().size(), 4u);  // two emitting quads, two triangles each
  Bounds3 b = s.scene->bounds();
  EXPECT_TRUE(is_finite(b.min) && is_finite(b.max));
}

TEST(SceneBuilder, WaterCausticGeometryLoadsWithNormalsAndUvs) {
  Registry registry = builtin_registry();
  BuiltScene s = build_with_diffuse_materials("water-caustic", registry);
  EXPECT_GT(s.scene->triangle_count(), 102938u);  // the water surface alone has 102,938 faces
}

TEST(SceneBuilder, VeachMisSpheresBecomeAreaLights) {
  Registry registry = builtin_registry();
  BuiltScene s = build_with_diffuse_materials("veach-mis", registry);
  size_t spheres_and_quads = s.scene->lights().size();
  EXPECT_GE(spheres_and_quads, 3u);
}

TEST(SceneBuilder, BuildsNoLightDistributionWithoutLights) {
  SceneDescription d = parse_scene_string(
      "Camera \"perspective\"\nFilm \"rgb\" \"integer xresolution\" [4] \"integer yresolution\" [4]\nWorldBegin\n"
      "Shape \"sphere\"\n");
  Registry registry = builtin_registry();
  BuiltScene s = build_scene(d, registry);
  EXPECT_EQ(s.structures_built, std::vector<std::string>{"embree_scene"});
  EXPECT_EQ(registry.loaded(), (std::vector<std::string>{"sampler/independent", "integrator/path", "bsdf/diffuse"}));
}

TEST(SceneBuilder, UnknownMaterialIsLocatedAndListsAvailable) {
  SceneDescription d = parse_scene_string(
      "Camera \"perspective\"\nWorldBegin\nMakeNamedMaterial \"m\" \"string type\" \"measuredbrdf\"\nNamedMaterial \"m\"\nShape \"sphere\"\n",
      "s.pbrt");
  Registry registry = builtin_registry();
  try {
    build_scene(d, registry);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_THAT(e.formatted(), ::testing::HasSubstr("s.pbrt:3:1: error: unknown bsdf 'measuredbrdf'; available: "));
    EXPECT_THAT(e.formatted(), ::testing::HasSubstr("conductor"));
  }
}
