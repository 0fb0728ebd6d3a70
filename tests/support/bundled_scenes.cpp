#include "support/bundled_scenes.h"

#include "support/command.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace penumbra::test {

std::string cornell_box_copy(const std::string& name, const std::string& integrator_line, bool box_filter) {
  const std::string src = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/";
  std::string text = read_file(src + "scene.pbrt");
  if (box_filter) {
    const std::string gaussian = "PixelFilter \"gaussian\"";
    size_t at = text.find(gaussian);
    if (at == std::string::npos)
      throw std::runtime_error("cornell_box_copy: scenes/cornell-box/scene.pbrt has no '" + gaussian + "' to replace");
    text.replace(at, gaussian.size(), "PixelFilter \"box\"");
  }
  if (!integrator_line.empty()) {
    size_t at = text.find("\nIntegrator ");
    if (at == std::string::npos)
      throw std::runtime_error("cornell_box_copy: scenes/cornell-box/scene.pbrt has no Integrator line to replace");
    size_t end = text.find('\n', at + 1);
    text.replace(at + 1, end - at - 1, integrator_line);
  }
  std::string dir = temp_dir(name);
  write_file(dir, "unit-cube.pbrt", read_file(src + "unit-cube.pbrt"));
  return write_file(dir, "scene.pbrt", text);
}

namespace {
bool is_whole_scene(const std::string& file) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    size_t start = line.find_first_not_of(" \t");
    if (start != std::string::npos && line.compare(start, 10, "WorldBegin") == 0) return true;
  }
  return false;
}
}  // namespace

std::vector<std::string> bundled_scene_files() {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(std::string(PENUMBRA_SOURCE_DIR) + "/scenes"))
    if (entry.path().extension() == ".pbrt" && is_whole_scene(entry.path().string())) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace penumbra::test
