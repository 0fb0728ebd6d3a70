// Loop subdivision surfaces (pbrt-v4's Shape "loopsubdiv"): the control mesh is refined `levels`
// times with Loop's rules (boundary edges and vertices by the cubic B-spline boundary rules), then
// every vertex is moved to its limit position and given the limit surface's normal.
#pragma once

#include <penumbra/error.h>
#include <penumbra/math.h>

#include <vector>

namespace penumbra {

struct LoopSurface {
  std::vector<Vec3> P;  // limit positions
  std::vector<Vec3> N;  // unit limit normals, on the side the triangles' winding faces
  std::vector<int> indices;
};

/// Subdivides the triangle mesh (P, indices) `levels` times and returns the limit mesh.
/// Throws located errors for a bad index count, an out-of-range index or too many levels.
LoopSurface loop_subdivide(const std::vector<Vec3>& P, const std::vector<int>& indices, int levels,
                           const FileLoc& indices_loc, const FileLoc& levels_loc);

}  // namespace penumbra
