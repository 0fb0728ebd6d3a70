// Triangle meshes from PLY files, for pbrt's "plymesh" shape.
#pragma once

#include <penumbra/error.h>
#include <penumbra/math.h>

#include <string>
#include <vector>

namespace penumbra {

/// An indexed triangle mesh. N and uv are empty when the file has no normals or texture
/// coordinates; otherwise they have one entry per position.
struct TriangleMeshData {
  std::vector<Vec3> P, N;
  std::vector<Vec2> uv;
  std::vector<int> indices;  // three per triangle
};

/// Reads an ascii or binary PLY file: vertex positions (x y z), optional normals (nx ny nz) and
/// texture coordinates (u v, s t or texture_u texture_v), and polygonal faces, which are split into
/// triangles (quads along their 0-2 diagonal). Other elements and properties are skipped. Errors
/// name the file and are located at `loc` (the scene parameter that names the file).
TriangleMeshData read_ply(const std::string& path, const FileLoc& loc);

}  // namespace penumbra
