// Heap allocations of bidirectional path tracing in steady state: a pixel sample of "bdpt" (camera
// subpath, light subpath, every strategy's connection and MIS weight, the cached techniques' HRR
// and probabilistic connections at every eye vertex) and of "lighttracing" must not allocate once
// the per-thread scratch space exists. The global operator new is replaced in this executable, so
// allocations made inside the core and the plugins (BSDFs, lights, the sampler) count too.
//
// The test links the bidirectional library (libs/bidirectional) that the plugins link.
#include "connect_cached.h"
#include "subpath.h"

#include "parser/scene_description.h"
#include "registry/registry.h"
#include "scene/scene_builder.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

namespace {

std::atomic<bool> counting{false};
std::atomic<uint64_t> allocations{0};

void* counted_alloc(std::size_t n) {
  if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1, std::memory_order_relaxed);
  void* p = std::malloc(n ? n : 1);
  if (!p) throw std::bad_alloc();
  return p;
}

void* counted_alloc_aligned(std::size_t n, std::align_val_t a) {
  if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1, std::memory_order_relaxed);
  std::size_t align = static_cast<std::size_t>(a);
  void* p = std::aligned_alloc(align, (n + align - 1) / align * align);
  if (!p) throw std::bad_alloc();
  return p;
}

}  // namespace

void* operator new(std::size_t n) { return counted_alloc(n); }
void* operator new[](std::size_t n) { return counted_alloc(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted_alloc(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted_alloc(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new(std::size_t n, std::align_val_t a) { return counted_alloc_aligned(n, a); }
void* operator new[](std::size_t n, std::align_val_t a) { return counted_alloc_aligned(n, a); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

using namespace penumbra;
using namespace penumbra::bdpt;

namespace {

// A closed box: quad and sphere area lights, a point light, diffuse walls, a glossy metal sphere
// (HRR eye lobes), a glass sphere (specular vertices), a thin-lens camera.
const char* kBox = R"(
LookAt 0 1 3.4  0 0.9 0  0 1 0
Camera "perspective" "float fov" [ 45 ] "float lensradius" [ 0.03 ] "float focaldistance" [ 3.4 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
Sampler "independent" "integer pixelsamples" [ 4 ]
WorldBegin
Material "diffuse" "rgb reflectance" [ 0.7 0.7 0.7 ]
Shape "trianglemesh" "point3 P" [ -1 0 1  1 0 1  1 0 -1  -1 0 -1 ] "integer indices" [ 0 1 2  0 2 3 ]
Shape "trianglemesh" "point3 P" [ -1 2 1  -1 2 -1  1 2 -1  1 2 1 ] "integer indices" [ 0 1 2  0 2 3 ]
Shape "trianglemesh" "point3 P" [ -1 0 -1  1 0 -1  1 2 -1  -1 2 -1 ] "integer indices" [ 0 1 2  0 2 3 ]
Shape "trianglemesh" "point3 P" [ -1 0 1  -1 0 -1  -1 2 -1  -1 2 1 ] "integer indices" [ 0 1 2  0 2 3 ]
Shape "trianglemesh" "point3 P" [ 1 0 -1  1 0 1  1 2 1  1 2 -1 ] "integer indices" [ 0 1 2  0 2 3 ]
Shape "trianglemesh" "point3 P" [ -1 0 3.5  1 0 3.5  1 2 3.5  -1 2 3.5 ] "integer indices" [ 0 2 1  0 3 2 ]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 10 10 10 ]
  Shape "trianglemesh" "point3 P" [ -0.3 1.98 -0.3  0.3 1.98 -0.3  0.3 1.98 0.3  -0.3 1.98 0.3 ] "integer indices" [ 0 1 2  0 2 3 ]
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 6 5 4 ]
  Translate 0.6 1.5 -0.5
  Shape "sphere" "float radius" [ 0.08 ]
AttributeEnd
LightSource "point" "rgb I" [ 0.5 0.5 0.5 ] "point3 from" [ -0.6 1.6 0.4 ]
AttributeBegin
  Material "conductor" "float roughness" [ 0.05 ] "bool remaproughness" false
  Translate -0.45 0.35 -0.2
  Shape "sphere" "float radius" [ 0.35 ]
AttributeEnd
AttributeBegin
  Material "dielectric" "float eta" [ 1.5 ]
  Translate 0.45 0.3 0.3
  Shape "sphere" "float radius" [ 0.3 ]
AttributeEnd
)";

struct Counts {
  uint64_t samples = 0, connections = 0, allocations = 0;
};

// Pixel samples [first, first + count) of every pixel, as bdpt's sample() takes them: the camera
// subpath, the light subpath, every strategy (s, t), and (with `cached`) the cached techniques at
// every eye vertex t >= 2. Allocations are counted only when `count_them`.
Counts run_samples(const Context& ctx, const BuiltScene& built, const CachedConnector* cached, uint32_t first,
                   int count, bool count_them) {
  const Scene& scene = *built.scene;
  std::unique_ptr<Sampler> sampler = built.sampler->clone();
  Point2i res = built.film->resolution();
  const int max_depth = ctx.config.max_depth;
  std::vector<Vertex> camera(max_depth + 2), light(max_depth + 1);
  Counts out;
  Rgb sink(0.f);
  allocations = 0;
  counting = count_them;
  for (int y = 0; y < res.y; ++y)
    for (int x = 0; x < res.x; ++x)
      for (int i = 0; i < count; ++i) {
        Point2i pixel(x, y);
        uint32_t index = first + static_cast<uint32_t>(i);
        sampler->start_pixel_sample(pixel, index);
        CameraSample cs{Vec2(pixel) + sampler->get_pixel_2d(), sampler->get_2d()};
        std::optional<Ray> ray = scene.camera().generate_ray(cs);
        if (!ray) continue;
        ++out.samples;
        PathSampler ps(*sampler, pixel, index);
        int nc = camera_subpath(ctx, *ray, ps, camera.data());
        int nl = light_subpath(ctx, ps, light.data());
        for (int t = 1; t <= nc; ++t)
          for (int s = 0; s <= nl; ++s) {
            int depth = s + t - 2;
            if ((s == 1 && t == 1) || depth < 0 || depth > max_depth) continue;
            Connection c = connect(ctx, light.data(), s, camera.data(), t, ps);
            sink += c.weighted;
            ++out.connections;
          }
        if (cached)
          for (int t = 2; t <= nc; ++t)
            cached->connect_eye_vertex(ctx, camera.data(), t, pixel, index, [&](const Connection& c, int) {
              sink += c.weighted;
              ++out.connections;
            });
        // Light tracing: every light vertex to the lens, unweighted.
        Vertex lens;
        lens.kind = VertexKind::Camera;
        for (int s = 1; s <= nl; ++s) sink += connect(ctx, light.data(), s, &lens, 1, ps, false).L;
      }
  counting = false;
  out.allocations = allocations.load();
  EXPECT_TRUE(is_finite(sink));
  return out;
}

// The counter sees allocations made inside plugins (here: a sampler plugin's clone()).
TEST(BdptAllocations, CounterSeesAllocationsInPlugins) {
  Registry registry(Registry::default_search_dirs());
  SceneDescription d = parse_scene_string(kBox);
  BuiltScene built = build_scene(d, registry);
  allocations = 0;
  counting = true;
  std::unique_ptr<Sampler> clone = built.sampler->clone();
  counting = false;
  EXPECT_GE(allocations.load(), 1u);
}

TEST(BdptAllocations, NoHeapAllocationPerPixelSampleInSteadyState) {
  Registry registry(Registry::default_search_dirs());
  SceneDescription d = parse_scene_string(kBox);
  BuiltScene built = build_scene(d, registry);
  LightChooser lights(*built.scene, false);
  Config config;
  config.max_depth = 6;
  Context ctx{*built.scene, lights, config};
  run_samples(ctx, built, nullptr, 0, 2, false);  // warm-up: per-thread scratch space
  Counts c = run_samples(ctx, built, nullptr, 2, 8, true);
  EXPECT_GT(c.connections, 10000u);
  EXPECT_EQ(c.allocations, 0u) << c.allocations << " allocations in " << c.samples << " pixel samples ("
                               << static_cast<double>(c.allocations) / c.samples << " per sample)";
}

TEST(BdptAllocations, NoHeapAllocationPerPixelSampleWithCachedTechniques) {
  Registry registry(Registry::default_search_dirs());
  SceneDescription d = parse_scene_string(kBox);
  BuiltScene built = build_scene(d, registry);
  LightChooser lights(*built.scene, false);
  Config config;
  config.max_depth = 5;
  CachedOptions options;
  options.hrr = true;
  options.hrr_max_alpha = 1.0;
  options.probconnect = true;
  CachedConnector cached(options, config.max_depth);
  TechniqueSet techniques;
  techniques.cached = &cached;
  Context ctx{*built.scene, lights, config, &techniques};
  Point2i res = built.film->resolution();
  cached.prepare(ctx, *built.sampler, res);
  cached.begin_iteration(ctx, *built.sampler, res, 0);
  run_samples(ctx, built, &cached, 0, 1, false);  // warm-up
  Counts c = run_samples(ctx, built, &cached, 1, 4, true);
  EXPECT_GT(c.connections, 10000u);
  EXPECT_EQ(c.allocations, 0u) << c.allocations << " allocations in " << c.samples << " pixel samples ("
                               << static_cast<double>(c.allocations) / c.samples << " per sample)";
}

}  // namespace
