#include "subpath.h"

#include <algorithm>

namespace penumbra::bdpt {

namespace {

bool is_at_infinity(const Light* light) {
  return light->type() == LightType::Infinite || light->type() == LightType::DeltaDirection;
}

// Area density at `to` of a solid-angle density at `from` (vertices at infinity keep solid angle).
inline float convert_density(float pdf_dir, const Vertex& from, const Vertex& to) {
  if (to.infinite) return pdf_dir;
  Vec3 d = to.p - from.p;
  float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.f)) return 0.f;
  float pdf = pdf_dir / dist2;
  if (to.on_surface()) pdf *= std::abs(glm::dot(to.ng, d)) / std::sqrt(dist2);
  return pdf;
}

// Veach's adjoint correction for shading normals (importance transport only): wo towards the
// previous vertex, wi towards the next.
float shading_correction(const Vertex& v, const Vec3& wo, const Vec3& wi) {
  float num = std::abs(glm::dot(wo, v.ns)) * std::abs(glm::dot(wi, v.ng));
  float den = std::abs(glm::dot(wo, v.ng)) * std::abs(glm::dot(wi, v.ns));
  return den == 0.f ? 0.f : num / den;
}

bool leaks(const Vertex& v, const Vec3& wo, const Vec3& wi) {
  bool reflect_shading = glm::dot(wi, v.ns) * glm::dot(wo, v.ns) > 0.f;
  bool reflect_geometric = glm::dot(wi, v.ng) * glm::dot(wo, v.ng) > 0.f;
  return reflect_shading != reflect_geometric;
}

// Surfaces know their error bound; other points (light samples, emitted-ray origins) are estimated
// from their magnitude, as the SDK does for points it is handed.
Vec3 error_of(const Vertex& v) { return v.kind == VertexKind::Surface ? v.p_error : point_error_bound(v.p); }

// Shadow ray from vertex v to a point that is not a path vertex (light sample, lens point).
Ray shadow_ray(const Vertex& v, const Vec3& p1, const Vec3& n1) {
  return spawn_ray_to(v.p, error_of(v), v.ng, p1, point_error_bound(p1), n1);
}

// Fills `v` in place (a returned vertex was built and then copied, 272 bytes, at every bounce).
void make_surface_vertex(Vertex& v, const SurfaceInteraction& si, const Rgb& beta, TransportMode mode,
                         const SampledWavelengths* wavelengths) {
  v = Vertex{};
  v.kind = VertexKind::Surface;
  v.p = si.p;
  v.p_error = si.p_error;
  v.ng = si.ng;
  v.ns = si.ns;
  v.shading = si.shading;
  // Built in place: assigned from a temporary, the context was stored in pieces and then copied in
  // wider loads, a store-forwarding stall that cost 2 % of bdpt's time.
  new (&v.sc.tex) TextureEvalContext(si.texture_context());
  v.sc.tex.wavelengths = wavelengths;
  v.wo = si.wo;
  v.wo_local = si.shading.to_local(si.wo);
  v.bsdf = si.bsdf;
  v.surface_connectible = si.bsdf && si.bsdf->flags() != 0 && !si.bsdf->is_specular_only();
  v.light = si.area_light;
  v.beta = beta;
  v.sc.mode = mode;
  v.media = si.media;
}

// The medium a segment leaving vertex v towards d travels in (MediumInterface::leaving; unknown for
// cameras and lights).
int medium_side(const Vertex& v, const Vec3& d) {
  return v.kind == VertexKind::Surface ? v.media.leaving(v.ng, d, v.medium) : kMediumUnknown;
}

// pdf_area(&a, cur, b) and pdf_area(&b, cur, a) for a surface vertex `cur` that has a predecessor,
// given the local directions towards a and b: one pair of directions for both BSDF densities.
void surface_pdf_pair(const Vertex& cur, const Vertex& a, const Vec3& wa, const Vertex& b, const Vec3& wb,
                      float* to_b, float* to_a) {
  const ShadingContext& sc = cur.sc;
  *to_b = convert_density(cur.bsdf->pdf(wa, wb, sc), cur, b);
  *to_a = convert_density(cur.bsdf->pdf(wb, wa, sc), cur, a);
}

// The same for `prev`, the vertex's own predecessor on its subpath, whose local direction it keeps.
void surface_pdf_pair_from_prev(const Vertex& cur, const Vertex& prev, const Vertex& b, float* to_b, float* to_prev) {
  surface_pdf_pair(cur, prev, cur.w_prev_local, b, cur.shading.to_local(direction_to(cur, b)), to_b, to_prev);
}

// Extends path[0 .. n-1] (n >= 1, path[n-1] the start point) by at most `max_vertices` scattering
// vertices; returns how many were added. The stored densities are evaluated between the vertices'
// positions rather than taken from the sampled directions: spawned rays start a few ULPs off the
// surface, and for close vertices the two differ by up to 1e-3, which would make the weights of
// different strategies for the same path disagree by as much.
int random_walk(const Context& ctx, Ray ray, PathSampler& ps, Rgb beta, TransportMode mode, Vertex* path,
                int max_vertices) {
  if (max_vertices <= 0) return 0;
  const Scene& scene = ctx.scene;
  float roulette_scale = std::max(max_component(beta), 1e-30f);
  // Product of eta'^2 over the refractions of a camera subpath so far (pbrt-v4's etaScale): the
  // roulette looks at the throughput without the 1/eta'^2 that radiance mode puts on refractions.
  // Without it a path entering glass of index 1.6 was ended with probability 0.61 and its survivors
  // left the glass with throughput 2.56: the fireflies that decided bdpt's relMSE on the benchmark
  // scenes. Importance transport (light subpaths) carries no such factor.
  float eta_scale = 1.f;
  const bool media = scene.has_media();
  int added = 0;
  for (;;) {
    Vertex& prev = path[added];
    Vertex& v = path[added + 1];
    Vertex* before = added > 0 ? &path[added - 1] : nullptr;
    std::optional<SurfaceInteraction> si = scene.intersect(ray);
    int medium = kMediumUnknown;
    if (media) {  // absorption along the segment just traced
      medium = segment_medium(medium_side(prev, ray.d), si ? si->media.toward(si->ng, -ray.d) : kMediumUnknown);
      beta *= scene.transmittance(medium, si ? si->t * glm::length(ray.d) : Infinity, ctx.wavelengths);
    }
    if (si) {
      make_surface_vertex(v, *si, beta, mode, ctx.wavelengths);
      v.medium = static_cast<int16_t>(medium);
      v.w_prev_local = v.shading.to_local(direction_to(v, prev));
    } else if (mode == TransportMode::Radiance && !scene.infinite_lights().empty()) {
      // Camera rays that escape may see environment lights: keep them as an endpoint at infinity.
      v = Vertex{};
      v.kind = VertexKind::Light;
      v.infinite = true;
      v.w_light = -ray.d;
      v.p = ray.o;
      v.beta = beta;
    } else {
      break;
    }
    if (!prev.delta) {
      if (before && prev.kind == VertexKind::Surface) {
        // Both densities at prev from one pair of directions (the same values as pdf_area's).
        surface_pdf_pair_from_prev(prev, *before, v, &v.pdf_fwd, &before->pdf_rev);
      } else {
        v.pdf_fwd = pdf_area(ctx, before, prev, v);  // solid angle for a vertex at infinity
        if (before) before->pdf_rev = pdf_area(ctx, &v, prev, *before);
      }
    } else if (prev.kind == VertexKind::Surface) {
      // A specular scattering generates both its neighbours with a delta of unit solid-angle density
      // (every strategy that can make the path shares it, once per specular vertex: mis.h), converted
      // to area like any other density. Counting the area density itself as 1 (pbrt-v3's rule) drops
      // the geometry terms around the specular chain and gives camera paths that hit a light through
      // glass far more weight than light paths that make the same caustic.
      v.pdf_fwd = convert_density(1.f, prev, v);
      if (before) before->pdf_rev = convert_density(1.f, prev, *before);
    }
    ++added;
    if (!si || added >= max_vertices) break;

    int level = added - 1;
    ps.seek(mode == TransportMode::Radiance ? PathSampler::camera_bounce(level) : PathSampler::light_bounce(level));
    float u_lobe = ps.get_1d();
    Vec2 u_dir = ps.get_2d();
    float u_rr = ps.get_1d();

    const Bsdf& bsdf = *v.bsdf;
    const ShadingContext& sctx = v.sc;
    const Vec3& wo = v.wo_local;
    std::optional<BsdfSample> bs = bsdf.flags() ? bsdf.sample_f(wo, u_lobe, u_dir, sctx) : std::nullopt;
    if (!bs || !(bs->pdf > 0.f) || is_black(bs->f)) break;
    Vec3 wi = v.shading.to_world(bs->wi);
    if (leaks(v, v.wo, wi)) break;
    Rgb scatter = bs->f * std::abs(bs->wi.z) / bs->pdf;
    if (mode == TransportMode::Importance) scatter *= shading_correction(v, v.wo, wi);
    beta *= scatter;
    if (mode == TransportMode::Radiance && (bs->flags & BsdfTransmission)) eta_scale *= bs->eta * bs->eta;
    // A specular choice generates both neighbours with a delta (see above for their densities). The flag is
    // the sample's, not the BSDF's: a mixed BSDF (delta + diffuse) is delta only where it sampled its
    // delta, and stays connectible through its other lobes (connectible(), mis_weight()).
    v.delta = bs->is_specular();

    if (added >= ctx.config.rr_depth) {
      // Throughput relative to the subpath's start, so light and camera paths are treated alike.
      float q = std::max(0.f, 1.f - max_component(beta) * eta_scale / roulette_scale);
      if (u_rr < q) break;
      beta /= 1.f - q;
    }
    if (!is_finite(beta) || is_black(beta)) break;
    ray = Ray{offset_ray_origin(v.p, v.p_error, v.ng, wi), wi, Infinity};
  }
  return added;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

std::optional<SampledLight> LightChooser::sample(float u) const {
  if (!uniform_) return scene_.sample_light(u);
  auto lights = scene_.lights();
  if (lights.empty()) return std::nullopt;
  size_t i = std::min(static_cast<size_t>(u * lights.size()), lights.size() - 1);
  return SampledLight{lights[i], 1.f / lights.size()};
}

float LightChooser::pmf(const Light* light) const {
  if (!uniform_) return scene_.light_pmf(light);
  return scene_.lights().empty() ? 0.f : 1.f / scene_.lights().size();
}

bool Vertex::connectible() const {
  switch (kind) {
    case VertexKind::Camera: return true;
    case VertexKind::Light: return !infinite;  // a direction cannot be connected to deterministically
    case VertexKind::Surface: return surface_connectible;
  }
  return false;
}

Rgb Vertex::f(const Vertex& next) const {
  if (kind != VertexKind::Surface) return Rgb(0.f);
  Vec3 wi = direction_to(*this, next);
  if (leaks(*this, wo, wi)) return Rgb(0.f);
  Rgb value = bsdf->f(wo_local, shading.to_local(wi), sc);
  if (sc.mode == TransportMode::Importance) value *= shading_correction(*this, wo, wi);
  return value;
}

float pdf_light_dir(const Vertex& cur, const Vertex& next) {
  const Light* light = cur.light;
  if (!light) return 0.f;
  float pdf_pos, pdf_dir;
  if (cur.infinite) {
    // Emitted rays start on a disk facing the scene: the density at `next` is the disk's, projected.
    light->pdf_le(Ray{cur.p, cur.w_light}, Vec3(0.f), &pdf_pos, &pdf_dir);
    return next.on_surface() ? pdf_pos * std::abs(glm::dot(next.ng, cur.w_light)) : pdf_pos;
  }
  Vec3 w = direction_to(cur, next);
  light->pdf_le(Ray{cur.p, w}, cur.ng, &pdf_pos, &pdf_dir);
  return convert_density(pdf_dir, cur, next);
}

float pdf_light_origin(const Context& ctx, const Vertex& cur, const Vertex& next) {
  const Light* light = cur.light;
  if (!light) return 0.f;
  float pmf = ctx.lights.pmf(light);
  float pdf_pos, pdf_dir;
  switch (light->type()) {
    case LightType::DeltaPosition:
    case LightType::DeltaDirection:
      return pmf;  // a delta (in position or direction): counts as 1, like every other delta
    case LightType::Infinite:
      light->pdf_le(Ray{cur.p, cur.w_light}, Vec3(0.f), &pdf_pos, &pdf_dir);
      return pmf * pdf_dir;  // the origin of an environment path is its direction
    case LightType::Area:
      light->pdf_le(Ray{cur.p, direction_to(cur, next)}, cur.ng, &pdf_pos, &pdf_dir);
      return pmf * pdf_pos;
  }
  return 0.f;
}

float pdf_area(const Context& ctx, const Vertex* prev, const Vertex& cur, const Vertex& next) {
  if (cur.kind == VertexKind::Light || (cur.kind == VertexKind::Surface && !prev)) return pdf_light_dir(cur, next);
  Vec3 wn = direction_to(cur, next);
  if (cur.kind == VertexKind::Camera) {
    float pdf_pos, pdf_dir;
    ctx.scene.camera().pdf_we(Ray{cur.p, wn}, &pdf_pos, &pdf_dir);
    return convert_density(pdf_dir, cur, next);
  }
  Vec3 wp = direction_to(cur, *prev);
  float pdf_dir = cur.bsdf->pdf(cur.shading.to_local(wp), cur.shading.to_local(wn), cur.sc);
  return convert_density(pdf_dir, cur, next);
}

namespace {

// next_event_ratio() given the two densities it needs: pdf_li() of x0 seen from x1 (solid angle) and
// pdf_le()'s positional density of x0.
double next_event_ratio_from(const Vertex& x0, const Vertex& x1, float pdf_solid_angle, float pdf_pos) {
  Vec3 d = x0.p - x1.p;
  float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.f)) return 1.0;
  Vec3 wi = d / std::sqrt(dist2);
  if (!(pdf_pos > 0.f)) return 1.0;
  double nee_area = static_cast<double>(pdf_solid_angle) * std::abs(glm::dot(x0.ng, wi)) / dist2;
  return nee_area / pdf_pos;
}

bool next_event_ratio_applies(const Vertex& x0, const Vertex& x1) {
  return x0.light && x1.on_surface() && x0.light->li_density_depends_on_receiver();
}

// The same for an environment light: pdf_li()'s density of the direction seen from x1 (a constant
// sky samples about x1's normal) over the emission's density of that direction.
double infinite_next_event_ratio(float pdf_solid_angle, float pdf_dir) {
  return pdf_dir > 0.f && pdf_solid_angle != pdf_dir ? static_cast<double>(pdf_solid_angle) / pdf_dir : 1.0;
}

}  // namespace

double next_event_ratio(const Vertex& x0, const Vertex& x1) {
  if (!next_event_ratio_applies(x0, x1)) return 1.0;
  if (x0.infinite) {
    SurfaceInteraction none;
    float pdf_solid_angle = x0.light->pdf_li(LightSampleContext{x1.p, x1.ng}, -x0.w_light, none);
    float pdf_pos, pdf_dir;
    x0.light->pdf_le(Ray{x0.p, x0.w_light}, Vec3(0.f), &pdf_pos, &pdf_dir);
    return infinite_next_event_ratio(pdf_solid_angle, pdf_dir);
  }
  Vec3 d = x0.p - x1.p;
  float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.f)) return 1.0;
  Vec3 wi = d / std::sqrt(dist2);
  SurfaceInteraction hit;
  hit.p = x0.p;
  hit.ng = x0.ng;
  hit.ns = x0.ng;
  hit.uv = x0.sc.tex.uv;
  float pdf_solid_angle = x0.light->pdf_li(LightSampleContext{x1.p, x1.ng}, wi, hit);
  float pdf_pos, pdf_dir;
  x0.light->pdf_le(Ray{x0.p, -wi}, x0.ng, &pdf_pos, &pdf_dir);
  return next_event_ratio_from(x0, x1, pdf_solid_angle, pdf_pos);
}

// ---------------------------------------------------------------------------------------------

namespace {

double remap_density(double p) { return p != 0.0 ? p : 1.0; }  // deltas count as 1 (mis.h)

// (p_i / p_{i+1})^beta for the strategies either side of `v` on its subpath: moving v to the other
// side replaces its own side's density by the other side's (mis.h's recurrence, both subpaths).
double moved_ratio(const Vertex& v, MisHeuristic h) {
  return mis_power(remap_density(v.pdf_rev) / remap_density(v.pdf_fwd), h);
}

bool light_hittable(const Vertex& x0) { return x0.light && !is_delta_light(x0.light->type()); }

// Vertex::mis_sum along a traced light subpath: G_j = rho_j (poss_j w_j + G_{j-1}), where strategy j
// (light vertices 0..j-1) is possible when neither x_{j-1} nor x_j is specular (strategy 0: when
// camera paths can hit the light), and w_1 is the next-event correction (mis.h).
void fold_light_sums(const Context& ctx, Vertex* path, int n) {
  MisHeuristic h = ctx.config.heuristic;
  double nee_w = 1.0;
  if (n >= 2) {
    double nee = std::isnan(path[0].nee_ratio) ? next_event_ratio(path[0], path[1]) : path[0].nee_ratio;
    nee_w = mis_power(nee, h);
  }
  double g = 0.0;
  for (int j = 0; j < n; ++j) {
    bool possible = j == 0 ? light_hittable(path[0]) : !path[j - 1].delta && !path[j].delta;
    g = moved_ratio(path[j], h) * ((possible ? (j == 1 ? nee_w : 1.0) : 0.0) + g);
    path[j].mis_sum = g;
  }
}

// The same along a camera subpath: H_j = rho_j (poss_j + H_{j-1}), H_0 = 0 (the lens never moves:
// there is no t = 0 strategy).
void fold_camera_sums(const Context& ctx, Vertex* path, int n) {
  MisHeuristic h = ctx.config.heuristic;
  double sum = 0.0;
  path[0].mis_sum = 0.0;
  for (int j = 1; j < n; ++j) {
    bool possible = !path[j].delta && !path[j - 1].delta;
    sum = moved_ratio(path[j], h) * ((possible ? 1.0 : 0.0) + sum);
    path[j].mis_sum = sum;
  }
}

}  // namespace

int camera_subpath(const Context& ctx, const Ray& ray, PathSampler& ps, Vertex* path) {
  Vertex& cam = path[0];
  cam = Vertex{};
  cam.kind = VertexKind::Camera;
  cam.p = ray.o;
  cam.beta = Rgb(1.f);  // We cos / (pdf_pos pdf_dir) = 1 for every camera ray
  // A camera that is a delta in direction (orthographic) scatters "specularly" into its rays: no
  // strategy can connect to it (mis.h), as for a mirror.
  cam.delta = !ctx.scene.camera().connectible();
  float pdf_dir;
  ctx.scene.camera().pdf_we(ray, &cam.pdf_fwd, &pdf_dir);
  int n = 1 + random_walk(ctx, ray, ps, Rgb(1.f), TransportMode::Radiance, path, ctx.config.max_depth + 1);
  fold_camera_sums(ctx, path, n);
  return n;
}

int light_subpath(const Context& ctx, PathSampler& ps, Vertex* path) {
  ps.seek(PathSampler::kLightChoice);
  float u_light = ps.get_1d();
  Vec2 u_pos = ps.get_2d(), u_dir = ps.get_2d();
  std::optional<SampledLight> sl = ctx.lights.sample(u_light);
  if (!sl || !(sl->pmf > 0.f)) return 0;
  std::optional<LightLeSample> le = sl->light->sample_le(u_pos, u_dir);
  if (!le || !(le->pdf_pos > 0.f) || !(le->pdf_dir > 0.f) || is_black(le->L)) return 0;

  Vertex& y0 = path[0];
  y0 = Vertex{};
  y0.kind = VertexKind::Light;
  y0.light = sl->light;
  y0.p = le->ray.o;
  y0.ng = le->n;
  y0.infinite = is_at_infinity(sl->light);
  y0.w_light = le->ray.d;
  y0.beta = Rgb(1.f / (sl->pmf * le->pdf_pos));  // emission is evaluated per connection
  y0.sc.mode = TransportMode::Importance;

  float cos0 = le->n != Vec3(0.f) ? std::abs(glm::dot(le->n, le->ray.d)) : 1.f;
  Rgb beta = emission_at(ctx.wavelengths, le->L) * cos0 / (sl->pmf * le->pdf_pos * le->pdf_dir);
  int n = random_walk(ctx, le->ray, ps, beta, TransportMode::Importance, path, ctx.config.max_depth);
  y0.pdf_fwd = pdf_light_origin(ctx, y0, n > 0 ? path[1] : y0);
  // The same for every connection with s >= 2 (x_0 and x_1 are this path's): once per path.
  if (ctx.config.store_nee_ratio) y0.nee_ratio = n > 0 ? static_cast<float>(next_event_ratio(y0, path[1])) : 1.f;
  if (ctx.config.store_nee_ratio) fold_light_sums(ctx, path, n + 1);
  return n + 1;
}

// ---------------------------------------------------------------------------------------------

namespace {

// The densities a connection changes (see mis_weight()): the two vertices on each side of the new
// edge see new neighbours, strategy 1 has its own origin density, and the next-event ratio of the
// path's first two vertices.
struct Patch {
  float light_s = 0.f;    // x_s's pdf_light (t >= 1)
  float light_s1 = 0.f;   // x_{s+1}'s pdf_light (t >= 2)
  float camera_s1 = 0.f;  // x_{s-1}'s pdf_camera (s >= 1)
  float camera_s2 = 0.f;  // x_{s-2}'s pdf_camera (s >= 2)
  float light_0 = 0.f;    // x_0's pdf_light (s = 1)
  double nee_ratio = 1.0;
};

// Scratch space of one weight: on the stack for paths of up to kInlineVertices vertices (maxdepth
// 30), per thread beyond.
constexpr int kInlineVertices = 32;

template <class T, int Tag>
struct Scratch {
  union {
    T inline_[kInlineVertices];
  };
  T* data;
  explicit Scratch(int n) {
    if (n <= kInlineVertices) {
      data = inline_;
    } else {
      thread_local std::vector<T> heap;
      if (static_cast<int>(heap.size()) < n) heap.resize(n);
      data = heap.data();
    }
  }
  ~Scratch() {}
};

// Next-event ratio of a path whose first vertices are light[0], light[1] (s >= 2): stored on the
// light subpath by light_subpath().
double cached_nee_ratio(const Vertex* light, int s, const Vertex* light_end, const Vertex& x0, const Vertex& x1) {
  if (!(light_end && s == 2) && !std::isnan(light[0].nee_ratio)) return light[0].nee_ratio;
  return next_event_ratio(x0, x1);
}

// The weight of strategy (s, t) when every technique is a per-sample one, in O(1): the densities
// the connection changes (`patch`) for the two vertices on each side of the new edge, and the
// subpaths' folded sums (Vertex::mis_sum) beyond them. The same sum as strategy_density_ratios() and
// mis_weight_from_ratios() make from the whole path, term by term.
double regular_weight(const Context& ctx, const Vertex* light, int s, const Vertex* camera, int t,
                      const Vertex* light_end, const Vertex* camera_end, const Patch& patch) {
  const MisHeuristic h = ctx.config.heuristic;
  auto L = [&](int i) -> const Vertex& { return (i == s - 1 && light_end) ? *light_end : light[i]; };
  auto C = [&](int j) -> const Vertex& { return (j == t - 1 && camera_end) ? *camera_end : camera[j]; };
  const double nee_w = mis_power(patch.nee_ratio, h);  // the correction of strategy 1 (k >= 2 here)

  // Strategies 0 .. s-1: x_{s-1} (connected, so not specular) and x_{s-2} see new neighbours.
  double light_sum = 0.0;
  if (s == 1) {
    double rho = mis_power(remap_density(patch.camera_s1) / remap_density(patch.light_0), h);
    light_sum = light_hittable(L(0)) ? rho : 0.0;
  } else if (s >= 2) {
    const Vertex& end = L(s - 1);
    const Vertex& before = L(s - 2);
    double rho_end = mis_power(remap_density(patch.camera_s1) / remap_density(end.pdf_fwd), h);
    double rho_before = mis_power(remap_density(patch.camera_s2) / remap_density(before.pdf_fwd), h);
    double w_end = before.delta ? 0.0 : (s == 2 ? nee_w : 1.0);
    bool before_possible = s == 2 ? light_hittable(L(0)) : !L(s - 3).delta && !before.delta;
    double w_before = before_possible ? (s == 3 ? nee_w : 1.0) : 0.0;
    double beyond = s >= 3 ? L(s - 3).mis_sum : 0.0;
    light_sum = rho_end * (w_end + rho_before * (w_before + beyond));
  }
  // Strategies s+1 .. k: x_s (connected) and x_{s+1} see new neighbours.
  double camera_sum = 0.0;
  if (t >= 2) {
    const Vertex& end = C(t - 1);
    const Vertex& before = C(t - 2);
    double rho_end = mis_power(remap_density(patch.light_s) / remap_density(end.pdf_fwd), h);
    double inner = before.delta ? 0.0 : (s == 0 ? nee_w : 1.0);
    if (t >= 3) {
      double rho_before = mis_power(remap_density(patch.light_s1) / remap_density(before.pdf_fwd), h);
      const Vertex& beyond = C(t - 3);
      inner += rho_before * ((!before.delta && !beyond.delta ? 1.0 : 0.0) + beyond.mis_sum);
    }
    camera_sum = rho_end * inner;
  }
  // Strategy 1 samples x_0 by next-event estimation: every other strategy's ratio is over its density.
  double sum = 1.0 + (s == 1 ? (light_sum + camera_sum) / nee_w : light_sum + camera_sum);
  if (!(sum > 0.0) || !std::isfinite(sum)) return std::isinf(sum) ? 0.0 : 1.0;
  return 1.0 / sum;
}

double weight_with(const Context& ctx, const Vertex* light, int s, const Vertex* camera, int t,
                   const Vertex* light_end, const Vertex* camera_end, Technique tau, const Patch& patch) {
  if (s + t == 2) return 1.0;
  if (!ctx.techniques || ctx.techniques->all_regular())
    return regular_weight(ctx, light, s, camera, t, light_end, camera_end, patch);
  int k = s + t - 1;
  auto L = [&](int i) -> const Vertex& { return (i == s - 1 && light_end) ? *light_end : light[i]; };
  auto C = [&](int j) -> const Vertex& { return (j == t - 1 && camera_end) ? *camera_end : camera[j]; };

  Scratch<MisVertex, 0> mv_scratch(k + 1);
  Scratch<double, 1> ratio_scratch(k + 1);
  MisVertex* mv = mv_scratch.data;
  std::span<double> ratios(ratio_scratch.data, k + 1);
  const int s_own = light_end ? s - 1 : s, t_own = camera_end ? t - 1 : t;  // vertices from the subpaths
  for (int i = 0; i < s_own; ++i) mv[i] = MisVertex{light[i].pdf_fwd, light[i].pdf_rev, light[i].delta};
  if (s_own < s) mv[s - 1] = MisVertex{light_end->pdf_fwd, light_end->pdf_rev, light_end->delta};
  for (int j = 0; j < t_own; ++j) mv[k - j] = MisVertex{camera[j].pdf_rev, camera[j].pdf_fwd, camera[j].delta};
  if (t_own < t) mv[s] = MisVertex{camera_end->pdf_rev, camera_end->pdf_fwd, camera_end->delta};
  // The connected vertices scatter through their non-delta parts; their neighbours' densities change.
  if (s > 0) {
    mv[s - 1].delta = false;
    mv[s - 1].pdf_camera = patch.camera_s1;
  }
  if (t > 0) {
    mv[s].delta = false;
    mv[s].pdf_light = patch.light_s;
  }
  if (t > 1) mv[s + 1].pdf_light = patch.light_s1;
  if (s > 1) mv[s - 2].pdf_camera = patch.camera_s2;
  if (s == 1) mv[0].pdf_light = patch.light_0;

  const Vertex& x0 = s > 0 ? L(0) : C(t - 1);
  MisPath path;
  path.vertices = std::span<const MisVertex>(mv, k + 1);
  path.light_hittable = x0.light && !is_delta_light(x0.light->type());
  path.nee_ratio = k >= 2 ? patch.nee_ratio : 1.0;
  strategy_density_ratios(path, s, ratios);

  // Several techniques per strategy: strategy i's sum is sum_tau c_tau(i)^beta (mis.h).
  const TechniqueSet& ts = *ctx.techniques;
  auto X = [&](int m) -> const Vertex& { return m < s ? L(m) : C(k - m); };
  Scratch<double, 2> sum_scratch(k + 1);
  std::span<double> sums(sum_scratch.data, k + 1);
  double own = 1.0;
  for (int i = 0; i <= k; ++i) {
    sums[i] = 0.0;
    if (ratios[i] == 0.0) continue;
    double sum = 0.0;
    if (i == 0) {
      sum = 1.0;
    } else if (i == 1) {
      sum = ts.nextevent ? 1.0 : 0.0;
    } else if (i == k) {
      sum = ts.lighttrace ? 1.0 : 0.0;
    } else {
      sum = ts.connect ? 1.0 : 0.0;
      if (ts.cached)
        for (Technique cached : {Technique::Hrr, Technique::ProbConnect}) {
          if (!ts.cached->enabled(cached)) continue;
          double c = ts.cached->factor(cached, X(i - 2), X(i - 1), X(i), X(i + 1));
          sum += mis_power(c, ctx.config.heuristic);
          if (i == s && cached == tau) own = c;
        }
    }
    sums[i] = sum;
  }
  return mis_weight_from_ratios(ratios, s, ctx.config.heuristic, sums, own);
}

// Vertex::f() towards world direction wi (local wi_local), wi = direction_to(v, next).
Rgb surface_f(const Vertex& v, const Vec3& wi, const Vec3& wi_local) {
  if (leaks(v, v.wo, wi)) return Rgb(0.f);
  Rgb value = v.bsdf->f(v.wo_local, wi_local, v.sc);
  if (v.sc.mode == TransportMode::Importance) value *= shading_correction(v, v.wo, wi);
  return value;
}

// Strategy (s, t) with s, t >= 2: joins light[s-1] and camera[t-1] with a shadow ray (the contribution
// of pbrt-v3's ConnectBDPT: both throughputs, both BSDFs, the geometry term) and, when `patch` is given and the connection carries light, fills the
// densities the MIS weight needs from the same directions. Returns 0 when occluded.
Rgb connect_surfaces(const Context& ctx, const Vertex* light, int s, const Vertex* camera, int t, Patch* patch) {
  const Vertex& qs = light[s - 1];
  const Vertex& pt = camera[t - 1];
  if (!qs.connectible() || !pt.connectible() || pt.kind != VertexKind::Surface) return Rgb(0.f);
  // qs (s >= 2) and pt are surface vertices.
  Vec3 d = pt.p - qs.p;
  float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.f)) return Rgb(0.f);
  float dist = std::sqrt(dist2);
  Vec3 w = d / dist;  // qs -> pt
  Vec3 wq = qs.shading.to_local(w), wp = pt.shading.to_local(-w);
  Rgb L = qs.beta * surface_f(qs, w, wq) * surface_f(pt, -w, wp) * pt.beta;
  if (is_black(L)) return L;
  L *= std::abs(glm::dot(qs.ns, w)) * std::abs(glm::dot(pt.ns, w)) / dist2;
  if (ctx.scene.has_media())
    L *= ctx.scene.segment_transmittance(medium_side(qs, w), medium_side(pt, -w), dist, ctx.wavelengths);
  if (is_black(L) ||
      ctx.scene.occluded(spawn_ray_to(qs.p, error_of(qs), qs.ng, pt.p, error_of(pt), pt.ng)))
    return Rgb(0.f);
  if (patch) {
    const Vertex& qs_prev = light[s - 2];
    const Vertex& pt_prev = camera[t - 2];
    surface_pdf_pair(qs, qs_prev, qs.w_prev_local, pt, wq, &patch->light_s, &patch->camera_s2);
    surface_pdf_pair(pt, qs, wp, pt_prev, pt.w_prev_local, &patch->light_s1, &patch->camera_s1);
    patch->nee_ratio = s + t - 1 >= 2 ? cached_nee_ratio(light, s, nullptr, light[0], light[1]) : 1.0;
  }
  return L;
}

}  // namespace

double mis_weight(const Context& ctx, const Vertex* light, int s, const Vertex* camera, int t,
                  const Vertex* light_end, const Vertex* camera_end, Technique tau) {
  if (s + t == 2) return 1.0;
  int k = s + t - 1;
  auto L = [&](int i) -> const Vertex& { return (i == s - 1 && light_end) ? *light_end : light[i]; };
  auto C = [&](int j) -> const Vertex& { return (j == t - 1 && camera_end) ? *camera_end : camera[j]; };

  // The densities the connection changes: the two vertices on each side of the new edge see new
  // neighbours, and the connected vertices scatter through their non-delta parts.
  const Vertex* qs = s > 0 ? &L(s - 1) : nullptr;
  const Vertex* qs_prev = s > 1 ? &L(s - 2) : nullptr;
  const Vertex* pt = t > 0 ? &C(t - 1) : nullptr;
  const Vertex* pt_prev = t > 1 ? &C(t - 2) : nullptr;
  Patch patch;
  if (pt) patch.light_s = qs ? pdf_area(ctx, qs_prev, *qs, *pt) : pdf_light_origin(ctx, *pt, pt_prev ? *pt_prev : *pt);
  if (pt_prev) patch.light_s1 = qs ? pdf_area(ctx, qs, *pt, *pt_prev) : pdf_light_dir(*pt, *pt_prev);
  if (qs) patch.camera_s1 = pdf_area(ctx, pt_prev, *pt, *qs);
  if (qs_prev) patch.camera_s2 = pdf_area(ctx, pt, *qs, *qs_prev);
  if (s == 1) patch.light_0 = pdf_light_origin(ctx, *qs, *pt);
  const Vertex& x0 = s > 0 ? L(0) : *pt;
  const Vertex& x1 = s > 1 ? L(1) : (s == 1 ? *pt : *pt_prev);
  if (k >= 2) patch.nee_ratio = s > 1 ? cached_nee_ratio(light, s, light_end, x0, x1) : next_event_ratio(x0, x1);
  return weight_with(ctx, light, s, camera, t, light_end, camera_end, tau, patch);
}

Connection connect(const Context& ctx, const Vertex* light, int s, const Vertex* camera, int t, PathSampler& ps,
                   bool weighted) {
  Connection c;
  const Scene& scene = ctx.scene;
  const Vertex& pt = camera[t - 1];
  if (t > 1 && s != 0 && pt.kind == VertexKind::Light) return c;  // an escaped ray connects to nothing

  auto finish = [&](const Vertex* light_end, const Vertex* camera_end) {
    if (is_black(c.L)) return;
    c.weight = weighted ? mis_weight(ctx, light, s, camera, t, light_end, camera_end) : 1.0;
    c.weighted = c.L * static_cast<float>(c.weight);
  };

  if (s == 0) {
    if (pt.kind == VertexKind::Light) {
      // Each environment light is its own strategy family: weight it with its own densities.
      for (const Light* env : scene.infinite_lights()) {
        Rgb Le = emission_at(ctx.wavelengths, env->Le(Ray{camera[t - 2].p, -pt.w_light}));
        if (is_black(Le)) continue;
        Vertex end = pt;
        end.light = env;
        Rgb contribution = pt.beta * Le;
        c.weight = weighted ? mis_weight(ctx, light, s, camera, t, nullptr, &end) : 1.0;
        c.L += contribution;
        c.weighted += contribution * static_cast<float>(c.weight);
      }
      return c;
    }
    if (!pt.light) return c;
    Rgb Le = pt.light->L(pt.p, pt.ng, pt.sc.tex.uv, direction_to(pt, camera[t - 2]));
    c.L = pt.beta * emission_at(ctx.wavelengths, Le);
    finish(nullptr, nullptr);
    return c;
  }

  const TechniqueSet* ts = ctx.techniques;
  if (t == 1) {
    if (ts && !ts->lighttrace) return c;
    const Vertex& qs = light[s - 1];
    if (!qs.connectible() || (qs.kind == VertexKind::Light && (!qs.light || qs.light->type() != LightType::Area)))
      return c;
    ps.seek(PathSampler::lens(s - 1));
    std::optional<CameraWiSample> cw = scene.camera().sample_wi(qs.p, ps.get_2d());
    if (!cw || !(cw->pdf > 0.f)) return c;
    c.sampled = Vertex{};
    Vertex& cam = c.sampled;
    cam.kind = VertexKind::Camera;
    cam.p = cw->p_lens;
    cam.beta = cw->We / cw->pdf;
    if (qs.kind == VertexKind::Surface)
      c.L = qs.beta * qs.f(cam) * cam.beta * std::abs(glm::dot(cw->wi, qs.ns));
    else  // a point on an area light seen directly (light tracing's s = 1)
      c.L = qs.beta * emission_at(ctx.wavelengths, qs.light->L(qs.p, qs.ng, qs.sc.tex.uv, cw->wi)) *
            std::abs(glm::dot(cw->wi, qs.ng)) * cam.beta;
    if (scene.has_media())
      c.L *= scene.segment_transmittance(medium_side(qs, cw->wi), kMediumUnknown, glm::length(cam.p - qs.p),
                                         ctx.wavelengths);
    if (is_black(c.L) || scene.occluded(shadow_ray(qs, cam.p, Vec3(0.f)))) {
      c.L = Rgb(0.f);
      return c;
    }
    // The lens vertex's densities: what pdf_we() gives for the ray lens -> qs, from sample_wi().
    cam.pdf_fwd = cw->pdf_pos;
    c.has_sampled = true;
    c.splat = true;
    c.p_raster = cw->p_raster;
    if (!weighted || s + t == 2) {
      c.weight = 1.0;
      c.weighted = c.L;
      return c;
    }
    // s >= 2: qs is a surface vertex with a predecessor. The lens density towards qs is the
    // directional one of the ray lens -> qs.
    Patch patch;
    surface_pdf_pair_from_prev(qs, light[s - 2], cam, &patch.light_s, &patch.camera_s2);
    patch.camera_s1 = convert_density(cw->pdf_dir, cam, qs);
    patch.nee_ratio = cached_nee_ratio(light, s, nullptr, light[0], light[1]);
    c.weight = weight_with(ctx, light, s, camera, t, nullptr, &cam, Technique::Regular, patch);
    c.weighted = c.L * static_cast<float>(c.weight);
    return c;
  }

  if (s == 1) {
    if ((ts && !ts->nextevent) || !pt.connectible()) return c;
    ps.seek(PathSampler::next_event(t - 2));
    float u_light = ps.get_1d();
    Vec2 u = ps.get_2d();
    std::optional<SampledLight> sl = ctx.lights.sample(u_light);
    if (!sl || !(sl->pmf > 0.f)) return c;
    std::optional<LightLiSample> ls = sl->light->sample_li(LightSampleContext{pt.p, pt.ng}, u);
    if (!ls || !(ls->pdf > 0.f) || is_black(ls->L)) return c;
    c.sampled = Vertex{};
    Vertex& lv = c.sampled;
    lv.kind = VertexKind::Light;
    lv.light = sl->light;
    lv.p = ls->p_light;
    lv.ng = ls->n_light;
    lv.infinite = is_at_infinity(sl->light);
    lv.w_light = -ls->wi;
    lv.beta = emission_at(ctx.wavelengths, ls->L) / (ls->pdf * sl->pmf);
    lv.sc.mode = TransportMode::Importance;
    // Both emission densities of the sampled point from one pdf_le() call (pdf_light_origin() and
    // pdf_light_dir() towards pt).
    float pdf_pos = 0.f, pdf_dir = 0.f, to_pt = 0.f;
    LightType type = sl->light->type();
    if (lv.infinite) {
      sl->light->pdf_le(Ray{lv.p, lv.w_light}, Vec3(0.f), &pdf_pos, &pdf_dir);
      to_pt = pt.on_surface() ? pdf_pos * std::abs(glm::dot(pt.ng, lv.w_light)) : pdf_pos;
    } else {
      sl->light->pdf_le(Ray{lv.p, direction_to(lv, pt)}, lv.ng, &pdf_pos, &pdf_dir);
      to_pt = convert_density(pdf_dir, lv, pt);
    }
    float pmf = ctx.lights.pmf(sl->light);
    lv.pdf_fwd = type == LightType::Area ? pmf * pdf_pos : type == LightType::Infinite ? pmf * pdf_dir : pmf;
    c.has_sampled = true;
    Vec3 w = direction_to(pt, lv);
    Vec3 wl = pt.shading.to_local(w);
    c.L = pt.beta * surface_f(pt, w, wl) * lv.beta * std::abs(glm::dot(ls->wi, pt.ns));
    if (scene.has_media())
      c.L *= scene.segment_transmittance(medium_side(pt, ls->wi), kMediumUnknown, glm::length(ls->p_light - pt.p),
                                         ctx.wavelengths);
    if (is_black(c.L) || scene.occluded(shadow_ray(pt, ls->p_light, ls->n_light))) {
      c.L = Rgb(0.f);
      return c;
    }
    if (!weighted) {
      c.weight = 1.0;
      c.weighted = c.L;
      return c;
    }
    Patch patch;
    patch.light_s = to_pt;
    patch.light_0 = lv.pdf_fwd;
    surface_pdf_pair(pt, lv, wl, camera[t - 2], pt.w_prev_local, &patch.light_s1, &patch.camera_s1);
    // sample_li() drew lv with the density next_event_ratio() asks pdf_li() for.
    patch.nee_ratio = !next_event_ratio_applies(lv, pt) ? 1.0
                      : lv.infinite ? infinite_next_event_ratio(ls->pdf, pdf_dir)
                                    : next_event_ratio_from(lv, pt, ls->pdf, pdf_pos);
    c.weight = weight_with(ctx, light, s, camera, t, &lv, nullptr, Technique::Regular, patch);
    c.weighted = c.L * static_cast<float>(c.weight);
    return c;
  }

  if (ts && !ts->connect) return c;
  Patch patch;
  c.L = connect_surfaces(ctx, light, s, camera, t, weighted ? &patch : nullptr);
  if (is_black(c.L)) return c;
  c.weight = weighted ? weight_with(ctx, light, s, camera, t, nullptr, nullptr, Technique::Regular, patch) : 1.0;
  c.weighted = c.L * static_cast<float>(c.weight);
  return c;
}

Connection connect_cached(const Context& ctx, const Vertex* light, int s, const Vertex* camera, int t,
                          Technique tau, double factor) {
  Connection c;
  if (s < 2 || t < 2 || !(factor > 0.0)) return c;
  Patch patch;
  c.L = connect_surfaces(ctx, light, s, camera, t, &patch);
  if (is_black(c.L)) return c;
  c.L /= static_cast<float>(factor);
  c.weight = weight_with(ctx, light, s, camera, t, nullptr, nullptr, tau, patch);
  c.weighted = c.L * static_cast<float>(c.weight);
  return c;
}

Config read_subpath_config(const ParamSet& p, bool* uniform_lights) {
  Config config;
  config.max_depth = p.get_int("maxdepth");
  if (config.max_depth < 0) throw Error(p.loc_of("maxdepth"), "maxdepth must be >= 0");
  config.rr_depth = p.get_int("rrdepth");
  if (config.rr_depth < 1) throw Error(p.loc_of("rrdepth"), "rrdepth must be >= 1");
  std::string ls = p.get_string("lightsampler");
  if (ls != "power" && ls != "uniform")
    throw Error(p.loc_of("lightsampler"), "lightsampler '" + ls + "' is not supported; available: power, uniform");
  *uniform_lights = ls == "uniform";
  return config;
}

}  // namespace penumbra::bdpt
