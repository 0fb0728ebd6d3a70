// Normal maps (pbrt-v4's "string normalmap" on a material): tangent-space RGB in [0, 1] -> [-1, 1],
// looked up bilinearly at (u, 1 - v) with wrapping, in the frame (dp/du, n x dp/du, n).
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "scene/scene_builder.h"
#include "scene/normal_map.h"
#include "support/command.h"

#include <penumbra/image.h>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

using namespace penumbra;

namespace {

// Writes a width x 1 float EXR whose texels have the given RGB.
std::string write_map(const std::string& dir, const std::string& name, const std::vector<Vec3>& texels) {
  ImageRgb img;
  img.width = static_cast<int>(texels.size());
  img.height = 1;
  for (const Vec3& t : texels) img.pixels.insert(img.pixels.end(), {t.x, t.y, t.z});
  std::string path = dir + "/" + name;
  write_image(path, img);
  return path;
}

// The quad of the bump tests: dp/du = (4, 0, 0), dp/dv = (0, 4, 0) in z = 0, seen along +z.
BuiltScene mapped_quad(Registry& registry, const std::string& map_file) {
  SceneDescription d = parse_scene_string(fmt::format(R"(LookAt 0 0 -5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 90 ]
WorldBegin
Material "conductor" "string normalmap" "{}" "float roughness" [ 0.3 ]
Shape "trianglemesh" "point3 P" [ -2 -2 0  2 -2 0  2 2 0  -2 2 0 ] "integer indices" [ 0 1 2  0 2 3 ]
    "point2 uv" [ 0 0  1 0  1 1  0 1 ]
)",
                                                      map_file),
                                          "nm.pbrt");
  return build_scene(d, registry);
}

SurfaceInteraction hit(const BuiltScene& b, Vec2 xy) {
  auto si = b.scene->intersect(Ray{Vec3(xy, -5.f), Vec3(0.f, 0.f, 1.f)});
  EXPECT_TRUE(si.has_value());
  return si.value_or(SurfaceInteraction{});
}

float max_diff(const Vec3& x, const Vec3& y) {
  Vec3 d = glm::abs(x - y);
  return std::max({d.x, d.y, d.z});
}

// The tangent-space normal c * 2 - 1 in the frame x = (1, 0, 0), z = ng = (0, 0, s), y = z x x; the
// result lies on ng's side already.
Vec3 expected(const Vec3& c, float s) {
  Vec3 l = glm::normalize(2.f * c - Vec3(1.f));
  Vec3 x(1.f, 0.f, 0.f), z(0.f, 0.f, s);
  return glm::normalize(l.x * x + l.y * glm::cross(z, x) + l.z * z);
}

}  // namespace

TEST(NormalMap, FlatColourLeavesTheNormalUnchanged) {
  std::string dir = test::temp_dir("normal-map-flat");
  Registry registry(Registry::default_search_dirs());
  BuiltScene b = mapped_quad(registry, write_map(dir, "flat.exr", {Vec3(0.5f, 0.5f, 1.f)}));
  for (Vec2 xy : {Vec2(0.f), Vec2(1.3f, -0.6f)}) {
    SurfaceInteraction si = hit(b, xy);
    EXPECT_LT(max_diff(si.ns, si.ng), 1e-6f);
    EXPECT_LT(max_diff(si.shading.s, Vec3(1.f, 0.f, 0.f)), 1e-6f);
  }
}

// (0.75, 0.5, 1) -> (0.5, 0, 1) / |.|: tilted by atan(0.5) = 26.565 degrees towards +dp/du. A map 1 %
// redder (0.7575) tilts by 0.43 degrees more: outside the 1e-4 tolerance.
TEST(NormalMap, TiltedColourTiltsByTheKnownAngle) {
  std::string dir = test::temp_dir("normal-map-tilt");
  Registry registry(Registry::default_search_dirs());
  BuiltScene b = mapped_quad(registry, write_map(dir, "tilt.exr", {Vec3(0.75f, 0.5f, 1.f)}));
  SurfaceInteraction si = hit(b, Vec2(0.4f, 0.2f));
  float s = si.ng.z > 0.f ? 1.f : -1.f;
  EXPECT_LT(max_diff(si.ns, expected(Vec3(0.75f, 0.5f, 1.f), s)), 1e-4f);
  EXPECT_NEAR(std::acos(glm::dot(si.ns, si.ng)), std::atan(0.5f), 1e-4f);
  EXPECT_NEAR(si.ns.x, 1.f / std::sqrt(5.f), 1e-4f);  // towards +u
  EXPECT_GT(max_diff(si.ns, expected(Vec3(0.7575f, 0.5f, 1.f), s)), 1e-4f);  // control
  // A green tilt goes towards n x dp/du.
  BuiltScene g = mapped_quad(registry, write_map(dir, "green.exr", {Vec3(0.5f, 0.75f, 1.f)}));
  SurfaceInteraction sg = hit(g, Vec2(0.4f, 0.2f));
  EXPECT_LT(max_diff(sg.ns, expected(Vec3(0.5f, 0.75f, 1.f), s)), 1e-4f);
}

// Bilinear with wrapping: a 2 x 1 map (flat, tilted) at s = 0.5 lies halfway between the texel centres
// (0.25 and 0.75), and at s = 0 halfway between the last texel and the first (repeat): both read
// (0.625, 0.5, 1). pbrt-v4 reads the map at (u, 1 - v).
TEST(NormalMap, BilinearLookupWrapsAround) {
  NormalMapImage map(2, 1, {Vec3(0.5f, 0.5f, 1.f), Vec3(0.75f, 0.5f, 1.f)});
  EXPECT_LT(max_diff(map.bilerp(Vec2(0.5f, 0.3f)), Vec3(0.625f, 0.5f, 1.f)), 1e-6f);
  EXPECT_LT(max_diff(map.bilerp(Vec2(0.f, 0.9f)), Vec3(0.625f, 0.5f, 1.f)), 1e-6f);
  EXPECT_LT(max_diff(map.bilerp(Vec2(2.25f, 0.5f)), Vec3(0.5f, 0.5f, 1.f)), 1e-6f);
  EXPECT_LT(max_diff(map.bilerp(Vec2(-0.25f, 0.5f)), Vec3(0.75f, 0.5f, 1.f)), 1e-6f);
  std::string dir = test::temp_dir("normal-map-bilerp");
  Registry registry(Registry::default_search_dirs());
  BuiltScene b = mapped_quad(registry, write_map(dir, "two.exr", {Vec3(0.5f, 0.5f, 1.f), Vec3(0.75f, 0.5f, 1.f)}));
  SurfaceInteraction si = hit(b, Vec2(0.f, 0.5f));  // u = 0.5
  EXPECT_LT(max_diff(si.ns, expected(Vec3(0.625f, 0.5f, 1.f), si.ng.z > 0.f ? 1.f : -1.f)), 1e-4f);
}

// 8-bit files are read as value / 255, not sRGB-decoded (pbrt-v4 reads normal maps as linear):
// (128, 128, 255) is (0.00392, 0.00392, 1) after * 2 - 1, a tilt of 0.318 degrees; sRGB decoding would
// have given 0.216 * 2 - 1 = -0.57 and a tilt of 39 degrees.
TEST(NormalMap, EightBitMapsAreLinear) {
  std::string dir = test::temp_dir("normal-map-png");
  std::string path = dir + "/map.png";
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out);
  OIIO::ImageSpec spec(1, 1, 3, OIIO::TypeDesc::UINT8);
  ASSERT_TRUE(out->open(path, spec));
  unsigned char px[3] = {128, 128, 255};
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, px));
  out->close();
  Registry registry(Registry::default_search_dirs());
  BuiltScene b = mapped_quad(registry, path);
  SurfaceInteraction si = hit(b, Vec2(0.f));
  EXPECT_LT(max_diff(si.ns, expected(Vec3(128.f / 255.f, 128.f / 255.f, 1.f), si.ng.z > 0.f ? 1.f : -1.f)), 1e-5f);
}
