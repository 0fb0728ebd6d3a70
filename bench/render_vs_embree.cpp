// Measures, in one run on the same geometry, (1) the path tracer's whole-render ray throughput on the
// Cornell box and (2) Embree's raw throughput for incoherent closest-hit and shadow rays with no
// shading, and prints their ratio.
// Usage: penumbra-bench-render [--scene FILE] [--threads N] [--spp N] [--res N] [--rays N] [--rounds N]
//                              [--raw-only] [--camera-packets] [--minimal] [--json] [--idle-contention X]
//   --rounds N        the render and the raw measurement alternate N times per thread count (default 5);
//                     each round gives a ratio, and the median ratio and the range are reported, so a
//                     drift of the machine between the two measurements moves one round, not the figure
//   --raw-only        skips the path-tracer render: only raw Embree on the scene's geometry (any scene file;
//                     spheres the scene tests outside Embree, up to four, are not in Embree's scene)
//   --camera-packets  only the scene's camera rays at its film resolution (about --rays of them), one
//                     at a time and as 8-wide and 16-wide packets
//   --minimal         each round also renders with bench/minimal_path_tracer.h, the same estimator written
//                     straight on Embree (Lambertian triangles and area lights only), and reports its ray
//                     rate and ratio to raw Embree: what the renderer's ratio could be without its overheads;
//                     and once more with the renderer's robust ray origins (error-bounded offsets) instead
//                     of a fixed tnear, the one overhead a correct renderer cannot drop
//   --json            one JSON object per thread count on stdout instead of the table: the medians, and
//                     each round's ratio and rates in order (bench/ratio-runs.sh summarises many runs)
//   --idle-contention X  the core-contention index of an idle core on this machine (the smallest
//                     `idle_core_contention` of earlier runs; bench/ratio-runs.sh prints it)
// Each round is bracketed by three probes of core contention (bench/core_contention.h: before the
// render, between it and raw Embree, after both), and ten more come first. The table prints each
// round's largest index over the idle value and the median ratio of the rounds within 10 % of it
// (quiet rounds). The idle value is --idle-contention, or else this run's smallest index, which a run
// that falls wholly inside a contended phase does not find. The JSON has `round_core_contention`,
// `idle_core_contention` (this run's smallest), `idle_reference` (the idle value used), `quiet_rounds`
// and `ratio_quiet`. Another guest's thread on the same physical core slows the path tracer about
// twice as much as raw Embree, so the ratio of a contended round says more about the host than the
// renderer.
#include "core_contention.h"
#include "minimal_path_tracer.h"
#include "number_options.h"
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "render/render_session.h"
#include "scene/scene_builder.h"
#include "timing.h"

#include <penumbra/memory.h>
#include <penumbra/rng.h>
#include <penumbra/sampling.h>

#include <embree3/rtcore.h>
#include <fmt/core.h>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

using namespace penumbra;

// The layers of the minimal path tracer measured with --minimal, each adding the renderer's pieces.
constexpr unsigned kLayerSets[4] = {kMinimalOnly, kHits, kHits | kLights, kHits | kLights | kBsdf};

namespace {

using bench::median;
using bench::now;

// A closest-hit query from o along d over (0, infinity), as Embree takes it.
RTCRayHit closest_hit_query(const Vec3& o, const Vec3& d) {
  RTCRayHit rh;
  std::memset(&rh, 0, sizeof rh);
  rh.ray.org_x = o.x, rh.ray.org_y = o.y, rh.ray.org_z = o.z;
  rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
  rh.ray.tfar = Infinity;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

struct RawResult {
  double closest_mrays, shadow_mrays, mixed_mrays;
};

// Incoherent rays: origins uniform in the scene bounds, directions uniform on the sphere; shadow rays
// join pairs of closest-hit points. The rays are made once per run and every measurement traces
// copies of them. Made anew in each round, their 400 MB (at 2 M rays) were faulted in and unmapped
// again around every render; the renders on two threads that followed rounds on one were then 3-9 %
// slower than in a run of two-thread rounds only in six of six alternated pairs of runs, and after
// the change in three of six (docs/benchmarks.md).
class RawRays {
 public:
  // The shadow rays join hits in `scene`, so every measurement traces that scene.
  RawRays(RTCScene scene, const Bounds3& b, size_t n) : scene_(scene) {
    // The four buffers are announced before they are allocated: an error naming --rays, not bad_alloc.
    require_memory(static_cast<uint64_t>(n) * 2 * (sizeof(RTCRayHit) + sizeof(RTCRay)), "--rays: raw Embree's rays",
                   fmt::format("{} closest-hit and {} shadow rays, each with a copy to trace", n, n));
    rays_.resize(n);
    work_.resize(n);
    shadow_.resize(n);
    shadow_work_.resize(n);
    for (size_t i = 0; i < n; ++i) {
      Pcg32 rng(i, 7);
      Vec3 o = b.min + (b.max - b.min) * Vec3(rng.next_float(), rng.next_float(), rng.next_float());
      rays_[i] = closest_hit_query(o, sample_uniform_sphere(Vec2(rng.next_float(), rng.next_float())));
    }
    // Shadow rays between consecutive hit points (the hits of one untimed pass).
    work_ = rays_;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (size_t i = 0; i < n; ++i) rtcIntersect1(scene, &ctx, &work_[i]);
    for (size_t i = 0; i < n; ++i) {
      const RTCRayHit& a = work_[i];
      const RTCRayHit& c = work_[(i * 7919 + 1) % n];
      auto hit_point = [](const RTCRayHit& h) {
        float t = std::isfinite(h.ray.tfar) ? h.ray.tfar * 0.999f : 1.f;
        return Vec3(h.ray.org_x + t * h.ray.dir_x, h.ray.org_y + t * h.ray.dir_y, h.ray.org_z + t * h.ray.dir_z);
      };
      Vec3 p = hit_point(a), q = hit_point(c);
      RTCRay& r = shadow_[i];
      std::memset(&r, 0, sizeof r);
      r.org_x = p.x, r.org_y = p.y, r.org_z = p.z;
      r.dir_x = q.x - p.x, r.dir_y = q.y - p.y, r.dir_z = q.z - p.z;
      r.tnear = 1e-3f;
      r.tfar = 0.999f;
      r.mask = 0xFFFFFFFFu;
    }
  }

  // Traces copies of the rays (the copies are made before timing, into buffers kept between calls).
  RawResult measure(int threads) {
    const size_t n = rays_.size();
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    std::copy(rays_.begin(), rays_.end(), work_.begin());
    std::copy(shadow_.begin(), shadow_.end(), shadow_work_.begin());
    double t0 = now();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& r) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      for (size_t i = r.begin(); i < r.end(); ++i) rtcIntersect1(scene_, &ctx, &work_[i]);
    });
    double t_closest = now() - t0;
    t0 = now();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& r) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      for (size_t i = r.begin(); i < r.end(); ++i) rtcOccluded1(scene_, &ctx, &shadow_work_[i]);
    });
    double t_shadow = now() - t0;
    return {n / t_closest * 1e-6, n / t_shadow * 1e-6, 2.0 * n / (t_closest + t_shadow) * 1e-6};
  }

 private:
  RTCScene scene_;
  std::vector<RTCRayHit> rays_, work_;
  std::vector<RTCRay> shadow_, shadow_work_;
};

// The scene's camera rays through every pixel centre, traced one at a time (rtcIntersect1), as
// 8-wide packets of 4x2 pixels (rtcIntersect8, coherent) and as 16-wide packets of 4x4 pixels
// (rtcIntersect16): what the render loop's packets of camera rays gain (docs/benchmarks.md, "Camera
// rays as packets"). All return the same hits except along edges between primitives, where the
// intersectors round differently (counted against the single rays; more than 0.1 % of the pixels is
// an error). Mrays/s on `threads` threads; every way fills its query structures inside the timing,
// as a renderer would for each ray.
struct CameraRays {
  double single_mrays, packet8_mrays, packet16_mrays;
  size_t differ8, differ16;  // pixels whose packet ray hit other geometry than the single ray
};

// Seconds to trace `rays` (w x h, row-major) `repeats` times as packets of kWidth lanes covering 4 x
// (kWidth / 4) pixels; each ray's geometry id goes to `hit`.
template <int kWidth>
double trace_packets(RTCScene scene, const std::vector<Ray>& rays, int w, int h, int repeats,
                     std::vector<unsigned>& hit) {
  using Packet = std::conditional_t<kWidth == 16, RTCRayHit16, RTCRayHit8>;
  constexpr int rows = kWidth / 4;
  double t0 = now();
  for (int rep = 0; rep < repeats; ++rep)
    tbb::parallel_for(tbb::blocked_range<int>(0, h / rows), [&](const tbb::blocked_range<int>& r) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      alignas(64) int valid[kWidth];
      alignas(64) Packet p;
      for (int py = r.begin(); py < r.end(); ++py)
        for (int x0 = 0; x0 < w; x0 += 4) {
          std::memset(&p, 0, sizeof p);
          for (int k = 0; k < kWidth; ++k) {
            const Ray& ray = rays[static_cast<size_t>(rows * py + k / 4) * w + x0 + k % 4];
            valid[k] = -1;
            p.ray.org_x[k] = ray.o.x, p.ray.org_y[k] = ray.o.y, p.ray.org_z[k] = ray.o.z;
            p.ray.dir_x[k] = ray.d.x, p.ray.dir_y[k] = ray.d.y, p.ray.dir_z[k] = ray.d.z;
            p.ray.tfar[k] = Infinity;
            p.ray.mask[k] = 0xFFFFFFFFu;
            p.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
          }
          if constexpr (kWidth == 16) rtcIntersect16(valid, scene, &ctx, &p);
          else rtcIntersect8(valid, scene, &ctx, &p);
          for (int k = 0; k < kWidth; ++k)
            hit[static_cast<size_t>(rows * py + k / 4) * w + x0 + k % 4] = p.hit.geomID[k];
        }
    });
  return now() - t0;
}

CameraRays camera_rays(RTCScene scene, const Camera& camera, Point2i res, int threads, int repeats) {
  const int w = (res.x + 3) / 4 * 4, h = (res.y + 3) / 4 * 4;  // whole packets; extra pixels repeat
  std::vector<Ray> rays(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Vec2 centre(std::min(x, res.x - 1) + 0.5f, std::min(y, res.y - 1) + 0.5f);
      std::optional<Ray> r = camera.generate_ray(CameraSample{centre});
      rays[static_cast<size_t>(y) * w + x] = r ? *r : Ray{Vec3(0.f), Vec3(0.f, 0.f, 1.f), Infinity};
    }
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  std::vector<unsigned> single_hit(rays.size()), hit8(rays.size()), hit16(rays.size());
  double t0 = now();
  for (int rep = 0; rep < repeats; ++rep)
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& r) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      for (int y = r.begin(); y < r.end(); ++y)
        for (int x = 0; x < w; ++x) {
          size_t i = static_cast<size_t>(y) * w + x;
          RTCRayHit rh = closest_hit_query(rays[i].o, rays[i].d);
          rtcIntersect1(scene, &ctx, &rh);
          single_hit[i] = rh.hit.geomID;
        }
    });
  double t_single = now() - t0;
  double t8 = trace_packets<8>(scene, rays, w, h, repeats, hit8);
  double t16 = trace_packets<16>(scene, rays, w, h, repeats, hit16);
  size_t differ8 = 0, differ16 = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    differ8 += single_hit[i] != hit8[i];
    differ16 += single_hit[i] != hit16[i];
  }
  if (std::max(differ8, differ16) * 1000 > rays.size())
    throw Error(fmt::format("camera rays: packets and single rays hit different geometry at {} (8-wide) and {} "
                            "(16-wide) of {} pixels (spheres, disks and cylinders are user geometry that answers "
                            "single rays only)",
                            differ8, differ16, rays.size()));
  double n = static_cast<double>(rays.size()) * repeats;
  return {n / t_single * 1e-6, n / t8 * 1e-6, n / t16 * 1e-6, differ8, differ16};
}

}  // namespace

int main(int argc, char** argv) {
  int spp = 32, res = 256, rounds = 5, threads_option = 0;
  size_t n_rays = 2'000'000;
  bool raw_only = false, json = false, camera_packets = false, minimal = false;
  double idle_option = 0;
  std::string scene_file = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt";
  CLI::App app{"The path tracer's ray rate against raw Embree on the same geometry"};
  app.add_option("--scene", scene_file, "pbrt-v4 scene file (default: the bundled Cornell box)")
      ->check(CLI::ExistingFile);
  app.add_option("--threads", threads_option, "one thread count (default: 1, then 2)")
      ->check(cli::whole_number(1, 4096, "a whole number of threads from 1 to 4096"));
  app.add_option("--spp", spp, "samples per pixel of each render (default 32)")->check(cli::positive_whole_number());
  app.add_option("--res", res, "square film resolution (default 256)")
      ->check(cli::whole_number(1, 65536, "a whole number of pixels from 1 to 65536"));
  app.add_option("--rays", n_rays, "rays of each raw Embree measurement (default 2000000)")
      ->check(cli::whole_number(1, 1'000'000'000, "a whole number of rays from 1 to 10^9"));
  app.add_option("--rounds", rounds, "alternated rounds of render and raw Embree (default 5)")
      ->check(cli::whole_number(1, 1000, "a whole number of rounds from 1 to 1000"));
  app.add_flag("--raw-only", raw_only, "only raw Embree on the scene's geometry");
  app.add_flag("--camera-packets", camera_packets, "only the camera rays, one at a time and as 8- and 16-wide packets");
  app.add_flag("--minimal", minimal, "also the minimal path tracer on raw Embree, in every round");
  app.add_flag("--json", json, "one JSON object per thread count instead of the table");
  app.add_option("--idle-contention", idle_option,
                 "the core-contention index of an idle core on this machine (default: this run's smallest)")
      ->check(cli::positive_number());
  if (std::optional<int> exit_code = cli::parse_tool_options(app, argc, argv, "penumbra-bench-render:"))
    return *exit_code;
  std::vector<int> thread_counts = threads_option > 0 ? std::vector<int>{threads_option} : std::vector<int>{1, 2};
  try {
    if (minimal && (raw_only || camera_packets)) throw Error("--minimal goes with the render, not --raw-only or --camera-packets");
    SceneDescription desc = parse_scene_file(scene_file);
    if (minimal) {  // the minimal tracer uses this scene's camera at the render's resolution
      desc.film.params.set_int("xresolution", res);
      desc.film.params.set_int("yresolution", res);
    }
    Registry registry(Registry::default_search_dirs());
    BuiltScene built = build_scene(desc, registry);
    std::optional<MinimalPathTracer> minimal_tracer;
    if (minimal)
      minimal_tracer.emplace(*built.scene, desc.integrator.params.get_int("maxdepth", 5),
                             desc.integrator.params.get_int("rrdepth", 3));
    if (size_t n = built.scene->spheres_outside_embree())
      fmt::print(stderr, "note: {} sphere(s) of {} are tested outside Embree (EmbreeScene); the raw Embree "
                 "figures leave them out\n", n, scene_file);
    if (camera_packets) {
      Point2i film_res = built.film->resolution();
      int repeats = static_cast<int>(std::max<size_t>(1, n_rays / (static_cast<size_t>(film_res.x) * film_res.y)));
      for (int threads : thread_counts) {
        CameraRays c = camera_rays(built.scene->rtc_scene(), built.scene->camera(), film_res, threads, repeats);
        fmt::print("scene {}: {} triangles, {}x{} camera rays, {} threads: one at a time {:.2f}, 8-wide packets "
                   "{:.2f} ({:.2f}x; {} pixels hit other geometry), 16-wide packets {:.2f} Mrays/s ({:.2f}x; {}); "
                   "Embree's native 16-wide packets: {}\n",
                   scene_file, built.scene->triangle_count(), film_res.x, film_res.y, threads, c.single_mrays,
                   c.packet8_mrays, c.packet8_mrays / c.single_mrays, c.differ8, c.packet16_mrays,
                   c.packet16_mrays / c.single_mrays, c.differ16,
                   built.scene->packet_width() == 16 ? "yes" : "no (emulated)");
      }
      return 0;
    }
    // Rounds of (path render, raw Embree) on each thread count; rates and ratios are medians over rounds.
    struct Rounds {
      std::vector<double> path_mrays, path_msamples, closest, shadow, mixed, ratio;
      std::vector<double> minimal_mrays, minimal_ratio;  // with --minimal
      std::vector<double> robust_mrays, robust_ratio, robust_ns;  // the minimal tracer with robust ray origins
      std::vector<double> path_ns, layer_ns[4];          // nanoseconds per sample: path, and the layers
      std::vector<double> contention;  // per round: the largest core-contention index of its probes
      double idle_contention = 0;      // the smallest index of all probes
      double idle_reference = 0;       // what rounds are compared with: --idle-contention, or the above
      std::vector<double> quiet_ratio;  // of the rounds whose probes all stayed within 10 % of idle
      double path_rays_per_sample = 0, path_mean = 0, minimal_rays_per_sample = 0, minimal_mean = 0;
    };
    RawRays raw_rays(built.scene->rtc_scene(), built.scene->bounds(), n_rays);
    auto measure = [&](int threads) {
      Rounds r;
      // The idle value is the smallest index seen: ten probes first, 20 ms apart, then the rounds'.
      // Contention comes and goes within a second even in a contended phase, so one of them
      // usually finds the core to itself.
      r.idle_contention = Infinity;
      for (int k = 0; k < 10; ++k) {
        r.idle_contention = std::min(r.idle_contention, bench::probe_cores(threads));
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      for (int round = 0; round < rounds; ++round) {
        // The probes bracket the render and the raw measurement (bench/core_contention.h).
        double probes[3];
        probes[0] = bench::probe_cores(threads);
        if (!raw_only) {
          RenderSettings settings;
          settings.scene_file = scene_file;
          settings.spp = spp;
          settings.resolution = std::make_pair(res, res);
          settings.threads = threads;
          settings.quiet = true;
          RenderResult result = render(settings);
          const RenderStats& s = result.stats;
          r.path_mrays.push_back(s.mrays_per_second());
          r.path_msamples.push_back(s.pixels * double(s.spp) / s.seconds * 1e-6);
          r.path_rays_per_sample = s.rays / (s.pixels * double(s.spp));
          r.path_ns.push_back(s.seconds / (s.pixels * double(s.spp)) * 1e9);
          double total = 0;
          for (float v : result.image.pixels) total += v;
          r.path_mean = total / result.image.pixels.size();
        }
        if (minimal_tracer) {
          MinimalRenderResult m = minimal_tracer->render(Point2i(res, res), spp, threads, round);
          r.minimal_mrays.push_back(m.rays / m.seconds * 1e-6);
          r.minimal_rays_per_sample = m.rays / double(m.samples);
          r.minimal_mean = m.mean;
          // The yardstick must compute what the path integrator computes: their images' means agree to
          // 0.02-0.15 % on the bench scenes (box filter and flat normals against Gaussian and
          // interpolated ones); a missing or doubled term shows as a difference of whole percents.
          if (r.path_mean > 0 && std::abs(r.minimal_mean - r.path_mean) > 0.01 * r.path_mean)
            throw Error(fmt::format("the minimal path tracer's image mean {:.5f} differs from the path integrator's "
                                    "{:.5f} by more than 1 %: it does not compute the same estimator on {}",
                                    r.minimal_mean, r.path_mean, scene_file));
          r.layer_ns[0].push_back(m.seconds / m.samples * 1e9);
          for (int k = 1; k < 4; ++k) {
            MinimalRenderResult layered = minimal_tracer->render(Point2i(res, res), spp, threads, round, kLayerSets[k]);
            r.layer_ns[k].push_back(layered.seconds / layered.samples * 1e9);
          }
          MinimalRenderResult robust = minimal_tracer->render(Point2i(res, res), spp, threads, round, kRobust);
          if (r.path_mean > 0 && std::abs(robust.mean - r.path_mean) > 0.01 * r.path_mean)
            throw Error(fmt::format("the minimal path tracer with robust ray origins has image mean {:.5f}, the path "
                                    "integrator {:.5f}: they differ by more than 1 % on {}",
                                    robust.mean, r.path_mean, scene_file));
          r.robust_ns.push_back(robust.seconds / robust.samples * 1e9);
          r.robust_mrays.push_back(robust.rays / robust.seconds * 1e-6);
        }
        probes[1] = bench::probe_cores(threads);
        RawResult raw = raw_rays.measure(threads);
        probes[2] = bench::probe_cores(threads);
        r.contention.push_back(*std::max_element(probes, probes + 3));
        r.idle_contention = std::min(r.idle_contention, *std::min_element(probes, probes + 3));
        r.closest.push_back(raw.closest_mrays);
        r.shadow.push_back(raw.shadow_mrays);
        r.mixed.push_back(raw.mixed_mrays);
        if (!raw_only) r.ratio.push_back(r.path_mrays.back() / raw.mixed_mrays);
        if (minimal_tracer) {
          r.minimal_ratio.push_back(r.minimal_mrays.back() / raw.mixed_mrays);
          r.robust_ratio.push_back(r.robust_mrays.back() / raw.mixed_mrays);
        }
      }
      r.idle_reference = idle_option > 0 ? idle_option : r.idle_contention;
      if (!raw_only)
        for (int round = 0; round < rounds; ++round)
          if (r.contention[round] <= 1.1 * r.idle_reference) r.quiet_ratio.push_back(r.ratio[round]);
      return r;
    };
    if (raw_only || json) {
      for (int threads : thread_counts) {
        Rounds r = measure(threads);
        nlohmann::json j;
        j["scene"] = scene_file;
        j["triangles"] = built.scene->triangle_count();
        j["threads"] = threads;
        j["rays"] = n_rays;
        j["rounds"] = rounds;
        if (!raw_only) {
          j["path_mrays_per_second"] = median(r.path_mrays);
          j["path_msamples_per_second"] = median(r.path_msamples);
          j["ratio"] = median(r.ratio);
          j["ratio_min"] = *std::min_element(r.ratio.begin(), r.ratio.end());
          j["ratio_max"] = *std::max_element(r.ratio.begin(), r.ratio.end());
          j["round_ratios"] = r.ratio;  // each round's, in order, with its two rates
          j["round_path_mrays_per_second"] = r.path_mrays;
          j["quiet_rounds"] = r.quiet_ratio.size();
          if (!r.quiet_ratio.empty()) j["ratio_quiet"] = median(r.quiet_ratio);
        }
        j["round_core_contention"] = r.contention;
        j["idle_core_contention"] = r.idle_contention;
        j["idle_reference"] = r.idle_reference;
        j["round_raw_mixed_mrays_per_second"] = r.mixed;
        if (minimal) {
          j["minimal_mrays_per_second"] = median(r.minimal_mrays);
          j["minimal_ratio"] = median(r.minimal_ratio);
          j["round_minimal_mrays_per_second"] = r.minimal_mrays;
          j["minimal_robust_ratio"] = median(r.robust_ratio);
          j["path_rays_per_sample"] = r.path_rays_per_sample;
          j["minimal_rays_per_sample"] = r.minimal_rays_per_sample;
          j["path_image_mean"] = r.path_mean;
          j["minimal_image_mean"] = r.minimal_mean;
        }
        j["raw_closest_mrays_per_second"] = median(r.closest);
        j["raw_shadow_mrays_per_second"] = median(r.shadow);
        j["raw_mixed_mrays_per_second"] = median(r.mixed);
        if (json) fmt::print("{}\n", j.dump());
        else
          fmt::print("scene {}: {} triangles, {} threads: raw Embree closest-hit {:.2f}, shadow {:.2f}, mixed {:.2f} Mrays/s "
                     "(medians of {} rounds)\n",
                     scene_file, built.scene->triangle_count(), threads, median(r.closest), median(r.shadow),
                     median(r.mixed), rounds);
      }
      return 0;
    }
    fmt::print("scene {}: {} triangles; medians of {} alternated rounds (render, raw Embree); the ratio is the median "
               "of the rounds' ratios [min, max]\n",
               scene_file, built.scene->triangle_count(), rounds);
    fmt::print("{:>7} {:>14} {:>14} {:>14} {:>14} {:>12} {:>8} {:>16}\n", "threads", "path Mrays/s", "Msamples/s",
               "raw hit Mr/s", "raw shad Mr/s", "raw mix Mr/s", "ratio", "[min, max]");
    for (int threads : thread_counts) {
      Rounds r = measure(threads);
      fmt::print("{:>7} {:>14.2f} {:>14.3f} {:>14.2f} {:>14.2f} {:>12.2f} {:>7.1f}% {:>16}\n", threads,
                 median(r.path_mrays), median(r.path_msamples), median(r.closest), median(r.shadow), median(r.mixed),
                 100.0 * median(r.ratio),
                 fmt::format("[{:.1f}, {:.1f}]", 100.0 * *std::min_element(r.ratio.begin(), r.ratio.end()),
                             100.0 * *std::max_element(r.ratio.begin(), r.ratio.end())));
      std::string per_round;
      for (double c : r.contention) per_round += fmt::format(" {:.2f}", c / r.idle_reference);
      fmt::print("{:>7} core contention per round, over idle ({:.2f}{}):{}; ", threads, r.idle_reference,
                 idle_option > 0 ? fmt::format(", this run's smallest {:.2f}", r.idle_contention) : "", per_round);
      if (!r.quiet_ratio.empty())
        fmt::print("ratio over the {} rounds within 10 % of idle {:.1f}%\n", r.quiet_ratio.size(),
                   100.0 * median(r.quiet_ratio));
      else
        fmt::print("no round within 10 % of idle\n");
      if (minimal) {
        fmt::print("{:>7} minimal path tracer on raw Embree: {:.2f} Mrays/s, ratio {:.1f}% [{:.1f}, {:.1f}]; rays per "
                   "sample {:.3f} (path {:.3f}); image mean {:.5f} (path {:.5f})\n",
                   threads, median(r.minimal_mrays), 100.0 * median(r.minimal_ratio),
                   100.0 * *std::min_element(r.minimal_ratio.begin(), r.minimal_ratio.end()),
                   100.0 * *std::max_element(r.minimal_ratio.begin(), r.minimal_ratio.end()),
                   r.minimal_rays_per_sample, r.path_rays_per_sample, r.minimal_mean, r.path_mean);
        fmt::print("{:>7} minimal path tracer with robust ray origins: ratio {:.1f}% [{:.1f}, {:.1f}]\n", threads,
                   100.0 * median(r.robust_ratio), 100.0 * *std::min_element(r.robust_ratio.begin(), r.robust_ratio.end()),
                   100.0 * *std::max_element(r.robust_ratio.begin(), r.robust_ratio.end()));
        fmt::print("{:>7} ns per sample (medians): minimal {:.0f} (robust origins {:.0f}), + hit records {:.0f}, "
                   "+ light sampling {:.0f}, + BSDF objects {:.0f}, path integrator {:.0f}\n", threads,
                   median(r.layer_ns[0]), median(r.robust_ns), median(r.layer_ns[1]), median(r.layer_ns[2]),
                   median(r.layer_ns[3]), median(r.path_ns));
      }
    }
  } catch (const Error& e) {
    fmt::print(stderr, "{}\n", e.formatted());
    return 1;
  }
  return 0;
}
