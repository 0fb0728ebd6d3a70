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

namespace penumbra {

namespace {

constexpr float kTnear = 1e-4f;  // where secondary and shadow rays start, instead of offset origins
const ShadingContext sctx;       // Lambertian BSDFs read no texture (made once: it is 80 bytes of zeros)

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
      t.bsdf = g.bsdf;
      const Light* light = scene.geometry_view(id, static_cast<unsigned>(i)).light;
      const float pmf = light ? scene.light_pmf(light) : 0.f;
      if (light) {
        Vec3 c = p0 + (t.e1 + t.e2) / 3.f;
        t.le_front = light->L(c, t.n, Vec2(0.f), t.n);
        t.le_back = light->L(c, t.n, Vec2(0.f), -t.n);
        if (pmf > 0.f) emitters_.push_back(static_cast<uint32_t>(triangles_.size()));
      }
      tri_lights_.push_back(light);
      emitter_pmf_.push_back(pmf);
      triangles_.push_back(t);
      other_vertices_.push_back(p1);
      other_vertices_.push_back(p2);
    }
  }
  if (emitters_.empty()) throw Error("the minimal path tracer needs an area light");
  emitter_cdf_.push_back(0.f);
  for (uint32_t e : emitters_) emitter_cdf_.push_back(emitter_cdf_.back() + emitter_pmf_[e]);
}

template <unsigned kLayers>
Rgb MinimalPathTracer::Li(const Ray& camera_ray, uint64_t stream, uint64_t seed, uint64_t* rays) const {
  // Layers stack in order (render() builds 0, 1, 3 and 7, and kRobust alone): Light::pdf_li() reads
  // the hit record.
  static_assert((kLayers & kLights) == 0 || (kLayers & kHits) != 0, "kLights needs kHits");
  static_assert((kLayers & kRobust) == 0 || kLayers == kRobust, "kRobust goes alone");
  constexpr bool robust = (kLayers & kRobust) != 0;
  Pcg32 rng(stream, seed);
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  Rgb L(0.f), beta(1.f);
  Ray ray = camera_ray;
  float tnear = 0.f, bsdf_pdf = 0.f;
  LightSampleContext prev{};  // the vertex that sampled `ray` (kLights)
  for (int depth = 0;; ++depth) {
    // The hit: its triangle, point and the side the ray arrives on.
    // Built where it lives, as the path integrator's is: declared empty and assigned, it would cost
    // a zero-fill and a copy of 192 bytes per bounce that the renderer does not pay.
    std::optional<SurfaceInteraction> si = [&]() -> std::optional<SurfaceInteraction> {
      if constexpr ((kLayers & kHits) != 0) return scene_.intersect(ray);
      else return std::nullopt;
    }();
    uint32_t index;
    float t;
    Vec2 b12(0.f);  // Embree's barycentrics of the hit (kRobust)
    if constexpr ((kLayers & kHits) != 0) {
      ++*rays;
      if (!si) break;
      index = first_triangle_[si->shape_id] + si->prim_id;
      t = si->t;
    } else {
      RTCRayHit rh = embree_query(Ray{ray.o, ray.d, Infinity}, tnear);  // as the renderer writes its queries
      rtcIntersect1(scene_.rtc_scene(), &ctx, &rh);
      ++*rays;
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) break;
      index = first_triangle_[rh.hit.geomID] + rh.hit.primID;
      t = rh.ray.tfar;
      b12 = Vec2(rh.hit.u, rh.hit.v);
    }
    const Triangle& tri = triangles_[index];
    // kRobust: the point from the barycentrics and its error bound, as TriangleMesh::surface() makes them.
    Vec3 p, p_error(0.f);
    if constexpr ((kLayers & kHits) != 0) {
      p = si->p;
    } else if constexpr (robust) {
      const float b0 = 1.f - b12.x - b12.y;
      const Vec3 &p1 = other_vertices_[2 * index], &p2 = other_vertices_[2 * index + 1];
      p = b0 * tri.p0 + b12.x * p1 + b12.y * p2;
      p_error = error_gamma(7) * (abs_each(b0 * tri.p0) + abs_each(b12.x * p1) + abs_each(b12.y * p2));
    } else {
      p = ray.o + t * ray.d;
    }
    const float cos_o = glm::dot(tri.n, ray.d);  // < 0: the ray arrives on the side of n
    const Rgb& le = cos_o < 0.f ? tri.le_front : tri.le_back;
    if (le.r > 0.f || le.g > 0.f || le.b > 0.f) {
      if (depth == 0) {
        L += beta * le;
      } else {
        float light_pdf;
        if constexpr ((kLayers & kLights) != 0) {
          const Light* light = tri_lights_[index];
          light_pdf = scene_.light_pmf(light) * light->pdf_li(prev, ray.d, *si);
        } else {
          float dist2 = t * t * glm::dot(ray.d, ray.d);
          light_pdf = emitter_pmf_[index] * dist2 * glm::length(ray.d) / (std::abs(cos_o) * tri.area);
        }
        L += beta * le * power_heuristic(1, bsdf_pdf, 1, light_pdf);
      }
    }
    if (depth == max_depth_) break;
    const Vec3 n = cos_o < 0.f ? tri.n : -tri.n;  // facing the incoming ray
    const Frame frame = (kLayers & kHits) != 0 ? si->shading : Frame(n);
    Vec3 wo_local(0.f);  // only the BSDF objects take wo
    if constexpr ((kLayers & kBsdf) != 0) wo_local = frame.to_local(-glm::normalize(ray.d));

    // Next-event estimation: a light by power, a point on it uniformly by area.
    float u_light = rng.next_float();
    Vec2 u_point(rng.next_float(), rng.next_float());
    Vec3 q, wi, n_light;
    Rgb le_l;
    float light_pdf = 0.f;
    if constexpr ((kLayers & kLights) != 0) {
      if (std::optional<SampledLight> sl = scene_.sample_light(u_light)) {
        if (std::optional<LightLiSample> ls = sl->light->sample_li(LightSampleContext{p, n, true}, u_point)) {
          q = ls->p_light, wi = ls->wi, n_light = ls->n_light, le_l = ls->L;
          light_pdf = sl->pmf * ls->pdf;
        }
      }
    } else {
      size_t k = std::min<size_t>(std::upper_bound(emitter_cdf_.begin(), emitter_cdf_.end(), u_light) -
                                      emitter_cdf_.begin() - 1, emitters_.size() - 1);
      const uint32_t e = emitters_[k];
      const Triangle& light = triangles_[e];
      float su = std::sqrt(u_point.x);
      q = light.p0 + su * (1.f - u_point.y) * light.e1 + su * u_point.y * light.e2;
      wi = q - p;
      float dist2 = glm::dot(wi, wi), dist = std::sqrt(dist2);
      wi /= dist;
      float cos_l = glm::dot(wi, light.n);
      n_light = light.n;
      le_l = cos_l < 0.f ? light.le_front : light.le_back;
      if (cos_l != 0.f) light_pdf = emitter_pmf_[e] * dist2 / (std::abs(cos_l) * light.area);
    }
    const float cos_i = glm::dot(wi, n);
    if (light_pdf > 0.f && cos_i > 0.f && (le_l.r > 0.f || le_l.g > 0.f || le_l.b > 0.f)) {
      Rgb f_cos;
      float pdf_bsdf;
      if constexpr ((kLayers & kBsdf) != 0) {
        Vec3 wi_local = frame.to_local(wi);
        f_cos = tri.bsdf->f(wo_local, wi_local, sctx) * std::abs(wi_local.z);
        pdf_bsdf = tri.bsdf->pdf(wo_local, wi_local, sctx);
      } else {
        f_cos = tri.albedo * (InvPi * cos_i);
        pdf_bsdf = cos_i * InvPi;
      }
      bool occluded;
      if constexpr ((kLayers & kHits) != 0) {
        occluded = scene_.occluded(si->spawn_ray_to(q, n_light));
      } else {
        RTCRayHit shadow;
        if constexpr (robust) {  // both ends offset past their error bounds, as SurfaceInteraction::spawn_ray_to()
          shadow = embree_query(spawn_ray_to(p, p_error, tri.n, q, point_error_bound(q), n_light));
        } else {
          const Vec3 to = q - p;
          shadow = embree_query(Ray{p, to, 1.f - 1e-4f}, kTnear / glm::length(to));
        }
        rtcOccluded1(scene_.rtc_scene(), &ctx, &shadow.ray);
        occluded = shadow.ray.tfar < 0.f;
      }
      ++*rays;
      if (!occluded) L += beta * f_cos * le_l * (power_heuristic(1, light_pdf, 1, pdf_bsdf) / light_pdf);
    }

    // Continuation by BSDF sampling.
    float u_lobe = rng.next_float();
    Vec2 u_dir(rng.next_float(), rng.next_float());
    float u_rr = rng.next_float();
    Vec3 w_local;
    if constexpr ((kLayers & kBsdf) != 0) {
      std::optional<BsdfSample> bs = tri.bsdf->sample_f(wo_local, u_lobe, u_dir, sctx);
      if (!bs || !(bs->pdf > 0.f)) break;
      w_local = bs->wi;
      bsdf_pdf = bs->pdf;
      beta *= bs->f * std::abs(bs->wi.z) / bs->pdf;
    } else {
      w_local = sample_cosine_hemisphere(u_dir);
      if (!(w_local.z > 0.f)) break;
      bsdf_pdf = w_local.z * InvPi;
      beta *= tri.albedo;  // the Lambertian's f cos / pdf
    }
    const Vec3 d = frame.to_world(w_local);
    if constexpr ((kLayers & kLights) != 0) prev = LightSampleContext{p, n, true};
    if constexpr ((kLayers & kHits) != 0) ray = si->spawn_ray(d);
    else if constexpr (robust) ray = Ray{offset_ray_origin(p, p_error, tri.n, d), d, Infinity};
    else ray = Ray{p, d, Infinity};
    tnear = robust ? 0.f : kTnear;
    if (depth + 1 >= rr_depth_) {
      float q_end = std::max(0.f, 1.f - max_component(beta));
      if (u_rr < q_end) break;
      beta /= 1.f - q_end;
    }
  }
  return L;
}

template <unsigned kLayers>
MinimalRenderResult MinimalPathTracer::render_with(Point2i res, int spp, int threads, uint64_t seed) const {
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
          if (ray) sum += Li<kLayers>(*ray, pixel * static_cast<uint64_t>(spp) + s, seed, &n);
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

MinimalRenderResult MinimalPathTracer::render(Point2i res, int spp, int threads, uint64_t seed, unsigned layers) const {
  switch (layers) {
    case kMinimalOnly: return render_with<kMinimalOnly>(res, spp, threads, seed);
    case kHits: return render_with<kHits>(res, spp, threads, seed);
    case kHits | kLights: return render_with<kHits | kLights>(res, spp, threads, seed);
    case kHits | kLights | kBsdf: return render_with<kHits | kLights | kBsdf>(res, spp, threads, seed);
    case kRobust: return render_with<kRobust>(res, spp, threads, seed);
    default: throw Error(fmt::format("minimal path tracer: layers {} are not built (0, 1, 3, 7 and 8 are)", layers));
  }
}

}  // namespace penumbra
