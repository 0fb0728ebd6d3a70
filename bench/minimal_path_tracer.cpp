#include "minimal_path_tracer.h"

#include <penumbra/bsdf.h>
#include <penumbra/camera.h>
#include <penumbra/error.h>
#include <penumbra/light.h>
#include <penumbra/rng.h>
#include <penumbra/sampling.h>

#include <fmt/core.h>
#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cstring>

namespace penumbra {

namespace {

constexpr float kTnear = 1e-4f;  // where secondary and shadow rays start, instead of offset origins

bool is_lambertian(const Bsdf& bsdf) {
  if (bsdf.flags() != (BsdfReflection | BsdfDiffuse)) return false;
  ShadingContext ctx;
  Rgb a = bsdf.f(Vec3(0.f, 0.f, 1.f), Vec3(0.f, 0.f, 1.f), ctx);
  Rgb b = bsdf.f(Vec3(0.6f, 0.f, 0.8f), Vec3(0.f, -0.28f, 0.96f), ctx);
  return a == b;
}

}  // namespace

MinimalPathTracer::MinimalPathTracer(const EmbreeScene& scene, int max_depth, int rr_depth)
    : scene_(scene), max_depth_(max_depth), rr_depth_(rr_depth) {
  if (!scene.infinite_lights().empty() || scene.has_media() || scene.spheres_outside_embree() > 0)
    throw Error("the minimal path tracer takes only triangles, area lights and no media");
  ShadingContext ctx;
  first_triangle_.assign(scene.geometry_count(), 0);
  for (unsigned id = 0; id < scene.geometry_count(); ++id) {
    EmbreeScene::GeometryView g = scene.geometry_view(id, 0);
    if (!g.mesh || !g.bsdf || !is_lambertian(*g.bsdf))
      throw Error(fmt::format("the minimal path tracer takes only meshes of Lambertian triangles (geometry {})", id));
    first_triangle_[id] = static_cast<uint32_t>(triangles_.size());
    const TriangleMesh& mesh = *g.mesh;
    for (size_t i = 0; i < mesh.triangle_count(); ++i) {
      const Vec3 &p0 = mesh.P[mesh.indices[3 * i]], &p1 = mesh.P[mesh.indices[3 * i + 1]],
                 &p2 = mesh.P[mesh.indices[3 * i + 2]];
      Triangle t;
      t.p0 = p0;
      t.e1 = p1 - p0;
      t.e2 = p2 - p0;
      t.n = mesh.geometric_normal(i, Vec3(1.f / 3.f));
      t.albedo = Pi * g.bsdf->f(Vec3(0.f, 0.f, 1.f), Vec3(0.f, 0.f, 1.f), ctx);
      t.area = 0.5f * glm::length(glm::cross(t.e1, t.e2));
      t.le_front = t.le_back = Rgb(0.f);
      if (const Light* light = scene.geometry_view(id, static_cast<unsigned>(i)).light) {
        Vec3 c = p0 + (t.e1 + t.e2) / 3.f;
        t.le_front = light->L(c, t.n, Vec2(0.f), t.n);
        t.le_back = light->L(c, t.n, Vec2(0.f), -t.n);
        if (scene.light_pmf(light) > 0.f) emitters_.push_back(static_cast<uint32_t>(triangles_.size()));
        emitter_pmf_.resize(triangles_.size() + 1, 0.f);
        emitter_pmf_.back() = scene.light_pmf(light);
      }
      triangles_.push_back(t);
    }
  }
  if (emitters_.empty()) throw Error("the minimal path tracer needs an area light");
  emitter_pmf_.resize(triangles_.size(), 0.f);
  emitter_cdf_.push_back(0.f);
  for (uint32_t e : emitters_) emitter_cdf_.push_back(emitter_cdf_.back() + emitter_pmf_[e]);
}

Rgb MinimalPathTracer::Li(const Ray& camera_ray, uint64_t stream, uint64_t seed, uint64_t* rays) const {
  Pcg32 rng(stream, seed);
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  Rgb L(0.f), beta(1.f);
  Vec3 o = camera_ray.o, d = camera_ray.d;
  float tnear = 0.f, bsdf_pdf = 0.f;
  for (int depth = 0;; ++depth) {
    RTCRayHit rh;
    rh.ray.org_x = o.x, rh.ray.org_y = o.y, rh.ray.org_z = o.z, rh.ray.tnear = tnear;
    rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z, rh.ray.time = 0.f;
    rh.ray.tfar = Infinity, rh.ray.mask = 0xFFFFFFFFu, rh.ray.id = 0, rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_.rtc_scene(), &ctx, &rh);
    ++*rays;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) break;
    const uint32_t index = first_triangle_[rh.hit.geomID] + rh.hit.primID;
    const Triangle& tri = triangles_[index];
    const Vec3 p = o + rh.ray.tfar * d;
    const float cos_o = glm::dot(tri.n, d);  // < 0: the ray arrives on the side of n
    const Rgb& le = cos_o < 0.f ? tri.le_front : tri.le_back;
    if (le.r > 0.f || le.g > 0.f || le.b > 0.f) {
      if (depth == 0) {
        L += beta * le;
      } else {
        float dist2 = rh.ray.tfar * rh.ray.tfar * glm::dot(d, d);
        float light_pdf = emitter_pmf_[index] * dist2 * glm::length(d) / (std::abs(cos_o) * tri.area);
        L += beta * le * power_heuristic(1, bsdf_pdf, 1, light_pdf);
      }
    }
    if (depth == max_depth_) break;
    const Vec3 n = cos_o < 0.f ? tri.n : -tri.n;  // facing the incoming ray
    const Rgb f = tri.albedo * InvPi;

    // Next-event estimation: a light by power, a point on it uniformly by area.
    float u_light = rng.next_float();
    Vec2 u_point(rng.next_float(), rng.next_float());
    size_t k = std::min<size_t>(std::upper_bound(emitter_cdf_.begin(), emitter_cdf_.end(), u_light) -
                                    emitter_cdf_.begin() - 1, emitters_.size() - 1);
    const uint32_t e = emitters_[k];
    const Triangle& light = triangles_[e];
    float su = std::sqrt(u_point.x);
    Vec3 q = light.p0 + su * (1.f - u_point.y) * light.e1 + su * u_point.y * light.e2;
    Vec3 wi = q - p;
    float dist2 = glm::dot(wi, wi), dist = std::sqrt(dist2);
    wi /= dist;
    float cos_i = glm::dot(wi, n), cos_l = glm::dot(wi, light.n);
    const Rgb& le_l = cos_l < 0.f ? light.le_front : light.le_back;
    if (cos_i > 0.f && cos_l != 0.f && (le_l.r > 0.f || le_l.g > 0.f || le_l.b > 0.f)) {
      RTCRay shadow;
      shadow.org_x = p.x, shadow.org_y = p.y, shadow.org_z = p.z, shadow.tnear = kTnear;
      shadow.dir_x = wi.x, shadow.dir_y = wi.y, shadow.dir_z = wi.z, shadow.time = 0.f;
      shadow.tfar = dist * (1.f - 1e-4f), shadow.mask = 0xFFFFFFFFu, shadow.id = 0, shadow.flags = 0;
      rtcOccluded1(scene_.rtc_scene(), &ctx, &shadow);
      ++*rays;
      if (shadow.tfar >= 0.f) {
        float light_pdf = emitter_pmf_[e] * dist2 / (std::abs(cos_l) * light.area);
        float w = power_heuristic(1, light_pdf, 1, cos_i * InvPi);
        L += beta * f * le_l * (cos_i * w / light_pdf);
      }
    }

    // Cosine-weighted continuation: the Lambertian's f cos / pdf is its albedo.
    Vec2 u_dir(rng.next_float(), rng.next_float());
    float u_rr = rng.next_float();
    Vec3 local = sample_cosine_hemisphere(u_dir);
    if (!(local.z > 0.f)) break;
    Frame frame(n);
    d = frame.to_world(local);
    bsdf_pdf = local.z * InvPi;
    beta *= tri.albedo;
    o = p;
    tnear = kTnear;
    if (depth + 1 >= rr_depth_) {
      float q_end = std::max(0.f, 1.f - max_component(beta));
      if (u_rr < q_end) break;
      beta /= 1.f - q_end;
    }
  }
  return L;
}

MinimalRenderResult MinimalPathTracer::render(Point2i res, int spp, int threads, uint64_t seed) const {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  std::vector<Rgb> pixels(static_cast<size_t>(res.x) * res.y, Rgb(0.f));
  tbb::combinable<uint64_t> rays([] { return uint64_t{0}; });
  const Camera& camera = scene_.camera();
  auto t0 = std::chrono::steady_clock::now();
  tbb::parallel_for(tbb::blocked_range<int>(0, res.y), [&](const tbb::blocked_range<int>& rows) {
    uint64_t& n = rays.local();
    for (int y = rows.begin(); y < rows.end(); ++y)
      for (int x = 0; x < res.x; ++x) {
        const size_t pixel = static_cast<size_t>(y) * res.x + x;
        Pcg32 jitter(pixel, seed ^ 0x9e3779b97f4a7c15ull);
        Rgb sum(0.f);
        for (int s = 0; s < spp; ++s) {
          CameraSample cs{Vec2(x + jitter.next_float(), y + jitter.next_float())};
          std::optional<Ray> ray = camera.generate_ray(cs);
          if (ray) sum += Li(*ray, pixel * static_cast<uint64_t>(spp) + s, seed, &n);
        }
        pixels[pixel] = sum / static_cast<float>(spp);
      }
  });
  MinimalRenderResult r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.rays = rays.combine(std::plus<uint64_t>());
  r.samples = static_cast<uint64_t>(res.x) * res.y * spp;
  double total = 0.0;
  for (const Rgb& c : pixels) total += (c.r + c.g + c.b) / 3.0;
  r.mean = total / pixels.size();
  return r;
}

}  // namespace penumbra
