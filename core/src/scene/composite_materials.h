// The two pbrt-v4 materials the core builds itself, because they are made of other materials or of
// none: "mix" (two named materials chosen by amount: scene/mix_bsdf.h) and "interface" (no surface:
// rays pass through, since Penumbra has no participating media for it to bound).
#pragma once

#include <penumbra/bsdf.h>

#include <memory>
#include <string>
#include <vector>

#include "parser/scene_description.h"

namespace penumbra {

/// Whether material type `type` is built by build_composite_materials() rather than a plugin.
bool is_composite_material(const std::string& type);

/// Fills the slots of `bsdfs` (one per desc.materials, nullptr for the composite ones) for every
/// "mix" material; "interface" slots stay nullptr. Throws Error at the material or its parameter:
/// unknown or undefined names, not exactly two materials, amount outside [0, 1], cycles of mixes.
void build_composite_materials(const SceneDescription& desc, std::vector<std::unique_ptr<Bsdf>>& bsdfs);

}  // namespace penumbra
