// Alpha cut-outs on shapes (pbrt-v4's "float alpha" / "texture alpha"): a hit where alpha is 0 is
// ignored by every ray (camera, bounce, shadow), one where it is 1 counts, and in between it counts
// with probability alpha, decided by a hash of the ray's origin and direction (pbrt-v4's HashFloat)
// and of the hit (primitive and distance), so that the same ray always decides the same way and
// stacked layers decide independently. Triangle meshes and spheres test it in Embree intersection and occlusion filters;
// disks and cylinders in their own intersection callbacks.
#pragma once

#include <penumbra/interaction.h>
#include <penumbra/texture.h>

#include <embree3/rtcore.h>

#include <cstdint>

namespace penumbra {

struct TriangleMesh;
class Sphere;
class Quadric;

struct AlphaCutout {
  TexturedFloat alpha{1.f};
  /// Whether there is anything to test (a texture, or a constant below 1).
  bool active() const { return !alpha.is_constant() || alpha.constant() < 1.f; }
  /// Whether a hit at `ctx` counts for the ray (o, d); `salt` identifies the primitive.
  bool keeps(const TextureEvalContext& ctx, const Vec3& o, const Vec3& d, uint64_t salt) const;
};

/// pbrt-v4's HashFloat(o, d), with a salt: a number in [0, 1) that is a pure function of its inputs.
float alpha_hash(const Vec3& o, const Vec3& d, uint64_t salt);

/// What Embree's callbacks for one geometry need: the shape (one of the three) and its cut-out.
struct GeometryUserData {
  const TriangleMesh* mesh = nullptr;
  const Sphere* sphere = nullptr;
  const Quadric* quadric = nullptr;
  AlphaCutout cutout;
};

/// Installs the intersection and occlusion filters of a triangle mesh geometry whose
/// `data` has an active cut-out (data must outlive the scene).
void set_alpha_filters(RTCGeometry geom, const GeometryUserData* data);

/// What identifies a hit besides its ray: geometry, primitive and distance (a sphere or cylinder can be
/// hit twice along a ray, and each layer decides on its own, as pbrt-v4's re-traced rays do).
uint64_t hit_salt(unsigned geom, unsigned prim, float t);

/// For user geometry (a sphere or a quadric): whether its hit at t of the ray counts (`salt`: hit_salt()).
bool user_hit_kept(const GeometryUserData& data, const Ray& ray, float t, uint64_t salt);

}  // namespace penumbra
