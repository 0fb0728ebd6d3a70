// EmbreeScene::intersect_coherent(), the packets of camera rays the render loop traces for pixel
// integrators, answers every ray as intersect() does: triangles, spheres (user geometry, answered
// lane by lane), instances and empty lanes, with the rays counted once each, in packets of up to 8
// and up to 16 lanes.
#include "render/ray_counter.h"
#include "scene/embree_scene.h"

#include <penumbra/rng.h>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <span>
#include <vector>

using namespace penumbra;

namespace {

std::unique_ptr<TriangleMesh> quad(float z, float half) {
  auto mesh = std::make_unique<TriangleMesh>();
  mesh->P = {Vec3(-half, -half, z), Vec3(half, -half, z), Vec3(half, half, z), Vec3(-half, half, z)};
  mesh->indices = {0, 1, 2, 0, 2, 3};
  return mesh;
}

// A wall behind, a sphere in front of its left half, and an instanced small quad in front of its
// right half: camera-like rays from the origin towards +z meet all three, and some miss everything.
void build(EmbreeScene& scene) {
  scene.add_mesh(quad(5.f, 2.f), nullptr, {});
  scene.add_sphere(std::make_unique<Sphere>(glm::translate(Mat4(1.f), Vec3(-0.8f, 0.f, 3.f)), 0.6f, false), nullptr,
                   nullptr);
  int proto = scene.begin_prototype();
  scene.add_mesh(quad(0.f, 0.4f), nullptr, {});
  scene.end_prototype();
  scene.add_instance(proto, glm::translate(Mat4(1.f), Vec3(0.9f, 0.1f, 2.5f)));
  scene.commit();
}

// 0: no hit; 1, 2, 3: the wall, the sphere and the instance (their geometry ids in order, plus 1).
int what(const std::optional<SurfaceInteraction>& hit) { return hit ? 1 + static_cast<int>(hit->shape_id) : 0; }

}  // namespace

TEST(RayPackets, EveryLaneAnswersAsASingleRay) {
  EmbreeScene scene;
  build(scene);
  Pcg32 rng(11, 12);
  int seen[4] = {0, 0, 0, 0};
  for (int packet = 0; packet < 4000; ++packet) {
    // Packets of 1 to 16 rays around a common direction (8-wide packets up to 8, 16-wide above),
    // with empty lanes among them.
    int n = 1 + packet % 16;
    Vec3 centre(1.2f * (rng.next_float() - 0.5f) * 4.f, 1.2f * (rng.next_float() - 0.5f) * 4.f, 5.f);
    std::vector<std::optional<Ray>> rays(n);
    std::vector<const Ray*> ptrs(n, nullptr);
    for (int k = 0; k < n; ++k) {
      if (packet % 5 == 0 && k == n / 2) continue;  // an empty lane (no camera ray for that pixel)
      Vec3 target = centre + Vec3(0.2f * rng.next_float(), 0.2f * rng.next_float(), 0.f);
      rays[k] = Ray{Vec3(0.f), glm::normalize(target), Infinity};
      ptrs[k] = &*rays[k];
    }
    std::optional<SurfaceInteraction> hits[16];
    for (auto& h : hits) h.emplace();  // stale values must be cleared
    scene.intersect_coherent(std::span<const Ray* const>(ptrs), hits);
    for (int k = 0; k < n; ++k) {
      if (!ptrs[k]) {
        EXPECT_FALSE(hits[k]) << "packet " << packet << " lane " << k;
        continue;
      }
      std::optional<SurfaceInteraction> single = scene.intersect(*ptrs[k]);
      ASSERT_EQ(bool(single), bool(hits[k])) << "packet " << packet << " lane " << k;
      ++seen[what(single)];
      if (!single) continue;
      EXPECT_NEAR(hits[k]->t, single->t, 1e-5f * single->t);
      EXPECT_NEAR(glm::distance(hits[k]->p, single->p), 0.f, 1e-5f);
      EXPECT_NEAR(glm::dot(hits[k]->ng, single->ng), 1.f, 1e-5f);
      EXPECT_EQ(hits[k]->shape_id, single->shape_id);
    }
  }
  // Every kind of answer was exercised.
  for (int i = 0; i < 4; ++i) EXPECT_GT(seen[i], 500) << "kind " << i;
}

// The render loop's blocks follow the packet width: 16 where Embree traces 16-wide packets natively.
TEST(RayPackets, WidthIsWhatEmbreeTracesNatively) {
  EmbreeScene scene;  // the width is the device's: no geometry needed
  RTCDevice device = rtcNewDevice(nullptr);
  ASSERT_NE(device, nullptr);
  bool native16 = rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) != 0;
  rtcReleaseDevice(device);
  EXPECT_EQ(scene.packet_width(), native16 ? 16 : 8);
}

TEST(RayPackets, CountsEachRayOnce) {
  EmbreeScene scene;
  build(scene);
  Ray a{Vec3(0.f), Vec3(0.f, 0.f, 1.f), Infinity}, b{Vec3(0.f), glm::normalize(Vec3(0.3f, 0.f, 1.f)), Infinity};
  const Ray* rays[5] = {&a, nullptr, &b, &a, nullptr};
  std::optional<SurfaceInteraction> hits[5];
  uint64_t before = total_rays();
  scene.intersect_coherent(std::span<const Ray* const>(rays, 5), hits);
  EXPECT_EQ(total_rays() - before, 3u);
  EXPECT_TRUE(hits[0] && hits[2] && hits[3]);
  EXPECT_FALSE(hits[1] || hits[4]);
}

// The packets see the user geometry's cut-outs and the geometry's limits exactly as single rays: a
// ray whose tmax ends before the wall misses it in both.
TEST(RayPackets, HonoursTmax) {
  EmbreeScene scene;
  build(scene);
  Ray shortened{Vec3(0.f), Vec3(0.f, 0.f, 1.f), 4.f}, full{Vec3(0.f), Vec3(0.f, 0.f, 1.f), Infinity};
  const Ray* rays[2] = {&shortened, &full};
  std::optional<SurfaceInteraction> hits[2];
  scene.intersect_coherent(std::span<const Ray* const>(rays, 2), hits);
  EXPECT_FALSE(hits[0]);
  ASSERT_TRUE(hits[1]);
  EXPECT_NEAR(hits[1]->t, 5.f, 1e-5f);
}
