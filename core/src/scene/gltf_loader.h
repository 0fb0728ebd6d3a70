// glTF 2.0 meshes through tinygltf: every triangle primitive of the default scene's node tree, in
// the node transforms' space, with positions, normals, uvs and the metallic-roughness factors of its
// material (textures are ignored, with one warning).
#pragma once

#include <penumbra/color.h>
#include <penumbra/error.h>

#include <optional>
#include <string>
#include <vector>

namespace penumbra {

/// The pbrMetallicRoughness factors of a glTF material.
struct GltfMaterial {
  Rgb base_color{1.f};
  float metallic = 1.f;
  float roughness = 1.f;
  std::string name;
};

struct GltfPrimitive {
  std::vector<Vec3> P, N;      // already transformed by the node hierarchy
  std::vector<Vec2> uv;
  std::vector<int> indices;
  std::optional<GltfMaterial> material;  // empty when the primitive has none
};

/// Loads a .gltf or .glb file. Errors (missing file, broken buffers, unsupported primitive modes)
/// are located at `loc` and name the file.
std::vector<GltfPrimitive> load_gltf(const std::string& path, const FileLoc& loc);

}  // namespace penumbra
