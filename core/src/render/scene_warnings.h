// Scenes that would render a black image without anyone noticing: pbrt-v4's warnings, which
// `penumbra render --strict` turns into errors.
#pragma once

#include "parser/scene_description.h"
#include "scene/scene_builder.h"

#include <string>
#include <vector>

namespace penumbra {

/// Messages for a scene with no WorldBegin (pbrt-v4 refuses it), for one with nothing to render
/// (no shapes and no infinite light: every camera ray escapes into black) and for one with shapes
/// but no light source. Empty when none applies.
std::vector<std::string> silent_result_warnings(const SceneDescription& desc, const BuiltScene& built);

/// Prints each warning, or, when `strict`, throws the first as an Error saying --strict made it one.
void report_silent_results(const std::vector<std::string>& warnings, bool strict);

}  // namespace penumbra
