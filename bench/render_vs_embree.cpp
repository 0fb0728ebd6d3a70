// Measures, in one run on the same geometry, (1) the path tracer's whole-render ray throughput on the
// Cornell box and (2) Embree's raw throughput for incoherent closest-hit and shadow rays with no
// shading, and prints their ratio.
// Usage: penumbra-bench-render [--scene FILE] [--threads N] [--spp N] [--res N] [--rays N] [--raw-only] [--json]
//   --raw-only  skips the path-tracer render: only raw Embree on the scene's geometry (any scene file)
//   --json      one JSON object per thread count on stdout instead of the table
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "render/render_session.h"
#include "scene/scene_builder.h"

#include <penumbra/rng.h>
#include <penumbra/sampling.h>

#include <embree3/rtcore.h>
#include <fmt/core.h>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace penumbra;

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct RawResult {
  double closest_mrays, shadow_mrays, mixed_mrays;
};

// Incoherent rays: origins uniform in the scene bounds, directions uniform on the sphere; shadow rays
// join pairs of closest-hit points. Rays are generated before timing.
RawResult raw_embree(RTCScene scene, const Bounds3& b, size_t n, int threads) {
  std::vector<RTCRayHit> rays(n);
  for (size_t i = 0; i < n; ++i) {
    Pcg32 rng(i, 7);
    Vec3 o = b.min + (b.max - b.min) * Vec3(rng.next_float(), rng.next_float(), rng.next_float());
    Vec3 d = sample_uniform_sphere(Vec2(rng.next_float(), rng.next_float()));
    RTCRayHit& rh = rays[i];
    std::memset(&rh, 0, sizeof rh);
    rh.ray.org_x = o.x, rh.ray.org_y = o.y, rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
    rh.ray.tfar = Infinity;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  }
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  std::vector<RTCRayHit> work = rays;
  double t0 = now();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& r) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (size_t i = r.begin(); i < r.end(); ++i) rtcIntersect1(scene, &ctx, &work[i]);
  });
  double t_closest = now() - t0;

  // Shadow rays between consecutive hit points.
  std::vector<RTCRay> shadow(n);
  for (size_t i = 0; i < n; ++i) {
    const RTCRayHit& a = work[i];
    const RTCRayHit& c = work[(i * 7919 + 1) % n];
    auto hit_point = [](const RTCRayHit& h) {
      float t = std::isfinite(h.ray.tfar) ? h.ray.tfar * 0.999f : 1.f;
      return Vec3(h.ray.org_x + t * h.ray.dir_x, h.ray.org_y + t * h.ray.dir_y, h.ray.org_z + t * h.ray.dir_z);
    };
    Vec3 p = hit_point(a), q = hit_point(c);
    RTCRay& r = shadow[i];
    std::memset(&r, 0, sizeof r);
    r.org_x = p.x, r.org_y = p.y, r.org_z = p.z;
    r.dir_x = q.x - p.x, r.dir_y = q.y - p.y, r.dir_z = q.z - p.z;
    r.tnear = 1e-3f;
    r.tfar = 0.999f;
    r.mask = 0xFFFFFFFFu;
  }
  t0 = now();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& r) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (size_t i = r.begin(); i < r.end(); ++i) rtcOccluded1(scene, &ctx, &shadow[i]);
  });
  double t_shadow = now() - t0;
  return {n / t_closest * 1e-6, n / t_shadow * 1e-6, 2.0 * n / (t_closest + t_shadow) * 1e-6};
}

}  // namespace

int main(int argc, char** argv) {
  int spp = 32, res = 256;
  size_t n_rays = 2'000'000;
  bool raw_only = false, json = false;
  std::string scene_file = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt";
  std::vector<int> thread_counts = {1, 2};
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--raw-only")) { raw_only = true; continue; }
    if (!std::strcmp(argv[i], "--json")) { json = true; continue; }
    if (i + 1 >= argc) {
      fmt::print(stderr, "penumbra-bench-render: {} needs a value\n", argv[i]);
      return 2;
    }
    if (!std::strcmp(argv[i], "--spp")) spp = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--res")) res = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--threads")) thread_counts = {std::atoi(argv[i + 1])};
    else if (!std::strcmp(argv[i], "--scene")) scene_file = argv[i + 1];
    else if (!std::strcmp(argv[i], "--rays")) n_rays = std::strtoull(argv[i + 1], nullptr, 10);
    else {
      fmt::print(stderr, "penumbra-bench-render: unknown option {}\n", argv[i]);
      return 2;
    }
    ++i;
  }
  try {
    SceneDescription desc = parse_scene_file(scene_file);
    Registry registry(Registry::default_search_dirs());
    BuiltScene built = build_scene(desc, registry);
    if (raw_only || json) {
      for (int threads : thread_counts) {
        nlohmann::json j;
        j["scene"] = scene_file;
        j["triangles"] = built.scene->triangle_count();
        j["threads"] = threads;
        j["rays"] = n_rays;
        if (!raw_only) {
          RenderSettings settings;
          settings.scene_file = scene_file;
          settings.spp = spp;
          settings.resolution = std::make_pair(res, res);
          settings.threads = threads;
          settings.quiet = true;
          RenderStats s = render(settings).stats;
          j["path_mrays_per_second"] = s.mrays_per_second();
          j["path_msamples_per_second"] = s.pixels * double(s.spp) / s.seconds * 1e-6;
        }
        RawResult raw = raw_embree(built.scene->rtc_scene(), built.scene->bounds(), n_rays, threads);
        j["raw_closest_mrays_per_second"] = raw.closest_mrays;
        j["raw_shadow_mrays_per_second"] = raw.shadow_mrays;
        j["raw_mixed_mrays_per_second"] = raw.mixed_mrays;
        if (json) fmt::print("{}\n", j.dump());
        else
          fmt::print("scene {}: {} triangles, {} threads: raw Embree closest-hit {:.2f}, shadow {:.2f}, mixed {:.2f} Mrays/s\n",
                     scene_file, built.scene->triangle_count(), threads, raw.closest_mrays, raw.shadow_mrays,
                     raw.mixed_mrays);
      }
      return 0;
    }
    fmt::print("scene {}: {} triangles\n", scene_file, built.scene->triangle_count());
    fmt::print("{:>7} {:>14} {:>14} {:>14} {:>14} {:>12} {:>8}\n", "threads", "path Mrays/s", "Msamples/s",
               "raw hit Mr/s", "raw shad Mr/s", "raw mix Mr/s", "ratio");
    for (int threads : thread_counts) {
      RenderSettings settings;
      settings.scene_file = scene_file;
      settings.spp = spp;
      settings.resolution = std::make_pair(res, res);
      settings.threads = threads;
      settings.quiet = true;
      RenderResult r = render(settings);
      const RenderStats& s = r.stats;
      double msamples = s.pixels * double(s.spp) / s.seconds * 1e-6;
      RawResult raw = raw_embree(built.scene->rtc_scene(), built.scene->bounds(), n_rays, threads);
      fmt::print("{:>7} {:>14.2f} {:>14.3f} {:>14.2f} {:>14.2f} {:>12.2f} {:>7.1f}%\n", threads,
                 s.mrays_per_second(), msamples, raw.closest_mrays, raw.shadow_mrays, raw.mixed_mrays,
                 100.0 * s.mrays_per_second() / raw.mixed_mrays);
    }
  } catch (const Error& e) {
    fmt::print(stderr, "{}\n", e.formatted());
    return 1;
  }
  return 0;
}
