// pbrt-v4's "curve" shape: thin strands (hair, fur, grass) as cubic Bezier segments traced by Embree's
// native curve primitives (EmbreeScene::add_curves).
//
// pbrt-v4 turns every curve into cubic Bezier segments: degree-2 segments are elevated, B-splines are
// converted segment by segment; so does this, and Embree's Bezier curves get the result. The width
// varies linearly from width0 to width1 along the whole curve (over u in [0, 1], segment i covering
// [i/n, (i+1)/n]); the control radii are half the width at the control points' u, which a Bezier
// interpolates exactly because the width is linear in u. The three types, as pbrt-v4 defines them:
//   flat      a ribbon that always faces the ray (Embree's flat curves); normal towards the ray
//   cylinder  the same ray-facing ribbon with its normal turned by -90 to 90 degrees across its
//             width, so it shades like a tube (pbrt-v4 does the same rather than trace a tube; as
//             there, geometric and shading normal turn together, and in pbrt-v4's sense: on the
//             side facing the ray towards the far edge, docs/hair.md)
//   ribbon    a band oriented by the normals "N" given at the segment ends (slerped between them;
//             Embree's normal-oriented curves)
// Embree draws a flat segment as ray-facing quads (16 per segment here, its most); on a strand bent
// strongly within each segment the image mean is within 0.3 % of pbrt-v4's exact ribbon
// (tests/curves_test.cpp). pbrt-v4's "splitdepth" (its intersector's refinement) is accepted and unused.
// uv as pbrt-v4: u along the whole curve, v across the width in [0, 1]. The hit's error bound is the
// strand's width at the hit, as pbrt-v4's, so spawned rays leave the ribbon.
//
// Widths are given in object space; under a transform that scales unevenly they are scaled by the
// cube root of the determinant (a strand's cross-section has no preferred axis).
#pragma once

#include <penumbra/interaction.h>
#include <penumbra/math.h>

#include <vector>

namespace penumbra {

struct ShapeEntity;

enum class CurveType { Flat, Cylinder, Ribbon };

class Curves {
 public:
  CurveType type = CurveType::Flat;
  /// Four world-space control points per segment (x, y, z, radius).
  std::vector<Vec4> control;
  /// Ribbons only: four control normals per segment (slerped from the segment's end normals).
  std::vector<Vec3> normals;
  /// The u range of each segment along the whole curve.
  std::vector<Vec2> u_range;

  size_t segment_count() const { return u_range.size(); }
  /// Centre line and its derivative by the segment's own parameter t in [0, 1].
  Vec3 center(size_t segment, float t) const;
  Vec3 derivative(size_t segment, float t) const;
  /// Strand width (twice the radius) at the segment's parameter t.
  float width(size_t segment, float t) const;

  /// The hit on segment `segment` at its parameter t and Embree's cross coordinate v (-1..1 for flat
  /// curves, 0..1 for ribbons), for a ray with direction d that reached p; `embree_ng` is Embree's
  /// (unnormalised) geometric normal, used by ribbons.
  struct Surface {
    Vec3 p, p_error, ng, ns, dpdu, dpdv;
    Vec2 uv;
  };
  Surface surface(size_t segment, float t, float v, const Vec3& p, const Vec3& d, const Vec3& embree_ng) const;
};

/// Reads pbrt-v4's curve parameters (P, basis, degree, type, N, width, width0, width1, splitdepth)
/// into world-space Bezier segments; every inconsistency is an error at the parameter's location.
Curves load_curves(ShapeEntity& e);

}  // namespace penumbra
