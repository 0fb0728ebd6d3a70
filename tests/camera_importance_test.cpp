// Camera importance (We, pdf_we, sample_wi), which light tracing and bidirectional path tracing use
// to connect light paths to the film: the normalisation of We, its consistency with the densities
// of generate_ray(), and sample_wi() landing on the raster position of the ray it connects along.
#include "parser/scene_description.h"
#include "scene/perspective_camera.h"
#include "support/pcg32.h"

#include <penumbra/sampling.h>

#include <gtest/gtest.h>

using namespace penumbra;

namespace {

PerspectiveCamera make_camera(const std::string& params, Point2i res, const std::string& transform = "") {
  SceneDescription d = parse_scene_string(transform + "LookAt 0.3 0.5 -1  1 0.8 2  0 1 0\nCamera \"perspective\" " +
                                          params + "\nWorldBegin\n");
  d.camera.params.validate(perspective_camera_params(), "camera");
  return PerspectiveCamera(d.camera.params, d.camera.to_world, res);
}

struct Case {
  std::string name, params, transform;
  Point2i res;
  float lens_area;
};

std::vector<Case> cases() {
  float r = 0.15f;
  return {
      {"pinhole", "\"float fov\" [ 50 ]", "", Point2i(64, 48), 1.f},
      {"tall_mirrored", "\"float fov\" [ 30 ]", "Scale -1 1 1\n", Point2i(30, 80), 1.f},
      {"screenwindow", "\"float fov\" [ 70 ] \"float screenwindow\" [ -0.5 1 -0.25 0.75 ]", "", Point2i(40, 40), 1.f},
      {"thin_lens", "\"float fov\" [ 40 ] \"float lensradius\" [ 0.15 ] \"float focaldistance\" [ 2.5 ]",
       "Scale -1 1 1\n", Point2i(50, 32), Pi * r * r},
  };
}

// A point of the camera's lens in world space (lens sample u).
Vec3 lens_point(const PerspectiveCamera& cam, Vec2 u) {
  return cam.generate_ray(CameraSample{Vec2(0.5f), u})->o;
}

// The viewing axis of make_camera()'s LookAt (a mirror in front of it keeps camera +z there).
const Vec3 kAxis = glm::normalize(Vec3(0.7f, 0.3f, 3.f));

}  // namespace

// The integral of We cos(theta) over all directions leaving a lens point is 1 / lens area: estimated
// with 2^20 uniform directions on the sphere (the relative standard error is about 0.5 % for these
// fields of view), tolerance 2 %.
TEST(CameraImportance, WeCosIntegratesToOneOverLensArea) {
  for (const Case& c : cases()) {
    PerspectiveCamera cam = make_camera(c.params, c.res, c.transform);
    test::Pcg32 rng(7);
    Vec3 o = lens_point(cam, Vec2(0.3f, 0.8f));
    const Vec3 axis = kAxis;
    const int n = 1 << 20;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      Vec3 w = sample_uniform_sphere(Vec2(rng.next_float(), rng.next_float()));
      float cos_theta = glm::dot(w, axis);
      if (cos_theta <= 0.f) continue;
      sum += cam.We(Ray{o, w}).x * cos_theta / uniform_sphere_pdf();
    }
    EXPECT_NEAR(sum / n * c.lens_area, 1.0, 0.02) << c.name;
  }
}

// For rays from generate_ray(): We cos / (pdf_pos pdf_dir) = 1 exactly (the estimator of a camera
// ray carries unit weight), the ray maps back to its raster position, and pdf_pos = 1 / lens area.
TEST(CameraImportance, DensitiesMatchGenerateRay) {
  for (const Case& c : cases()) {
    PerspectiveCamera cam = make_camera(c.params, c.res, c.transform);
    test::Pcg32 rng(11);
    const Vec3 axis = kAxis;
    for (int i = 0; i < 2000; ++i) {
      CameraSample cs{Vec2(rng.next_float() * c.res.x, rng.next_float() * c.res.y), Vec2(rng.next_float(), rng.next_float())};
      Ray ray = *cam.generate_ray(cs);
      Vec2 raster;
      float We = cam.We(ray, &raster).x;
      float pdf_pos, pdf_dir;
      cam.pdf_we(ray, &pdf_pos, &pdf_dir);
      ASSERT_GT(We, 0.f) << c.name;
      EXPECT_NEAR(pdf_pos, 1.f / c.lens_area, 1e-3f / c.lens_area);
      EXPECT_NEAR(We * glm::dot(ray.d, axis) / (pdf_pos * pdf_dir), 1.f, 1e-4f) << c.name;
      EXPECT_NEAR(raster.x, cs.p_film.x, 2e-3f * c.res.x) << c.name;
      EXPECT_NEAR(raster.y, cs.p_film.y, 2e-3f * c.res.y) << c.name;
    }
  }
}

// sample_wi() from a point on a camera ray (same lens sample) returns that ray's lens point, its
// reversed direction and its raster position; the pdf is the lens-area density as solid angle.
TEST(CameraImportance, SampleWiLandsWhereTheCameraRayStarted) {
  for (const Case& c : cases()) {
    PerspectiveCamera cam = make_camera(c.params, c.res, c.transform);
    test::Pcg32 rng(5);
    const Vec3 axis = kAxis;
    for (int i = 0; i < 2000; ++i) {
      CameraSample cs{Vec2(rng.next_float() * c.res.x, rng.next_float() * c.res.y), Vec2(rng.next_float(), rng.next_float())};
      Ray ray = *cam.generate_ray(cs);
      float t = 0.5f + 4.f * rng.next_float();
      Vec3 p = ray.o + t * ray.d;
      std::optional<CameraWiSample> s = cam.sample_wi(p, cs.p_lens);
      ASSERT_TRUE(s.has_value()) << c.name;
      EXPECT_NEAR(glm::distance(s->p_lens, ray.o), 0.f, 1e-4f) << c.name;
      EXPECT_NEAR(glm::dot(s->wi, -ray.d), 1.f, 1e-5f) << c.name;
      EXPECT_NEAR(s->p_raster.x, cs.p_film.x, 2e-3f * c.res.x) << c.name;
      EXPECT_NEAR(s->p_raster.y, cs.p_film.y, 2e-3f * c.res.y) << c.name;
      float expected_pdf = t * t / (glm::dot(ray.d, axis) * c.lens_area);
      EXPECT_NEAR(s->pdf / expected_pdf, 1.f, 1e-3f) << c.name;
      EXPECT_NEAR(s->We.x / cam.We(ray).x, 1.f, 1e-3f) << c.name;
      // The densities it carries are pdf_we()'s for the ray it connects along, to the bit, and We
      // is We()'s: bidirectional methods take them from here instead of calling again.
      Ray back{s->p_lens, -s->wi, Infinity};
      float pdf_pos = -1.f, pdf_dir = -1.f;
      cam.pdf_we(back, &pdf_pos, &pdf_dir);
      EXPECT_EQ(s->pdf_pos, pdf_pos) << c.name;
      EXPECT_EQ(s->pdf_dir, pdf_dir) << c.name;
      EXPECT_GT(s->pdf_dir, 0.f) << c.name;
      EXPECT_EQ(s->We.x, cam.We(back).x) << c.name;
    }
  }
}

TEST(CameraImportance, NoImportanceOutsideTheFilmOrBehindTheCamera) {
  PerspectiveCamera cam = make_camera("\"float fov\" [ 40 ]", Point2i(32, 32));
  Ray centre = *cam.generate_ray(CameraSample{Vec2(16.f)});
  EXPECT_GT(cam.We(centre).x, 0.f);
  EXPECT_EQ(cam.We(Ray{centre.o, -centre.d}).x, 0.f);
  // 60 degrees off the axis is outside a 40 degree field of view.
  Vec3 side = glm::normalize(glm::cross(centre.d, Vec3(0.f, 1.f, 0.f)));
  Vec3 off = glm::normalize(centre.d * 0.5f + side * 0.866f);
  EXPECT_EQ(cam.We(Ray{centre.o, off}).x, 0.f);
  float pos, dir;
  cam.pdf_we(Ray{centre.o, off}, &pos, &dir);
  EXPECT_EQ(dir, 0.f);
  EXPECT_FALSE(cam.sample_wi(centre.o - 3.f * centre.d, Vec2(0.5f)).has_value());
}
