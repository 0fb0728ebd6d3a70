#include "render/scene_warnings.h"

#include <penumbra/light.h>

#include <fmt/core.h>

#include <algorithm>

namespace penumbra {

std::vector<std::string> silent_result_warnings(const SceneDescription& desc, const BuiltScene& built) {
  std::vector<std::string> out;
  if (!desc.world_begin.filename)
    out.push_back(fmt::format("scene file '{}' has no WorldBegin: it describes no world, so the image is black",
                              desc.filename));
  bool infinite = std::any_of(built.lights.begin(), built.lights.end(),
                              [](const auto& l) { return l->type() == LightType::Infinite; });
  if (desc.shapes.empty() && !infinite)
    out.push_back(built.lights.empty() ? "nothing to render: the scene has no shapes and no light sources"
                                       : "nothing to render: the scene has no shapes, and its lights can only be "
                                         "seen on surfaces");
  else if (!desc.shapes.empty() && built.lights.empty())
    out.push_back("no light sources defined in the scene; rendering a black image");
  // A file without WorldBegin also has no shapes: one message says it.
  if (out.size() == 2 && !desc.world_begin.filename) out.pop_back();
  return out;
}

void report_silent_results(const std::vector<std::string>& warnings, bool strict) {
  for (const std::string& w : warnings) {
    if (strict) throw Error(fmt::format("{} (an error with --strict)", w));
    warning({}, w);
  }
}

}  // namespace penumbra
