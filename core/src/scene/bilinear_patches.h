// pbrt-v4's Shape "bilinearmesh" as triangles: each patch p(u, v) = (1-u)(1-v) p00 + u(1-v) p10 +
// (1-u) v p01 + u v p11 is tessellated into an n x n grid of (u, v) cells, two triangles each,
// with uv and N interpolated bilinearly from the corners.
//
// On a cell of side h = 1/n the triangles differ from the patch at the same (u, v) by at most
// |p00 - p10 - p01 + p11| h^2 / 4 (the bilinear term's error under linear interpolation), so
// that bounds the distance to the exact surface. n is the smallest grid whose bound is at most
// kBilinearTolerance times the patch's longer diagonal: parallelograms (and so every rectangle)
// take n = 1, two triangles, which are exact in position, uv and N.
#pragma once

#include <penumbra/error.h>
#include <penumbra/math.h>

#include <vector>

namespace penumbra {

inline constexpr float kBilinearTolerance = 2.5e-4f;

/// Cells per side for the patch with these corners (1 to 64).
int bilinear_grid_size(const Vec3& p00, const Vec3& p10, const Vec3& p01, const Vec3& p11);
/// The bound on the distance between an n x n tessellation and the patch.
float bilinear_deviation_bound(const Vec3& p00, const Vec3& p10, const Vec3& p01, const Vec3& p11, int n);

struct TessellatedPatches {
  std::vector<Vec3> P, N;  // N empty unless given
  std::vector<Vec2> uv;    // always: the given uv, else (0,0) (1,0) (0,1) (1,1) at p00 p10 p01 p11
  std::vector<int> indices;
};

/// Tessellates the patches (four indices each, p00 p10 p01 p11; empty indices with four points
/// mean one patch, as in pbrt-v4). Throws located errors for bad counts and indices.
TessellatedPatches tessellate_bilinear_patches(const std::vector<Vec3>& P, const std::vector<int>& indices,
                                               const std::vector<Vec2>& uv, const std::vector<Vec3>& N,
                                               const FileLoc& shape_loc, const FileLoc& indices_loc,
                                               const FileLoc& uv_loc, const FileLoc& n_loc);

}  // namespace penumbra
