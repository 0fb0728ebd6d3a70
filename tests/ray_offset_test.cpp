// Secondary rays never re-hit the surface they leave, near the origin or far from it, on triangles
// and on spheres (Waechter-Binder offsetting with points rebuilt from barycentrics).
#include "scene/embree_scene.h"

#include <penumbra/rng.h>
#include <penumbra/sampling.h>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <vector>

using namespace penumbra;

namespace {

// Counts rays that leave a surface point and hit the same surface again; the surface is convex or
// flat, so every such hit is acne.
int self_hits_on_plane(float offset, int n) {
  EmbreeScene scene;
  auto mesh = std::make_unique<TriangleMesh>();
  float s = std::max(1.f, offset * 1e-3f);
  mesh->P = {Vec3(offset - s, offset, offset - s), Vec3(offset + s, offset, offset - s),
             Vec3(offset + s, offset, offset + s), Vec3(offset - s, offset, offset + s)};
  mesh->indices = {0, 1, 2, 0, 2, 3};
  scene.add_mesh(std::move(mesh), nullptr, {});
  scene.commit();
  Pcg32 rng(3, 4);
  int self = 0;
  for (int i = 0; i < n; ++i) {
    Vec3 target(offset + s * (rng.next_float() - 0.5f), offset, offset + s * (rng.next_float() - 0.5f));
    Vec3 from = target + Vec3(0.3f, 1.f, -0.2f) * s;
    auto hit = scene.intersect(Ray{from, glm::normalize(target - from)});
    if (!hit) continue;
    // Leave towards the upper side (reflection), at grazing angles too.
    Vec3 d = sample_uniform_sphere(Vec2(rng.next_float(), rng.next_float()));
    d.y = std::abs(d.y) * (i % 2 ? 1e-3f : 1.f);
    d = glm::normalize(d);
    if (scene.intersect(hit->spawn_ray(d))) ++self;
    // Shadow ray to a point above: must be unoccluded.
    if (scene.occluded(spawn_ray_to(hit->p, hit->ng, hit->p + Vec3(0, s, 0), Vec3(0.f)))) ++self;
  }
  return self;
}

}  // namespace

TEST(RayOffset, NoSelfIntersectionNearOrigin) { EXPECT_EQ(self_hits_on_plane(0.f, 20000), 0); }

TEST(RayOffset, NoSelfIntersectionFarFromOrigin) { EXPECT_EQ(self_hits_on_plane(1e5f, 20000), 0); }

TEST(RayOffset, NoSelfIntersectionOnSphereFromOutsideOrInside) {
  EmbreeScene scene;
  scene.add_sphere(std::make_unique<Sphere>(glm::translate(Mat4(1.f), Vec3(1e3f, 0, 0)), 2.f, false), nullptr, nullptr);
  scene.commit();
  Pcg32 rng(5, 6);
  int bad = 0;
  for (int i = 0; i < 20000; ++i) {
    Vec3 from = Vec3(1e3f, 0, 0) + 10.f * sample_uniform_sphere(Vec2(rng.next_float(), rng.next_float()));
    auto hit = scene.intersect(Ray{from, glm::normalize(Vec3(1e3f, 0, 0) - from)});
    ASSERT_TRUE(hit);
    EXPECT_NEAR(glm::distance(hit->p, Vec3(1e3f, 0, 0)), 2.f, 1e-4f);
    Vec3 d = sample_uniform_sphere(Vec2(rng.next_float(), rng.next_float()));
    bool outward = glm::dot(d, hit->ng) > 0.f;
    auto next = scene.intersect(hit->spawn_ray(d));
    if (outward && next) ++bad;   // leaving a convex surface: nothing to hit
    if (!outward && (!next || next->t < 1e-3f)) ++bad;  // going inside: must reach the far side
  }
  EXPECT_EQ(bad, 0);
}

// The bit-level next_float_up/down agree with std::nextafter on every class of finite float.
TEST(RayOffset, NextFloatMatchesNextafter) {
  std::vector<float> values = {0.f, -0.f, 1.f, -1.f, 1e-40f, -1e-40f, 1e38f, -1e38f, 3.4028235e38f, -3.4028235e38f,
                               std::numeric_limits<float>::denorm_min(), -std::numeric_limits<float>::denorm_min()};
  uint32_t state = 7;
  for (int i = 0; i < 100000; ++i) {
    state = state * 1664525u + 1013904223u;
    float v = std::bit_cast<float>(state);
    if (std::isfinite(v)) values.push_back(v);
  }
  for (float v : values) {
    EXPECT_EQ(std::bit_cast<uint32_t>(next_float_up(v)), std::bit_cast<uint32_t>(std::nextafter(v, Infinity))) << v;
    EXPECT_EQ(std::bit_cast<uint32_t>(next_float_down(v)), std::bit_cast<uint32_t>(std::nextafter(v, -Infinity))) << v;
  }
}
