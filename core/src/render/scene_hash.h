// A fingerprint of what a render computes, written into its EXR header so that `penumbra merge`
// can refuse parts of different scenes.
#pragma once

#include "parser/scene_description.h"

#include <string>

namespace penumbra {

/// 16 hex digits over the parsed description after command-line overrides (types, parameter
/// values, transforms, material and light bindings) and the bytes of every file a "filename"
/// parameter names (meshes, textures, environment maps). Left out: the Film's output filename and
/// AOV list, and file locations, so the same scene in another folder or machine hashes the same.
std::string scene_hash(const SceneDescription& desc);

}  // namespace penumbra
