// The perspective camera follows pbrt's conventions: fov along the shorter axis, raster (0,0) at the
// top-left, +x to the right; a thin lens focuses at focaldistance.
#include "parser/scene_description.h"
#include "scene/perspective_camera.h"

#include <gtest/gtest.h>

using namespace penumbra;

namespace {

PerspectiveCamera make_camera(const std::string& params, Point2i res) {
  SceneDescription d = parse_scene_string("LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\" " + params + "\nWorldBegin\n");
  d.camera.params.validate(perspective_camera_params(), "camera");
  return PerspectiveCamera(d.camera.params, d.camera.to_world, res);
}

float angle_deg(Vec3 a, Vec3 b) { return std::acos(std::clamp(glm::dot(a, b), -1.f, 1.f)) * 180.f / Pi; }

}  // namespace

TEST(PerspectiveCamera, CentreRayLooksAlongViewDirection) {
  PerspectiveCamera cam = make_camera("\"float fov\" [ 60 ]", Point2i(200, 100));
  Ray r = *cam.generate_ray(CameraSample{Vec2(100, 50)});
  EXPECT_NEAR(r.d.z, 1.f, 1e-6f);
  EXPECT_NEAR(glm::length(r.o), 0.f, 1e-6f);
}

TEST(PerspectiveCamera, FovSpansTheShorterAxis) {
  PerspectiveCamera wide = make_camera("\"float fov\" [ 60 ]", Point2i(200, 100));
  Ray top = *wide.generate_ray(CameraSample{Vec2(100, 0)});
  Ray bottom = *wide.generate_ray(CameraSample{Vec2(100, 100)});
  EXPECT_NEAR(angle_deg(top.d, bottom.d), 60.f, 1e-3f);
  EXPECT_GT(top.d.y, 0.f);  // raster row 0 is the top of the image
  PerspectiveCamera tall = make_camera("\"float fov\" [ 60 ]", Point2i(100, 200));
  Ray left = *tall.generate_ray(CameraSample{Vec2(0, 100)});
  Ray right = *tall.generate_ray(CameraSample{Vec2(100, 100)});
  EXPECT_NEAR(angle_deg(left.d, right.d), 60.f, 1e-3f);
}

TEST(PerspectiveCamera, ThinLensRaysMeetOnTheFocalPlane) {
  PerspectiveCamera cam = make_camera("\"float fov\" [ 45 ] \"float lensradius\" [ 0.2 ] \"float focaldistance\" [ 3 ]", Point2i(64, 64));
  Vec3 focus_point(0.f);
  for (int i = 0; i < 5; ++i) {
    Ray r = *cam.generate_ray(CameraSample{Vec2(20.5f, 40.5f), Vec2(0.1f + 0.2f * i, 0.9f - 0.15f * i)});
    Vec3 p = r.o + r.d * ((3.f - r.o.z) / r.d.z);
    if (i == 0) focus_point = p;
    EXPECT_NEAR(glm::distance(p, focus_point), 0.f, 1e-5f);
    EXPECT_NEAR(p.z, 3.f, 1e-5f);
  }
}

TEST(PerspectiveCamera, RejectsImpossibleFov) {
  EXPECT_THROW(make_camera("\"float fov\" [ 180 ]", Point2i(8, 8)), Error);
}
