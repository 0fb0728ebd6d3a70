#include "support/scene_errors.h"

#include "parser/scene_description.h"
#include "registry/registry.h"
#include "scene/scene_builder.h"

namespace penumbra::test {

std::string scene_build_error(const std::string& world, const std::string& file_name) {
  Registry registry(Registry::default_search_dirs());
  try {
    SceneDescription d = parse_scene_string("WorldBegin\n" + world, file_name);
    build_scene(d, registry);
  } catch (const Error& e) {
    return e.formatted();
  }
  return "";
}

}  // namespace penumbra::test
