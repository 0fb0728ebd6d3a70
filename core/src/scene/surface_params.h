// The scene file's side of bump maps, normal maps and alpha cut-outs: reading pbrt-v4's material
// parameters "displacement" (a float texture) and "normalmap" (an image file), which the core takes off
// the material's parameter list before its plugin sees it, and the shapes' "alpha" (a constant in
// [0, 1] or a float texture). Errors are located at the parameter.
#pragma once

#include <penumbra/params.h>

#include "scene/alpha_cutout.h"
#include "scene/surface_detail.h"

#include <string>

namespace penumbra {

class TextureTable;

/// Removes "displacement" and "normalmap" from `params` and returns what they ask for (file names
/// relative to `base_dir`).
SurfaceDetail take_surface_detail(ParamSet& params, const std::string& base_dir, const TextureTable& textures);

/// The shape's "alpha" (validated parameters: a float, or a texture name).
AlphaCutout shape_alpha(const ParamSet& params, const std::string& base_dir, const TextureTable& textures);

}  // namespace penumbra
