// pbrt-v4's `Attribute "target" params`: defaults for the shapes, lights, materials, media and
// textures that follow in the attribute block; a directive's own parameters win, objects without a
// parameter of that name ignore it, and errors point at the Attribute's parameter.
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "scene/scene_builder.h"
#include "support/scene_errors.h"

#include <penumbra/bsdf.h>

#include <gtest/gtest.h>

using namespace penumbra;

namespace {

BuiltScene build(const std::string& world) {
  static Registry registry(Registry::default_search_dirs());
  SceneDescription d = parse_scene_string("WorldBegin\n" + world, "a.pbrt");
  return build_scene(d, registry);
}

std::string error_of(const std::string& world) { return test::scene_build_error(world, "a.pbrt"); }

}  // namespace

TEST(AttributeDirective, ShapeDefaultsApplyInTheirBlockAndLoseToOwnParameters) {
  BuiltScene a = build("AttributeBegin\nAttribute \"shape\" \"float radius\" [ 0.25 ]\nShape \"sphere\"\nAttributeEnd\n");
  EXPECT_NEAR(a.scene->bounds().max.x, 0.25f, 1e-4f);
  BuiltScene own = build("Attribute \"shape\" \"float radius\" [ 0.25 ]\nShape \"sphere\" \"float radius\" [ 2 ]\n");
  EXPECT_NEAR(own.scene->bounds().max.x, 2.f, 1e-4f);
  BuiltScene scoped = build("AttributeBegin\nAttribute \"shape\" \"float radius\" [ 0.25 ]\nAttributeEnd\nShape \"sphere\"\n");
  EXPECT_NEAR(scoped.scene->bounds().max.x, 1.f, 1e-4f);  // pbrt-v4's default radius
  // A later Attribute of the same name replaces the value; a mesh has no radius and ignores it.
  BuiltScene later = build("Attribute \"shape\" \"float radius\" [ 0.25 ]\nAttribute \"shape\" \"float radius\" [ 0.5 ]\n"
                           "Shape \"sphere\"\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0  0.1 0 0  0 0.1 0 ]\n");
  EXPECT_NEAR(later.scene->bounds().max.x, 0.5f, 1e-4f);
}

TEST(AttributeDirective, MaterialDefaults) {
  BuiltScene b = build("Attribute \"material\" \"rgb reflectance\" [ 0.2 0.4 0.6 ]\nMaterial \"diffuse\"\n"
                       "Material \"diffuse\" \"rgb reflectance\" [ 0.9 0.9 0.9 ]\nShape \"sphere\"\n");
  ShadingContext ctx;
  Vec3 w(0.f, 0.f, 1.f);
  EXPECT_NEAR(b.bsdfs[0]->f(w, w, ctx).b, 0.6f * InvPi, 1e-6f);
  EXPECT_NEAR(b.bsdfs[1]->f(w, w, ctx).b, 0.9f * InvPi, 1e-6f);
}

TEST(AttributeDirective, ErrorsAreLocatedAtTheAttribute) {
  std::string e = error_of("Attribute \"camera\" \"float fov\" [ 30 ]\n");
  EXPECT_NE(e.find("a.pbrt:2:11"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown attribute target"), std::string::npos) << e;
  // A parameter the object has, with the wrong type: the error points at the Attribute's parameter.
  e = error_of("Attribute \"shape\" \"integer radius\" [ 2 ]\nShape \"sphere\"\n");
  EXPECT_NE(e.find("a.pbrt:2:19"), std::string::npos) << e;
  EXPECT_NE(e.find("must have type 'float'"), std::string::npos) << e;
}
