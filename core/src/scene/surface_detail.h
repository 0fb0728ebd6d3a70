// Bump maps and normal maps (pbrt-v4's "displacement" and "normalmap" material parameters), applied by
// the core to a hit's shading geometry for every material alike: the scene builder takes the two
// parameters off the material before its plugin sees them, and EmbreeScene::intersect() calls
// apply_surface_detail() on hits of geometry whose material has either.
#pragma once

#include <penumbra/interaction.h>
#include <penumbra/texture.h>

#include "scene/normal_map.h"

#include <memory>

namespace penumbra {

struct SurfaceDetail {
  TexturedFloat displacement;                        // the bump map, when `bump`
  bool bump = false;
  std::shared_ptr<const NormalMapImage> normal_map;  // wins over the bump map when both are given (pbrt-v4)
  bool any() const { return bump || normal_map; }
};

/// A hit's shading geometry before detail is applied, as pbrt-v4 keeps it: the shading normal, its
/// dp/du and dp/dv (for a mesh with normals, dp/du made orthogonal to n and dp/dv = n x dp/du), and
/// the normal's derivatives (a sphere's; zero elsewhere).
struct ShadingGeometry {
  Vec3 n, dpdu, dpdv;
  Vec3 dndu{0.f}, dndv{0.f};
};

/// pbrt-v4's BumpMap: the displacement d is evaluated at the hit and at offsets du along u, dv along v
/// (du = (|du/dx| + |du/dy|) / 2 of the footprint, or 0.0005 when that is zero; the same for dv), and
/// the displaced surface p + d n gives dp/du + (d(u + du) - d(u)) / du n + d dn/du, and the same for v.
void bump_map(const TexturedFloat& displacement, const TextureEvalContext& ctx, const ShadingGeometry& g,
              Vec3* dpdu, Vec3* dpdv);

/// pbrt-v4's NormalMap: the map's RGB at (u, 1 - v), times 2 minus 1, normalised, is a normal in the
/// frame (x = dp/du normalised, z = n, y = z x x); returns dp/du made orthogonal to it (length kept)
/// and dp/dv = normal x dp/du (length |dp/dv|).
void normal_map(const NormalMapImage& map, Vec2 uv, const ShadingGeometry& g, Vec3* dpdu, Vec3* dpdv);

/// The shading frame of pbrt-v4's BSDF: s = dp/du made orthogonal to n, t = n x s; Frame(n) when dp/du
/// is (nearly) parallel to n or zero.
Frame tangent_frame(const Vec3& n, const Vec3& dpdu);

/// Replaces si.ns and si.shading by the bumped or normal-mapped ones: n = normalize(dpdu x dpdv) of
/// the new derivatives, flipped to si.ng's side, with the frame from the new dp/du.
void apply_surface_detail(const SurfaceDetail& detail, const ShadingGeometry& g, SurfaceInteraction& si);

}  // namespace penumbra
