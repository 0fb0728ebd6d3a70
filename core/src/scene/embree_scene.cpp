#include "scene/embree_scene.h"

#include "render/ray_counter.h"
#include "scene/triangle_surface.h"

#include <penumbra/error.h>

#include <fmt/core.h>

#include <bit>
#include <type_traits>

namespace penumbra {

static void embree_error(void*, RTCError code, const char* message) {
  throw Error(fmt::format("Embree error {}: {}", static_cast<int>(code), message ? message : ""));
}

// What every hit records besides its surface: distance, direction back, ids, material, media and
// the primitive's emitter (one per triangle of a mesh, one for other shapes).
[[gnu::always_inline]] inline void EmbreeScene::fill_hit_record(const Ray& ray, float t, const Geometry& g,
                                                                unsigned shape_id, unsigned prim_id,
                                                                SurfaceInteraction& si) {
  si.t = t;
  si.wo = -glm::normalize(ray.d);
  si.shape_id = shape_id;
  si.prim_id = prim_id;
  si.bsdf = g.bsdf;
  si.media = g.media;
  if (!g.lights.empty()) si.area_light = g.lights[g.mesh ? prim_id : 0];
}

// The surface at a hit Embree reported at distance t along `ray` (in the ray's own units). The
// common case, a triangle that is not instanced and needs no tangent frame, is inlined into the
// functions that trace (intersect(), intersect_coherent()) with the triangle's surface, so it makes
// no call: 65 instructions per pixel sample fewer on the Cornell box (docs/benchmarks.md, "What
// bounds the path tracer").
[[gnu::always_inline]] inline void EmbreeScene::fill_hit(const Ray& ray, float t, const RTCHit& hit,
                                                         SurfaceInteraction& si) const {
  if (hit.instID[0] == RTC_INVALID_GEOMETRY_ID) {
    const Geometry& g = geometries_[hit.geomID];
    if (g.mesh && !g.tangent_frame) {
      fill_hit_record(ray, t, g, hit.geomID, hit.primID, si);
      g.mesh->fill_surface(hit.primID, Vec3(1.f - hit.u - hit.v, hit.u, hit.v), Vec3(hit.Ng_x, hit.Ng_y, hit.Ng_z), si);
      si.shading = Frame(si.ns);
      return;
    }
  }
  fill_hit_general(ray, t, hit, si);
}

EmbreeScene::EmbreeScene() {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw Error("cannot create an Embree device");
  rtcSetDeviceErrorFunction(device_, embree_error, nullptr);
  scene_ = rtcNewScene(device_);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
  native_packet16_ = rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) != 0;
}

EmbreeScene::~EmbreeScene() {
  for (Prototype& p : prototypes_) rtcReleaseScene(p.scene);
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

// Other hits keep Frame(ns): a frame from dp/du costs 16 % more instructions per intersect() on the
// Cornell box (uv_derivatives and the Gram-Schmidt step: 1030 -> 1197 per call, 6.7 % of the path
// tracer's Li), and isotropic BSDFs do not depend on it.
static bool wants_tangent_frame(bool textured, const SurfaceOptions& o) {
  return textured || o.tangent_frame || o.detail.any();
}

// Commits an Embree geometry into the scene or the prototype being built, and records what its hits
// need under the id Embree gave it.
unsigned EmbreeScene::attach(RTCGeometry geom, Geometry g, const Bsdf* bsdf, bool textured, MediumInterface media,
                             const SurfaceOptions& options) {
  rtcCommitGeometry(geom);
  unsigned id = rtcAttachGeometry(target_scene(), geom);
  rtcReleaseGeometry(geom);
  g.bsdf = bsdf;
  g.textured = textured;
  g.media = media;
  g.detail = options.detail;
  g.tangent_frame = wants_tangent_frame(textured, options);
  std::vector<Geometry>& geometries = target_geometries();
  if (geometries.size() <= id) geometries.resize(id + 1);
  geometries[id] = std::move(g);
  return id;
}

const GeometryUserData* EmbreeScene::keep_user_data(GeometryUserData data) {
  user_data_.push_back(std::make_unique<GeometryUserData>(std::move(data)));
  return user_data_.back().get();
}

void EmbreeScene::add_mesh(std::unique_ptr<TriangleMesh> mesh, const Bsdf* bsdf,
                           std::vector<const Light*> lights, bool textured, MediumInterface media,
                           const SurfaceOptions& options) {
  mesh->finish();
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                        RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                        mesh->P.size()));
  for (size_t i = 0; i < mesh->P.size(); ++i) {
    v[3 * i] = mesh->P[i].x;
    v[3 * i + 1] = mesh->P[i].y;
    v[3 * i + 2] = mesh->P[i].z;
    target_bounds().extend(mesh->P[i]);
  }
  auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0,
                                                             RTC_FORMAT_UINT3, 3 * sizeof(uint32_t),
                                                             mesh->triangle_count()));
  std::copy(mesh->indices.begin(), mesh->indices.end(), idx);
  if (options.cutout.active()) set_alpha_filters(geom, keep_user_data({mesh.get(), nullptr, nullptr, options.cutout}));
  Geometry g;
  g.mesh = mesh.get();
  g.lights = std::move(lights);
  attach(geom, std::move(g), bsdf, textured, media, options);
  if (target_ >= 0) prototypes_[target_].triangles += mesh->triangle_count();
  meshes_.push_back(std::move(mesh));
}

// User-geometry callbacks for spheres, disks and cylinders (one primitive per geometry). On the
// benchmark scenes (ten triangles, two spheres) Embree's native sphere primitive
// (RTC_GEOMETRY_TYPE_SPHERE_POINT) added about 400 instructions per ray to the triangles' 412; as
// user geometry the spheres add about 310 (docs/bdpt.md), and tested in a loop before Embree
// (nearest_direct_sphere(), for up to kMaxDirectSpheres) 140-210 less than that.
static void user_bounds(const RTCBoundsFunctionArguments* args) {
  const auto* data = static_cast<const GeometryUserData*>(args->geometryUserPtr);
  Bounds3 b = data->quadric ? data->quadric->world_bounds()
                            : Bounds3{data->sphere->center() - Vec3(data->sphere->radius()),
                                      data->sphere->center() + Vec3(data->sphere->radius())};
  RTCBounds* out = args->bounds_o;
  out->lower_x = b.min.x, out->lower_y = b.min.y, out->lower_z = b.min.z;
  out->upper_x = b.max.x, out->upper_y = b.max.y, out->upper_z = b.max.z;
}

// The first hit in (t_min, t_max) that the cut-out keeps (a sphere or a cylinder has two along a ray).
static std::optional<float> first_kept_hit(const GeometryUserData& data, const Ray& ray, float t_min, float t_max,
                                           unsigned geom_id) {
  for (int k = 0; k < 4; ++k) {
    auto t = data.quadric ? data.quadric->intersect(ray, t_min, t_max) : data.sphere->intersect(ray, t_min, t_max);
    if (!t || !data.cutout.active() || user_hit_kept(data, ray, *t, hit_salt(geom_id, 0, *t))) return t;
    t_min = *t;
  }
  return std::nullopt;
}

// Lane i of a ray packet of width N (N = 1 for rtcIntersect1 and rtcOccluded1).
static Ray lane_ray(RTCRayN* rays, unsigned N, unsigned i) {
  return Ray{Vec3(RTCRayN_org_x(rays, N, i), RTCRayN_org_y(rays, N, i), RTCRayN_org_z(rays, N, i)),
             Vec3(RTCRayN_dir_x(rays, N, i), RTCRayN_dir_y(rays, N, i), RTCRayN_dir_z(rays, N, i))};
}

// Embree hands user geometry one ray (rtcIntersect1) or a packet of N (the render loop's camera
// rays, rtcIntersect8): each active lane is answered as a single ray would be.
static void user_intersect(const RTCIntersectFunctionNArguments* args) {
  const auto& data = *static_cast<const GeometryUserData*>(args->geometryUserPtr);
  const unsigned N = args->N;
  RTCRayN* rays = RTCRayHitN_RayN(args->rayhit, N);
  for (unsigned i = 0; i < N; ++i) {
    if (args->valid[i] != -1) continue;
    auto t = first_kept_hit(data, lane_ray(rays, N, i), RTCRayN_tnear(rays, N, i), RTCRayN_tfar(rays, N, i),
                            args->geomID);
    if (!t) continue;
    RTCRayN_tfar(rays, N, i) = *t;
    RTCHit hit{};  // u, v and Ng stay 0: the surface is rebuilt from t in fill_hit()
    hit.geomID = args->geomID;
    hit.primID = args->primID;
    hit.instID[0] = args->context->instID[0];
    rtcCopyHitToHitN(RTCRayHitN_HitN(args->rayhit, N), &hit, N, i);
  }
}

static void user_occluded(const RTCOccludedFunctionNArguments* args) {
  const auto& data = *static_cast<const GeometryUserData*>(args->geometryUserPtr);
  const unsigned N = args->N;
  for (unsigned i = 0; i < N; ++i) {
    if (args->valid[i] != -1) continue;
    if (first_kept_hit(data, lane_ray(args->ray, N, i), RTCRayN_tnear(args->ray, N, i), RTCRayN_tfar(args->ray, N, i),
                       args->geomID))
      RTCRayN_tfar(args->ray, N, i) = -INFINITY;
  }
}

RTCGeometry EmbreeScene::new_user_geometry(const GeometryUserData& data) {
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(geom, 1);
  rtcSetGeometryUserData(geom, const_cast<GeometryUserData*>(keep_user_data(data)));
  rtcSetGeometryBoundsFunction(geom, user_bounds, nullptr);
  rtcSetGeometryIntersectFunction(geom, user_intersect);
  rtcSetGeometryOccludedFunction(geom, user_occluded);
  return geom;
}

void EmbreeScene::add_sphere(std::unique_ptr<Sphere> sphere, const Bsdf* bsdf, const Light* light, bool textured,
                             MediumInterface media, const SurfaceOptions& options) {
  RTCGeometry geom = new_user_geometry({nullptr, sphere.get(), nullptr, options.cutout});
  Vec3 c = sphere->center();
  target_bounds().extend(c - Vec3(sphere->radius()));
  target_bounds().extend(c + Vec3(sphere->radius()));
  Geometry g;
  g.sphere = sphere.get();
  if (light) g.lights.push_back(light);
  bool top_level = target_ < 0;
  unsigned id = attach(geom, std::move(g), bsdf, textured, media, options);
  if (top_level && !options.cutout.active()) direct_spheres_.push_back({sphere.get(), id});
  spheres_.push_back(std::move(sphere));
}

void EmbreeScene::add_quadric(std::unique_ptr<Quadric> quadric, const Bsdf* bsdf, const Light* light,
                              bool textured, MediumInterface media, const SurfaceOptions& options) {
  RTCGeometry geom = new_user_geometry({nullptr, nullptr, quadric.get(), options.cutout});
  Bounds3 b = quadric->world_bounds();
  target_bounds().extend(b.min);
  target_bounds().extend(b.max);
  Geometry g;
  g.quadric = quadric.get();
  if (light) g.lights.push_back(light);
  attach(geom, std::move(g), bsdf, textured, media, options);
  quadrics_.push_back(std::move(quadric));
}

void EmbreeScene::add_curves(std::unique_ptr<Curves> curves, const Bsdf* bsdf, bool textured, MediumInterface media,
                             const SurfaceOptions& options) {
  has_curves_ = true;
  for (const Vec4& c : curves->control) curve_back_ = std::max(curve_back_, 2.5f * c.w);
  const bool ribbon = curves->type == CurveType::Ribbon;
  RTCGeometry geom =
      rtcNewGeometry(device_, ribbon ? RTC_GEOMETRY_TYPE_NORMAL_ORIENTED_BEZIER_CURVE : RTC_GEOMETRY_TYPE_FLAT_BEZIER_CURVE);
  const size_t n = curves->control.size();
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                                        4 * sizeof(float), n));
  for (size_t i = 0; i < n; ++i) {
    const Vec4& c = curves->control[i];
    for (int k = 0; k < 4; ++k) v[4 * i + k] = c[k];
    target_bounds().extend(Vec3(c) - Vec3(c.w));
    target_bounds().extend(Vec3(c) + Vec3(c.w));
  }
  if (ribbon) {
    auto* nb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_NORMAL, 0, RTC_FORMAT_FLOAT3,
                                                           3 * sizeof(float), n));
    for (size_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) nb[3 * i + k] = curves->normals[i][k];
  }
  auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT,
                                                             sizeof(uint32_t), curves->segment_count()));
  for (size_t i = 0; i < curves->segment_count(); ++i) idx[i] = static_cast<uint32_t>(4 * i);
  rtcSetGeometryTessellationRate(geom, 16.f);  // quads per flat segment: Embree's most
  Geometry g;
  g.curves = curves.get();
  SurfaceOptions o = options;
  o.tangent_frame = true;  // pbrt-v4's frame: x along the strand (hair BSDFs and anisotropy need it)
  attach(geom, std::move(g), bsdf, textured, media, o);
  curves_.push_back(std::move(curves));
}

void EmbreeScene::set_lights(std::vector<const Light*> lights, std::vector<const Light*> infinite) {
  lights_ = std::move(lights);
  infinite_ = std::move(infinite);
  std::vector<float> power;
  for (size_t i = 0; i < lights_.size(); ++i) {
    const_cast<Light*>(lights_[i])->set_index(static_cast<uint32_t>(i));
    power.push_back(std::max(0.f, luminance(lights_[i]->power())));
  }
  if (lights_.empty()) return;
  light_table_ = AliasTable(power);
}

void EmbreeScene::commit() {
  if (has_curves_ || direct_spheres_.size() > kMaxDirectSpheres) direct_spheres_.clear();
  for (const DirectSphere& d : direct_spheres_) rtcDisableGeometry(rtcGetGeometry(scene_, d.id));
  direct_lanes_ = DirectSphereLanes{};
  for (size_t k = 0; k < direct_spheres_.size(); ++k) {
    const Sphere& sphere = *direct_spheres_[k].sphere;
    direct_lanes_.cx[k] = sphere.center().x, direct_lanes_.cy[k] = sphere.center().y;
    direct_lanes_.cz[k] = sphere.center().z, direct_lanes_.r2[k] = sphere.radius() * sphere.radius();
    direct_lanes_.used |= 1u << k;
  }
  rtcCommitScene(scene_);
}

// The pre-test of every direct sphere in one pass: lanes past the spheres' count are masked off.
// Sphere by sphere, the two spheres of the benchmark scenes cost 45-55 more instructions per ray.
unsigned EmbreeScene::direct_sphere_candidates(const Ray& ray) const {
  const DirectSphereLanes& l = direct_lanes_;
  auto lanes = [](float x) { return Lanes{} + x; };
  auto missed = sphere_surely_missed<Lanes>(lanes(ray.o.x), lanes(ray.o.y), lanes(ray.o.z), lanes(ray.d.x),
                                            lanes(ray.d.y), lanes(ray.d.z), l.cx, l.cy, l.cz, l.r2);
#if defined(__SSE__)
  unsigned missed_bits = unsigned(__builtin_ia32_movmskps(reinterpret_cast<Lanes>(missed)));  // lane k: bit k
#else
  unsigned missed_bits = 0;
  for (unsigned k = 0; k < kMaxDirectSpheres; ++k) missed_bits |= unsigned(missed[k] != 0) << k;
#endif
  return ~missed_bits & l.used;
}

unsigned EmbreeScene::nearest_direct_sphere(const Ray& ray, float* t_max) const {
  unsigned id = RTC_INVALID_GEOMETRY_ID;
  for (unsigned c = direct_sphere_candidates(ray); c != 0; c &= c - 1) {
    const DirectSphere& d = direct_spheres_[std::countr_zero(c)];
    if (auto t = d.sphere->solve(ray, 0.f, *t_max)) {
      *t_max = *t;
      id = d.id;
    }
  }
  return id;
}

void EmbreeScene::fill_direct_sphere_hit(const Ray& ray, float t, unsigned id, SurfaceInteraction& si) const {
  RTCHit hit{};  // as user_intersect() reports a sphere: the surface is rebuilt from t
  hit.geomID = id;
  hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  fill_hit(ray, t, hit, si);
}

int EmbreeScene::begin_prototype() {
  if (target_ >= 0) throw Error("object definitions cannot nest");
  Prototype p;
  p.scene = rtcNewScene(device_);
  rtcSetSceneBuildQuality(p.scene, RTC_BUILD_QUALITY_HIGH);
  prototypes_.push_back(std::move(p));
  target_ = static_cast<int>(prototypes_.size()) - 1;
  return target_;
}

void EmbreeScene::end_prototype() {
  rtcCommitScene(prototypes_[target_].scene);
  target_ = -1;
}

void EmbreeScene::add_instance(int prototype, const Mat4& to_world) {
  const Prototype& proto = prototypes_.at(prototype);
  if (proto.geometries.empty()) return;  // an empty object places nothing
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
  rtcSetGeometryInstancedScene(geom, proto.scene);
  rtcSetGeometryTimeStepCount(geom, 1);
  rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &to_world[0][0]);
  rtcCommitGeometry(geom);
  unsigned id = rtcAttachGeometry(scene_, geom);
  rtcReleaseGeometry(geom);
  if (instances_.size() <= id) instances_.resize(id + 1);
  Instance inst;
  inst.prototype = prototype;
  inst.to_world = to_world;
  inst.to_object = glm::inverse(to_world);
  inst.normal_to_world = glm::transpose(glm::mat3(inst.to_object));
  instances_[id] = inst;
  ++instance_count_;
  for (int k = 0; k < 8; ++k) {  // the prototype's box, placed
    Vec3 c((k & 1) ? proto.bounds.max.x : proto.bounds.min.x, (k & 2) ? proto.bounds.max.y : proto.bounds.min.y,
           (k & 4) ? proto.bounds.max.z : proto.bounds.min.z);
    bounds_.extend(Vec3(to_world * Vec4(c, 1.f)));
  }
}

size_t EmbreeScene::instanced_triangle_count() const {
  size_t n = 0;
  for (const Instance& inst : instances_)
    if (inst.prototype >= 0) n += prototypes_[inst.prototype].triangles;
  return n;
}

size_t EmbreeScene::triangle_count() const {
  size_t n = 0;
  for (const auto& m : meshes_) n += m->triangle_count();
  return n;
}

std::optional<SampledLight> EmbreeScene::sample_light(float u) const {
  if (lights_.empty()) return std::nullopt;
  size_t i = light_table_.sample(u);
  float pmf = light_table_.pmf(i);
  if (pmf == 0.f) return std::nullopt;
  return SampledLight{lights_[i], pmf};
}

float EmbreeScene::light_pmf(const Light* light) const {
  if (lights_.empty() || !light) return 0.f;
  return light_table_.pmf(light->index());  // 0 for a light of another scene (index out of range)
}

// Embree ignores curve hits closer to the ray's origin than about two radii (its self-intersection
// avoidance), which would hide a neighbouring strand that pbrt-v4 sees. With curves in the scene the
// ray reaches Embree with a unit direction, its origin moved back along it by `back` (more than two of
// the largest radius) and tnear = back, so the blind zone lies before the ray's real start.
// Inline: called out of line it cost 23 instructions per ray on the Cornell box.
inline RTCRayHit EmbreeScene::embree_ray(const Ray& ray, float* t_scale, float* t_shift) const {
  *t_scale = 1.f;
  *t_shift = 0.f;
  if (!has_curves_) return embree_query(ray);
  float len = glm::length(ray.d);
  if (!(len > 0.f) || !std::isfinite(len)) return embree_query(ray);
  Vec3 d = ray.d / len;
  RTCRayHit rh = embree_query(Ray{ray.o - curve_back_ * d, d, ray.tmax * len + curve_back_}, curve_back_);
  *t_scale = len;
  *t_shift = curve_back_;
  return rh;
}

std::optional<SurfaceInteraction> EmbreeScene::intersect(const Ray& ray) const {
  count_ray();
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  float t_scale, t_shift;
  RTCRayHit rh = embree_ray(ray, &t_scale, &t_shift);
  // Spheres outside Embree first (never with curves, so t needs no rescaling): Embree then looks
  // only for something nearer.
  unsigned sphere = direct_spheres_.empty() ? RTC_INVALID_GEOMETRY_ID : nearest_direct_sphere(ray, &rh.ray.tfar);
  rtcIntersect1(scene_, &ctx, &rh);
  // Filled where the caller receives it (no copy out). Built engaged and reset for a miss: GCC 12
  // zero-fills an empty std::optional's whole storage with `rep stos` (3 % of a path tracer's time).
  std::optional<SurfaceInteraction> out(std::in_place);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
    if (sphere != RTC_INVALID_GEOMETRY_ID) fill_direct_sphere_hit(ray, rh.ray.tfar, sphere, *out);
    else out.reset();
    return out;
  }
  if (has_curves_) rh.ray.tfar = (rh.ray.tfar - t_shift) / t_scale;
  fill_hit(ray, rh.ray.tfar, rh.hit, *out);
  return out;
}

void EmbreeScene::intersect_coherent(std::span<const Ray* const> rays, std::optional<SurfaceInteraction>* hits) const {
  if (has_curves_ || rays.size() > 16) {  // curves move each ray's origin (embree_ray()): one at a time
    for (size_t i = 0; i < rays.size(); ++i) {
      if (rays[i]) hits[i] = intersect(*rays[i]);
      else hits[i].reset();
    }
    return;
  }
  if (rays.size() > 8) intersect_packet<16>(rays, hits);
  else intersect_packet<8>(rays, hits);
}

template <int kWidth>
void EmbreeScene::intersect_packet(std::span<const Ray* const> rays, std::optional<SurfaceInteraction>* hits) const {
  using Packet = std::conditional_t<kWidth == 16, RTCRayHit16, RTCRayHit8>;
  // Each lane is the ray intersect() would trace (embree_query()); empty lanes are masked off.
  alignas(64) int valid[kWidth];
  alignas(64) Packet packet;
  unsigned spheres[kWidth];
  RTCRayN* lanes = RTCRayHitN_RayN(reinterpret_cast<RTCRayHitN*>(&packet), kWidth);
  RTCHitN* lane_hits = RTCRayHitN_HitN(reinterpret_cast<RTCRayHitN*>(&packet), kWidth);
  for (unsigned i = 0; i < kWidth; ++i) {
    const Ray* r = i < rays.size() ? rays[i] : nullptr;
    valid[i] = r ? -1 : 0;
    RTCRayHit one = embree_query(r ? *r : Ray{Vec3(0.f), Vec3(0.f, 0.f, 1.f), -Infinity});
    spheres[i] = r && !direct_spheres_.empty() ? nearest_direct_sphere(*r, &one.ray.tfar) : RTC_INVALID_GEOMETRY_ID;
    RTCRayN_org_x(lanes, kWidth, i) = one.ray.org_x, RTCRayN_org_y(lanes, kWidth, i) = one.ray.org_y;
    RTCRayN_org_z(lanes, kWidth, i) = one.ray.org_z, RTCRayN_tnear(lanes, kWidth, i) = one.ray.tnear;
    RTCRayN_dir_x(lanes, kWidth, i) = one.ray.dir_x, RTCRayN_dir_y(lanes, kWidth, i) = one.ray.dir_y;
    RTCRayN_dir_z(lanes, kWidth, i) = one.ray.dir_z, RTCRayN_time(lanes, kWidth, i) = one.ray.time;
    RTCRayN_tfar(lanes, kWidth, i) = one.ray.tfar, RTCRayN_mask(lanes, kWidth, i) = one.ray.mask;
    RTCRayN_id(lanes, kWidth, i) = one.ray.id, RTCRayN_flags(lanes, kWidth, i) = one.ray.flags;
    RTCHitN_geomID(lane_hits, kWidth, i) = one.hit.geomID;
    RTCHitN_instID(lane_hits, kWidth, i, 0) = one.hit.instID[0];
  }
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  if constexpr (kWidth == 16) rtcIntersect16(valid, scene_, &ctx, &packet);
  else rtcIntersect8(valid, scene_, &ctx, &packet);
  for (size_t i = 0; i < rays.size(); ++i) {
    hits[i].reset();
    if (!rays[i]) continue;
    count_ray();
    if (RTCHitN_geomID(lane_hits, kWidth, i) == RTC_INVALID_GEOMETRY_ID) {
      if (spheres[i] != RTC_INVALID_GEOMETRY_ID)
        fill_direct_sphere_hit(*rays[i], RTCRayN_tfar(lanes, kWidth, i), spheres[i], hits[i].emplace());
      continue;
    }
    fill_hit(*rays[i], RTCRayN_tfar(lanes, kWidth, i), rtcGetHitFromHitN(lane_hits, kWidth, i), hits[i].emplace());
  }
}

EmbreeScene::GeometryView EmbreeScene::geometry_view(unsigned id, unsigned prim) const {
  if (id >= geometries_.size() || (id < instances_.size() && instances_[id].prototype >= 0))
    return {nullptr, nullptr, nullptr};
  const Geometry& g = geometries_[id];
  return {g.mesh, g.bsdf, g.lights.empty() ? nullptr : g.lights.at(g.mesh ? prim : 0)};
}

// fill_hit() for every other hit: instanced, on another shape, or with a tangent frame.
void EmbreeScene::fill_hit_general(const Ray& ray, float t, const RTCHit& hit, SurfaceInteraction& si) const {
  // A hit inside an instance is computed in the prototype's space and then placed.
  const Instance* inst = hit.instID[0] != RTC_INVALID_GEOMETRY_ID ? &instances_[hit.instID[0]] : nullptr;
  const Geometry& g = inst ? prototypes_[inst->prototype].geometries[hit.geomID] : geometries_[hit.geomID];
  fill_hit_record(ray, t, g, inst ? hit.instID[0] : hit.geomID, hit.primID, si);
  Ray local = inst ? Ray{Vec3(inst->to_object * Vec4(ray.o, 1.f)), glm::mat3(inst->to_object) * ray.d, ray.tmax} : ray;
  Vec3 dpdu(0.f), dpdv(0.f);  // for tangent frames and texture footprints only
  if (g.mesh) {
    // The hit point comes from the barycentrics: its error does not grow with t.
    g.mesh->surface(hit.primID, Vec3(1.f - hit.u - hit.v, hit.u, hit.v), Vec3(hit.Ng_x, hit.Ng_y, hit.Ng_z), si);
    if (g.tangent_frame) g.mesh->uv_derivatives(hit.primID, &dpdu, &dpdv);
  } else if (g.curves) {
    Curves::Surface s = g.curves->surface(hit.primID, hit.u, hit.v, local.o + si.t * local.d,
                                          glm::normalize(local.d), Vec3(hit.Ng_x, hit.Ng_y, hit.Ng_z));
    dpdu = s.dpdu;
    dpdv = s.dpdv;
    si.p = s.p;
    si.p_error = s.p_error;
    si.ng = s.ng;
    si.ns = s.ns;
    si.uv = s.uv;
  } else if (g.quadric) {
    Quadric::Surface s = g.quadric->surface_at(local, si.t);
    dpdu = s.dpdu;
    dpdv = s.dpdv;
    si.p = s.p;
    si.p_error = s.p_error;
    si.ng = si.ns = s.n;
    si.uv = s.uv;
  } else {
    si.p = g.sphere->reproject(local.o + si.t * local.d);
    si.p_error = error_gamma(5) * abs_each(si.p);
    si.ng = si.ns = g.sphere->normal_at(si.p);
    si.uv = g.sphere->uv_at(si.p);
    if (g.tangent_frame) g.sphere->uv_derivatives(si.p, &dpdu, &dpdv);
  }
  if (inst) {
    place_instanced_hit(si, *inst);
    dpdu = glm::mat3(inst->to_world) * dpdu;
    dpdv = glm::mat3(inst->to_world) * dpdv;
  }
  if (!g.tangent_frame) {
    si.shading = Frame(si.ns);
    return;
  }
  // The shading frame follows dp/du (pbrt-v4's BSDF frame), so anisotropic lobes and normal maps are
  // oriented by the parameterisation.
  si.shading = tangent_frame(si.ns, dpdu);
  if (g.textured) add_texture_footprint(si, dpdu, dpdv);
  if (g.detail.any()) apply_surface_detail(g.detail, shading_geometry(g, si, dpdu, dpdv), si);
}

// Point, normals and the error bound from the prototype's space to the world, as pbrt-v4 transforms
// an instance's SurfaceInteraction (normals by the inverse transpose). The error bound is the
// transformed bound plus the rounding of the transform itself.
void EmbreeScene::place_instanced_hit(SurfaceInteraction& si, const Instance& inst) const {
  Vec3 p = Vec3(inst.to_world * Vec4(si.p, 1.f));
  glm::mat3 abs_m(glm::abs(glm::mat3(inst.to_world)[0]), glm::abs(glm::mat3(inst.to_world)[1]),
                  glm::abs(glm::mat3(inst.to_world)[2]));
  Vec3 t = glm::abs(Vec3(inst.to_world[3]));
  si.p_error = (1.f + error_gamma(3)) * (abs_m * si.p_error) + error_gamma(3) * (abs_m * glm::abs(si.p) + t);
  si.p = p;
  si.ng = glm::normalize(inst.normal_to_world * si.ng);
  si.ns = glm::normalize(inst.normal_to_world * si.ns);
}

// The hit's shading geometry as pbrt-v4 has it before bump or normal mapping.
ShadingGeometry EmbreeScene::shading_geometry(const Geometry& g, const SurfaceInteraction& si, const Vec3& dpdu,
                                              const Vec3& dpdv) {
  ShadingGeometry sg{si.ns, dpdu, dpdv};
  if (g.mesh && !g.mesh->N.empty()) {  // dp/du made orthogonal to the interpolated normal, dp/dv = n x dp/du
    Vec3 t = glm::cross(si.ns, dpdu);
    if (glm::dot(t, t) > 0.f) {
      sg.dpdu = glm::cross(t, si.ns);
      sg.dpdv = t;
    }
  } else if (g.sphere) {  // n = (p - c) / r: dn/du = dp/du / r
    sg.dndu = dpdu / g.sphere->radius();
    sg.dndv = dpdv / g.sphere->radius();
  }
  return sg;
}

// pbrt-v4's differentials without ray differentials: the camera estimates how far p moves per
// pixel, and (du, dv) follow from dp = du dpdu + dv dpdv by least squares in the tangent plane.
void EmbreeScene::add_texture_footprint(SurfaceInteraction& si, const Vec3& dpdu, const Vec3& dpdv) const {
  camera_->approximate_dp_dxy(si.p, si.ng, &si.dpdx, &si.dpdy);
  si.dpdx *= footprint_scale_;
  si.dpdy *= footprint_scale_;
  float a00 = glm::dot(dpdu, dpdu), a01 = glm::dot(dpdu, dpdv), a11 = glm::dot(dpdv, dpdv);
  float det = a00 * a11 - a01 * a01;
  float inv = det != 0.f ? 1.f / det : 0.f;
  if (!std::isfinite(inv)) inv = 0.f;
  auto solve = [&](const Vec3& d, float* du, float* dv) {
    float b0 = glm::dot(dpdu, d), b1 = glm::dot(dpdv, d);
    *du = std::clamp((a11 * b0 - a01 * b1) * inv, -1e8f, 1e8f);
    *dv = std::clamp((a00 * b1 - a01 * b0) * inv, -1e8f, 1e8f);
  };
  solve(si.dpdx, &si.dudx, &si.dvdx);
  solve(si.dpdy, &si.dudy, &si.dvdy);
}

Rgb EmbreeScene::transmittance(int medium, float distance, const SampledWavelengths* wavelengths) const {
  if (medium < 0) return Rgb(1.f);
  const Rgb sigma = wavelengths ? wavelengths->unbounded(media_sigma_a_[medium]) : media_sigma_a_[medium];
  auto channel = [&](float s) { return s == 0.f ? 1.f : std::exp(-s * distance); };  // 0 * inf is no absorption
  return Rgb(channel(sigma.r), channel(sigma.g), channel(sigma.b));
}

bool EmbreeScene::occluded(const Ray& ray) const {
  count_ray();
  if (!direct_spheres_.empty())  // any hit will do, so no nearest_direct_sphere()
    for (unsigned c = direct_sphere_candidates(ray); c != 0; c &= c - 1)
      if (direct_spheres_[std::countr_zero(c)].sphere->solve(ray, 0.f, ray.tmax)) return true;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  float t_scale, t_shift;
  RTCRayHit rh = embree_ray(ray, &t_scale, &t_shift);
  rtcOccluded1(scene_, &ctx, &rh.ray);
  return rh.ray.tfar < 0.f;
}

}  // namespace penumbra
