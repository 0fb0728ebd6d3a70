// The renderable scene: Embree 3 geometry (triangle meshes and curves, and spheres, disks and
// cylinders as user geometry with analytic intersection; a few spheres tested before Embree) plus what a hit
// needs to become a SurfaceInteraction (material, area lights, orientation).
#pragma once

#include <penumbra/bsdf.h>
#include <penumbra/scene.h>

#include "scene/alpha_cutout.h"
#include "scene/curves.h"
#include "scene/quadrics.h"
#include "scene/sphere.h"
#include "scene/surface_detail.h"
#include "scene/triangle_mesh.h"
#include "util/alias_table.h"

#include <embree3/rtcore.h>
#include <immintrin.h>

#include <algorithm>
#include <bit>
#include <cstddef>
#include <memory>
#include <vector>

namespace penumbra {

/// The Embree query for `ray` over (tnear, ray.tmax): a closest-hit query, or an occlusion query
/// through its `ray` member. Written as three whole 16-byte stores because Embree starts a traversal
/// by loading the origin with tnear, and the direction with time, as 16-byte vectors. Written field
/// by field (smaller stores still in flight when Embree loads them), those loads cannot take their
/// data from the stores and wait until the stores reach the cache: a stall at the start of every
/// ray, which raw Embree, tracing rays built long before, never has. 4 % of the path tracer's time
/// on the Cornell box (docs/benchmarks.md, "Rays handed to Embree in whole vectors").
inline RTCRayHit embree_query(const Ray& ray, float tnear = 0.f) {
  static_assert(offsetof(RTCRay, tnear) == offsetof(RTCRay, org_x) + 12 &&
                    offsetof(RTCRay, time) == offsetof(RTCRay, dir_x) + 12 &&
                    offsetof(RTCRay, flags) == offsetof(RTCRay, tfar) + 12,
                "each 16-byte store below covers four of RTCRay's fields, in Embree 3's order");
  RTCRayHit rh;
  _mm_storeu_ps(&rh.ray.org_x, _mm_setr_ps(ray.o.x, ray.o.y, ray.o.z, tnear));
  _mm_storeu_ps(&rh.ray.dir_x, _mm_setr_ps(ray.d.x, ray.d.y, ray.d.z, 0.f));  // time 0
  _mm_storeu_ps(&rh.ray.tfar, _mm_setr_ps(ray.tmax, std::bit_cast<float>(0xFFFFFFFFu), 0.f, 0.f));  // mask, id, flags
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

/// What a shape's material and the shape itself add to its hits: bump or normal map, alpha cut-out.
struct SurfaceOptions {
  SurfaceDetail detail;
  AlphaCutout cutout;
  /// Build the shading frame from dp/du (pbrt-v4's) rather than from the normal alone: for anisotropic
  /// materials. Hits that are textured or bump/normal-mapped get it anyway.
  bool tangent_frame = false;
};

class EmbreeScene final : public Scene {
 public:
  EmbreeScene();
  ~EmbreeScene() override;
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  /// Adds a mesh; `lights` is empty or holds one area light per triangle. Hits on geometry whose
  /// material is `textured` get uv derivatives and a pixel footprint (SurfaceInteraction::dpdx ...).
  /// `media`: the media on the geometry's two sides (indices into set_media()'s table).
  void add_mesh(std::unique_ptr<TriangleMesh> mesh, const Bsdf* bsdf, std::vector<const Light*> lights,
                bool textured = false, MediumInterface media = {}, const SurfaceOptions& options = {});
  void add_sphere(std::unique_ptr<Sphere> sphere, const Bsdf* bsdf, const Light* light, bool textured = false,
                  MediumInterface media = {}, const SurfaceOptions& options = {});
  /// Multiplies the texture footprint: pbrt-v4's max(1/8, 1/sqrt(spp)), since many samples per pixel
  /// already average what a wider filter would. 1 until set.
  void set_texture_footprint_scale(float s) { footprint_scale_ = s; }
  /// Adds pbrt-v4 curves as Embree Bezier curves (flat and cylinder: ray-facing; ribbon: oriented).
  void add_curves(std::unique_ptr<Curves> curves, const Bsdf* bsdf, bool textured = false, MediumInterface media = {},
                  const SurfaceOptions& options = {});
  void add_quadric(std::unique_ptr<Quadric> quadric, const Bsdf* bsdf, const Light* light, bool textured = false,
                   MediumInterface media = {}, const SurfaceOptions& options = {});
  /// Object instancing (pbrt-v4's ObjectBegin/ObjectInstance through Embree instances: one copy of
  /// the geometry however many instances). Between begin_prototype() and end_prototype() the add_*
  /// calls build prototype `id` (no area lights) instead of the scene; add_instance() places it.
  int begin_prototype();
  void end_prototype();
  void add_instance(int prototype, const Mat4& to_world);
  size_t instance_count() const { return instance_count_; }
  /// Triangles as the instances place them (each instance counts its prototype's again).
  size_t instanced_triangle_count() const;
  /// Absorption coefficients of the media that geometry names by index.
  void set_media(std::vector<Rgb> sigma_a) { media_sigma_a_ = std::move(sigma_a); }
  bool has_media() const override { return !media_sigma_a_.empty(); }
  Rgb transmittance(int medium, float distance, const SampledWavelengths* wavelengths) const override;
  /// Meshes and spheres kept for area lights to reference before commit().
  const TriangleMesh& mesh(size_t i) const { return *meshes_[i]; }

  /// Keeps the shapes that area lights refer to (per-triangle shapes, cut-out wrappers) alive as
  /// long as the scene.
  void adopt_shapes(std::vector<std::unique_ptr<Shape>> shapes) { light_shapes_ = std::move(shapes); }
  void set_lights(std::vector<const Light*> lights, std::vector<const Light*> infinite);
  void set_camera(std::unique_ptr<Camera> camera) { camera_ = std::move(camera); }
  /// Builds the BVH. Call once, after all geometry was added.
  void commit();

  std::optional<SurfaceInteraction> intersect(const Ray& ray) const override;
  bool occluded(const Ray& ray) const override;
  /// intersect() of up to 16 rays at once, as one packet (Embree's rtcIntersect8 for up to 8,
  /// rtcIntersect16 above; coherent): for rays that start together and diverge little, such as the
  /// camera rays of neighbouring pixels. A null ray gets no hit. The render loop gives each packet a
  /// fixed set of rays (a pixel block at one sample index), because where two triangles share an
  /// edge, which one a ray reports can depend on the other rays of its packet.
  void intersect_coherent(std::span<const Ray* const> rays, std::optional<SurfaceInteraction>* hits) const;
  /// The packet width the render loop should use: 16 where this machine's Embree traces 16-wide
  /// packets natively (AVX-512), else 8. (Embree emulates packets wider than the machine's vectors.)
  int packet_width() const { return native_packet16_ ? 16 : 8; }
  std::span<const Light* const> lights() const override { return lights_; }
  std::span<const Light* const> infinite_lights() const override { return infinite_; }
  std::optional<SampledLight> sample_light(float u) const override;
  float light_pmf(const Light* light) const override;
  const Camera& camera() const override { return *camera_; }
  Bounds3 bounds() const override { return bounds_; }

  size_t triangle_count() const;
  /// Spheres intersected by the scene itself rather than by Embree (see direct_spheres_).
  size_t spheres_outside_embree() const { return direct_spheres_.size(); }
  /// Embree's scene: every geometry except the spheres_outside_embree().
  RTCScene rtc_scene() const { return scene_; }

  /// What top-level Embree geometry `id` is, for tools that trace rtc_scene() themselves (bench/):
  /// its triangle mesh (null for other shapes and instances), its BSDF, and the light of its
  /// primitive `prim` (null if it does not emit). Ids run from 0 to geometry_count() - 1.
  struct GeometryView {
    const TriangleMesh* mesh;
    const Bsdf* bsdf;
    const Light* light;
  };
  size_t geometry_count() const { return std::max(geometries_.size(), instances_.size()); }
  GeometryView geometry_view(unsigned id, unsigned prim) const;

 private:
  struct Geometry {
    const TriangleMesh* mesh = nullptr;  // one of these two
    const Sphere* sphere = nullptr;
    const Quadric* quadric = nullptr;
    const Curves* curves = nullptr;
    const Bsdf* bsdf = nullptr;
    std::vector<const Light*> lights;    // per primitive, or empty
    bool textured = false;
    MediumInterface media;
    SurfaceDetail detail;
    bool tangent_frame = false;  // textured, detailed or asked for by SurfaceOptions
  };
  struct Prototype {
    RTCScene scene = nullptr;
    std::vector<Geometry> geometries;  // indexed by Embree geometry id in `scene`
    Bounds3 bounds;
    size_t triangles = 0;
  };
  struct Instance {
    int prototype = -1;  // -1: the top-level geometry of this id is not an instance
    Mat4 to_world{1.f}, to_object{1.f};
    glm::mat3 normal_to_world{1.f};
  };
  // Where add_* put geometry: the scene, or the prototype being built.
  RTCScene target_scene() const { return target_ < 0 ? scene_ : prototypes_[target_].scene; }
  std::vector<Geometry>& target_geometries() { return target_ < 0 ? geometries_ : prototypes_[target_].geometries; }
  Bounds3& target_bounds() { return target_ < 0 ? bounds_ : prototypes_[target_].bounds; }
  void place_instanced_hit(SurfaceInteraction& si, const Instance& inst) const;
  RTCRayHit embree_ray(const Ray& ray, float* t_scale, float* t_shift) const;
  void fill_hit(const Ray& ray, float t, const RTCHit& hit, SurfaceInteraction& si) const;
  /// intersect_coherent() as one packet of kWidth (8 or 16) lanes.
  template <int kWidth>
  void intersect_packet(std::span<const Ray* const> rays, std::optional<SurfaceInteraction>* hits) const;
  void fill_hit_general(const Ray& ray, float t, const RTCHit& hit, SurfaceInteraction& si) const;
  static void fill_hit_record(const Ray& ray, float t, const Geometry& g, unsigned shape_id, unsigned prim_id,
                              SurfaceInteraction& si);
  unsigned attach(RTCGeometry geom, Geometry g, const Bsdf* bsdf, bool textured, MediumInterface media,
                  const SurfaceOptions& options);
  /// The nearest hit on the spheres tested outside Embree with t in (0, *t_max): lowers *t_max to
  /// it and returns the sphere's geometry id, or RTC_INVALID_GEOMETRY_ID.
  unsigned nearest_direct_sphere(const Ray& ray, float* t_max) const;
  /// fill_hit() for a hit on a sphere tested outside Embree.
  void fill_direct_sphere_hit(const Ray& ray, float t, unsigned id, SurfaceInteraction& si) const;
  void add_texture_footprint(SurfaceInteraction& si, const Vec3& dpdu, const Vec3& dpdv) const;
  const GeometryUserData* keep_user_data(GeometryUserData data);
  /// An Embree user geometry of one analytic primitive (a sphere or a quadric in `data`).
  RTCGeometry new_user_geometry(const GeometryUserData& data);
  static ShadingGeometry shading_geometry(const Geometry& g, const SurfaceInteraction& si, const Vec3& dpdu,
                                          const Vec3& dpdv);

  std::vector<Prototype> prototypes_;
  std::vector<Instance> instances_;  // indexed by Embree geometry id in scene_
  int target_ = -1;
  size_t instance_count_ = 0;

  std::vector<Rgb> media_sigma_a_;
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  bool native_packet16_ = false;  // rtcIntersect16 is native on this machine (packet_width())
  std::vector<std::unique_ptr<TriangleMesh>> meshes_;
  std::vector<std::unique_ptr<Sphere>> spheres_;
  // A scene with a few whole spheres (benchmark scenes: two) tests them itself, in a loop before
  // Embree, and Embree's copies are disabled: through Embree's user geometry every ray paid for a
  // second BVH and the callbacks; the loop costs 140-210 instructions per ray less on the benchmark
  // scenes (docs/benchmarks.md, "Spheres outside Embree"). Top-level spheres without a cut-out qualify;
  // with more than kMaxDirectSpheres of them, or with curves (whose rays Embree gets rescaled),
  // every sphere stays in Embree.
  struct DirectSphere {
    const Sphere* sphere;
    unsigned id;  // Embree geometry id, under which geometries_ describes it
  };
  static constexpr size_t kMaxDirectSpheres = 4;
  std::vector<DirectSphere> direct_spheres_;
  // Their centres and squared radii in lanes, for the pre-test of all at once.
  using Lanes = float __attribute__((vector_size(4 * kMaxDirectSpheres)));
  struct DirectSphereLanes {
    Lanes cx, cy, cz, r2;
    unsigned used;  // bit k: lane k holds a sphere
  };
  DirectSphereLanes direct_lanes_{};
  /// Bit k set: direct sphere k may be hit by `ray` (sphere_surely_missed() of each, in one pass).
  unsigned direct_sphere_candidates(const Ray& ray) const;
  std::vector<std::unique_ptr<Quadric>> quadrics_;
  std::vector<std::unique_ptr<Curves>> curves_;
  bool has_curves_ = false;  // rays then reach Embree moved back by curve_back_ (see embree_ray())
  float curve_back_ = 0.f;
  std::vector<std::unique_ptr<Shape>> light_shapes_;
  std::vector<Geometry> geometries_;  // indexed by Embree geometry id
  std::vector<std::unique_ptr<GeometryUserData>> user_data_;  // Embree callbacks' (quadrics, cut-outs)
  std::vector<const Light*> lights_, infinite_;
  AliasTable light_table_;  // over lights_, proportional to the luminance of their power
  std::unique_ptr<Camera> camera_;
  Bounds3 bounds_;
  float footprint_scale_ = 1.f;
};

}  // namespace penumbra
