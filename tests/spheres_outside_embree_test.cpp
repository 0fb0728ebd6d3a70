// A scene with a few whole spheres tests them itself, before Embree (EmbreeScene, "spheres outside
// Embree"); with more than it takes, every sphere stays Embree user geometry. Both ways must give
// the same answers: the same nearest hit (bit for bit), the same occlusion, the same packets, for
// rays from anywhere in a closed box, rays leaving the spheres' surfaces both ways, and rays whose
// tmax ends before, at and after the spheres.
#include "scene/embree_scene.h"

#include <penumbra/rng.h>
#include <penumbra/sampling.h>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <span>
#include <vector>

using namespace penumbra;

namespace {

// A closed box [-1, 1]^3 (12 triangles, outward normals do not matter here).
std::unique_ptr<TriangleMesh> box() {
  auto mesh = std::make_unique<TriangleMesh>();
  for (int k = 0; k < 8; ++k) mesh->P.push_back(Vec3(k & 1 ? 1.f : -1.f, k & 2 ? 1.f : -1.f, k & 4 ? 1.f : -1.f));
  mesh->indices = {0, 1, 3, 0, 3, 2, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                   2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 3, 7, 1, 7, 5};
  return mesh;
}

// A partition wall across the box at x = 0.6 (two triangles).
std::unique_ptr<TriangleMesh> partition() {
  auto mesh = std::make_unique<TriangleMesh>();
  mesh->P = {Vec3(0.6f, -1.f, -1.f), Vec3(0.6f, 1.f, -1.f), Vec3(0.6f, 1.f, 1.f), Vec3(0.6f, -1.f, 1.f)};
  mesh->indices = {0, 1, 2, 0, 2, 3};
  return mesh;
}

std::unique_ptr<Sphere> sphere(Vec3 c, float r) {
  return std::make_unique<Sphere>(glm::translate(Mat4(1.f), c), r, false);
}

// Two overlapping spheres and one that the partition wall cuts, all inside the closed box. `extra`
// spheres more, tiny and far outside the box where rays do not reach them, push the count past
// what is tested outside Embree.
// With `fourth`, a fourth sphere in the box fills every lane of the scene's pre-test of them all.
void build(EmbreeScene& scene, int extra, bool fourth = false) {
  scene.add_mesh(box(), nullptr, {});
  scene.add_mesh(partition(), nullptr, {});
  scene.add_sphere(sphere(Vec3(-0.35f, -0.3f, -0.5f), 0.4f), nullptr, nullptr);
  scene.add_sphere(sphere(Vec3(0.f, -0.2f, -0.4f), 0.3f), nullptr, nullptr);
  scene.add_sphere(sphere(Vec3(0.55f, 0.5f, 0.3f), 0.3f), nullptr, nullptr);
  if (fourth) scene.add_sphere(sphere(Vec3(0.5f, -0.6f, 0.55f), 0.25f), nullptr, nullptr);
  for (int i = 0; i < extra; ++i)
    scene.add_sphere(sphere(Vec3(1000.f + 3.f * i, 0.f, 0.f), 1e-3f), nullptr, nullptr);
  scene.commit();
}

struct Scenes {
  EmbreeScene outside, inside;  // spheres tested outside Embree / all in Embree
  explicit Scenes(bool fourth = false) {
    build(outside, 0, fourth);
    build(inside, 3, fourth);
  }
};

void expect_same(const std::optional<SurfaceInteraction>& a, const std::optional<SurfaceInteraction>& b, int ray) {
  ASSERT_EQ(bool(a), bool(b)) << "ray " << ray << (b ? " t " + std::to_string(b->t) + " shape " + std::to_string(b->shape_id) : "");
  if (!a) return;
  EXPECT_EQ(a->shape_id, b->shape_id) << "ray " << ray;
  EXPECT_EQ(a->t, b->t) << "ray " << ray;
  EXPECT_EQ(a->p, b->p) << "ray " << ray;
  EXPECT_EQ(a->ng, b->ng) << "ray " << ray;
}

// Rays from random points in the box, or leaving a sphere hit on either side; tmax infinite, or
// ending at a random fraction of the way to the first hit and beyond it.
std::vector<Ray> rays(const EmbreeScene& scene, int n) {
  Pcg32 rng(5, 9);
  std::vector<Ray> out;
  while (static_cast<int>(out.size()) < n) {
    Vec3 o = Vec3(rng.next_float(), rng.next_float(), rng.next_float()) * 1.9f - Vec3(0.95f);
    Vec3 d = sample_uniform_sphere(Vec2(rng.next_float(), rng.next_float()));
    Ray ray{o, d, Infinity};
    if (out.size() % 3 == 1) {  // leave a hit, into or out of the surface
      if (auto hit = scene.intersect(ray)) {
        Vec3 w = sample_uniform_sphere(Vec2(rng.next_float(), rng.next_float()));
        ray = hit->spawn_ray(w);
      }
    }
    if (out.size() % 3 == 2) {
      if (auto hit = scene.intersect(ray)) ray.tmax = hit->t * 2.f * rng.next_float();
    }
    out.push_back(ray);
  }
  return out;
}

}  // namespace

TEST(SpheresOutsideEmbree, OnlyAFewTopLevelSpheresQualify) {
  Scenes s;
  EXPECT_EQ(s.outside.spheres_outside_embree(), 3u);
  EXPECT_EQ(s.inside.spheres_outside_embree(), 0u);
}

TEST(SpheresOutsideEmbree, NearestHitsAndOcclusionAsEmbreeUserGeometry) {
  for (bool fourth : {false, true}) {
    SCOPED_TRACE(fourth ? "four spheres" : "three spheres");
    Scenes s(fourth);
    EXPECT_EQ(s.outside.spheres_outside_embree(), fourth ? 4u : 3u);
    std::vector<Ray> rs = rays(s.inside, 30000);
    int on_sphere = 0, on_fourth = 0, occluded = 0, finite = 0;
    for (size_t i = 0; i < rs.size(); ++i) {
      auto a = s.outside.intersect(rs[i]), b = s.inside.intersect(rs[i]);
      expect_same(a, b, static_cast<int>(i));
      if (b && b->shape_id >= 2) ++on_sphere;  // ids: box, partition, spheres
      if (b && b->shape_id == 5) ++on_fourth;
      bool occ = s.inside.occluded(rs[i]);
      EXPECT_EQ(s.outside.occluded(rs[i]), occ) << "ray " << i;
      occluded += occ;
      finite += std::isfinite(rs[i].tmax);
    }
    // Every kind of ray and answer was exercised.
    EXPECT_GT(on_sphere, 3000);
    EXPECT_GT(finite, 5000);
    EXPECT_GT(occluded, 2000);
    EXPECT_LT(occluded, static_cast<int>(rs.size()) - 2000);
    if (fourth) EXPECT_GT(on_fourth, 300);
  }
}

TEST(SpheresOutsideEmbree, PacketsAsEmbreeUserGeometry) {
  Scenes s;
  std::vector<Ray> rs = rays(s.inside, 8000);
  for (size_t i = 0; i + 8 <= rs.size(); i += 8) {
    const Ray* ptrs[8];
    for (int k = 0; k < 8; ++k) ptrs[k] = k == 3 && i % 16 == 0 ? nullptr : &rs[i + k];
    std::optional<SurfaceInteraction> a[8], b[8];
    s.outside.intersect_coherent(std::span<const Ray* const>(ptrs, 8), a);
    s.inside.intersect_coherent(std::span<const Ray* const>(ptrs, 8), b);
    for (int k = 0; k < 8; ++k) expect_same(a[k], b[k], static_cast<int>(i) + k);
  }
}

// Sphere::intersect() rejects rays in float before its double-precision solve() only when they
// surely miss: on rays that graze the sphere (closest approach within 1e-4 of the radius either
// side), rays from far away and rays leaving the surface, it answers exactly as solve() does.
TEST(SpheresOutsideEmbree, FloatPreTestRejectsOnlyMisses) {
  Pcg32 rng(3, 4);
  int hits = 0, misses = 0;
  for (int i = 0; i < 200000; ++i) {
    float r = std::exp2(8.f * rng.next_float() - 4.f);
    Vec3 c = (Vec3(rng.next_float(), rng.next_float(), rng.next_float()) - 0.5f) * 100.f;
    Sphere s(glm::translate(Mat4(1.f), c), r, false);
    // The line's closest point to the centre, at a distance near r, and a direction across it.
    Vec3 d = sample_uniform_sphere(Vec2(rng.next_float(), rng.next_float()));
    Vec3 side = glm::normalize(glm::cross(d, glm::abs(d.x) < 0.9f ? Vec3(1.f, 0.f, 0.f) : Vec3(0.f, 1.f, 0.f)));
    float approach = r * (i % 4 == 0 ? 1.f + 1e-4f * (2.f * rng.next_float() - 1.f) : 1.2f * rng.next_float());
    float back = i % 3 == 0 ? r * 1e4f * rng.next_float() : 3.f * r * (2.f * rng.next_float() - 1.f);
    Ray ray{c + approach * side - back * d, d * (0.5f + rng.next_float()), Infinity};
    if (i % 5 == 0) ray.o = c + r * glm::normalize(ray.o - c);  // on the surface
    auto fast = s.intersect(ray, 0.f, Infinity), exact = s.solve(ray, 0.f, Infinity);
    ASSERT_EQ(bool(fast), bool(exact)) << "ray " << i;
    if (exact) {
      EXPECT_EQ(*fast, *exact) << "ray " << i;
    }
    (exact ? hits : misses)++;
  }
  EXPECT_GT(hits, 50000);
  EXPECT_GT(misses, 50000);
}
