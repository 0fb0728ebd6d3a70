// pbrt-v4's object instancing (ObjectBegin / ObjectEnd / ObjectInstance) through Embree instances:
// a scene of instanced objects renders as the same scene with every copy written out (same seed:
// same image up to the float rounding of the transforms), the geometry is stored once (stats), and
// misuse is a located error.
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "render/render_session.h"
#include "scene/scene_builder.h"
#include "support/command.h"
#include "support/scene_errors.h"
#include "support/image_stats.h"

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace penumbra;
using namespace penumbra::test;

namespace {

const char* kHeader = R"(LookAt 0 4 9  0 0.5 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 48 ] "integer yresolution" [ 32 ]
PixelFilter "box"
Sampler "independent" "integer pixelsamples" [ 16 ]
Integrator "path" "integer maxdepth" [ 3 ]
WorldBegin
LightSource "distant" "point3 from" [ 1 3 2 ] "point3 to" [ 0 0 0 ] "rgb L" [ 3 3 3 ]
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Shape "trianglemesh" "point3 P" [ -6 0 -6  6 0 -6  6 0 6  -6 0 6 ] "integer indices" [ 0 2 1  0 3 2 ]
)";

// The object: a tilted box-like tetrahedron and a sphere, with their own material and transforms.
const char* kObjectBody = R"(  Material "conductor" "float roughness" [ 0.3 ]
  Translate 0 0.5 0
  Rotate 30 0 1 0
  Shape "trianglemesh" "point3 P" [ -0.5 -0.5 -0.5  0.5 -0.5 -0.5  0 -0.5 0.5  0 0.5 0 ]
      "integer indices" [ 0 1 2  0 3 1  1 3 2  2 3 0 ]
  Material "diffuse" "rgb reflectance" [ 0.2 0.6 0.3 ]
  Translate 0.6 0 0
  Shape "sphere" "float radius" [ 0.25 ]
)";

// Where the copies go: translations, rotations and a scale (uniform: a written-out sphere must be).
const char* kPlacements[] = {"Translate -2.5 0 0", "Translate 0 0 -1\n  Rotate 60 0 1 0",
                             "Translate 2.5 0 0.5\n  Rotate 20 1 0 0\n  Scale 1.3 1.3 1.3"};

std::string instanced_scene() {
  std::string s = kHeader;
  s += std::string("ObjectBegin \"thing\"\n") + kObjectBody + "ObjectEnd\n";
  for (const char* p : kPlacements) s += fmt::format("AttributeBegin\n  {}\n  ObjectInstance \"thing\"\nAttributeEnd\n", p);
  return s;
}

std::string flattened_scene() {
  std::string s = kHeader;
  for (const char* p : kPlacements) s += fmt::format("AttributeBegin\n  {}\n{}AttributeEnd\n", p, kObjectBody);
  return s;
}

RenderResult render_text(const std::string& name, const std::string& text) {
  RenderSettings s;
  s.scene_file = write_file(temp_dir(name), "scene.pbrt", text);
  s.quiet = true;
  s.seed = 7;
  return render(s);
}

}  // namespace

// Same seed, same sample streams: the two images differ only where the rounding of the transforms
// moves a hit (measured: means equal to 6 digits, every pixel within 1e-3). Tolerance 1e-4 on the
// means; a copy left out (2 of 3 instances) changes the mean by 0.85 %, far outside it.
TEST(ObjectInstancing, InstancesRenderAsTheCopiesWrittenOut) {
  RenderResult inst = render_text("instanced", instanced_scene());
  RenderResult flat = render_text("flattened", flattened_scene());
  ASSERT_EQ(count_nonfinite(inst.image), 0);
  int close = 0, n = inst.image.width * inst.image.height;
  for (int i = 0; i < n; ++i) {
    float a = inst.image.pixels[3 * i + 1], b = flat.image.pixels[3 * i + 1];
    close += std::abs(a - b) <= 1e-3f * std::max(1.f, b);
  }
  for (int c = 0; c < 3; ++c) {
    double a = mean_channel(inst.image, c), b = mean_channel(flat.image, c);
    std::printf("[ measured ] channel %d: instanced %.6f, written out %.6f\n", c, a, b);
    EXPECT_NEAR(a / b, 1.0, 1e-4);
  }
  std::printf("[ measured ] pixels within 1e-3: %d of %d\n", close, n);
  EXPECT_GE(close, n * 95 / 100);
  // Stored once: 4 triangles of the object plus the floor's 2; placed three times.
  EXPECT_EQ(inst.stats.triangles, 6u);
  EXPECT_EQ(inst.stats.instances, 3u);
  EXPECT_EQ(inst.stats.instanced_triangles, 12u);
  EXPECT_EQ(flat.stats.triangles, 14u);

  // Negative control: one instance fewer.
  std::string two = instanced_scene();
  two.resize(two.rfind("AttributeBegin"));
  RenderResult fewer = render_text("instanced-two", two);
  EXPECT_GT(std::abs(mean_channel(fewer.image, 1) / mean_channel(flat.image, 1) - 1.0), 1e-3);
}

TEST(ObjectInstancing, MisuseIsALocatedError) {
  auto error_of = [](const std::string& world) { return scene_build_error(world, "o.pbrt"); };
  auto expect_at = [&](const std::string& world, const std::string& where, const std::string& words) {
    std::string e = error_of(world);
    EXPECT_NE(e.find(where), std::string::npos) << e;
    EXPECT_NE(e.find(words), std::string::npos) << e;
  };
  expect_at("ObjectBegin \"a\"\nObjectBegin \"b\"\n", "o.pbrt:3:1", "do not nest");
  expect_at("ObjectEnd\n", "o.pbrt:2:1", "without a matching ObjectBegin");
  expect_at("ObjectBegin \"a\"\nAttributeEnd\n", "o.pbrt:3:1", "use ObjectEnd");
  expect_at("ObjectBegin \"a\"\nAttributeBegin\nObjectEnd\n", "o.pbrt:4:1", "closes the AttributeBegin");
  expect_at("ObjectBegin \"a\"\nShape \"sphere\"\n", "o.pbrt:2:1", "no matching ObjectEnd");
  expect_at("ObjectBegin \"a\"\nObjectEnd\nObjectBegin \"a\"\n", "o.pbrt:4:13", "redefined");
  expect_at("ObjectInstance \"ghost\"\n", "o.pbrt:2:16", "no ObjectBegin defines");
  expect_at("ObjectBegin \"a\"\nObjectInstance \"a\"\n", "o.pbrt:3:1", "do not nest");
  expect_at("ObjectBegin \"a\"\nAreaLightSource \"diffuse\"\nShape \"sphere\"\nObjectEnd\nObjectInstance \"a\"\n",
            "o.pbrt:4:1", "cannot emit");
  // An object never instanced, and an empty one instanced, are fine.
  EXPECT_EQ(error_of("ObjectBegin \"a\"\nShape \"sphere\"\nObjectEnd\nShape \"sphere\"\n"), "");
  EXPECT_EQ(error_of("ObjectBegin \"e\"\nObjectEnd\nObjectInstance \"e\"\nShape \"sphere\"\n"), "");
}
