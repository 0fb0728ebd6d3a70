// Building small scenes from text to see the errors they give.
#pragma once

#include <string>

namespace penumbra::test {

/// Parses "WorldBegin\n" + `world` as the file `file_name` and builds it with the default plugin
/// folders; returns Error::formatted() of what parsing or building throws, or "" when it builds.
std::string scene_build_error(const std::string& world, const std::string& file_name = "scene.pbrt");

}  // namespace penumbra::test
