#include "commands.h"

#include "image/image_io.h"
#include "registry/registry.h"
#include "render/merge.h"

#include <fmt/core.h>

#include <csignal>
#include <cstdio>
#include <filesystem>

namespace fs = std::filesystem;

namespace penumbra::cli {

std::string default_scene() {
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  fs::path installed = exe.parent_path() / ".." / "share" / "penumbra" / "scenes" / "cornell-box" / "scene.pbrt";
  if (!ec && fs::exists(installed)) return installed.lexically_normal().string();
  return std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt";
}

int run_render(const RenderSettings& settings) {
  RenderResult result = render(settings);
  write_outputs(settings, result);
  const RenderStats& s = result.stats;
  std::fprintf(stderr, "wrote %s: %dx%d, %d spp, %.2f s, %.2f Mrays/s%s\n", s.output.c_str(),
               result.image.width, result.image.height, s.spp, s.seconds, s.mrays_per_second(),
               settings.stats_file.empty() ? "" : fmt::format(", stats in {}", settings.stats_file).c_str());
  if (result.interrupted_by) {
    std::fprintf(stderr, "interrupted (%s) after %d spp: the image holds what was done%s\n",
                 result.interrupted_by == SIGTERM ? "SIGTERM" : "SIGINT", s.spp,
                 result.checkpoint.empty()
                     ? ""
                     : fmt::format("; continue with the same command and --resume {}", result.checkpoint).c_str());
    return kExitInterrupted;
  }
  return 0;
}

int run_merge(const std::vector<std::string>& parts, const std::string& output) {
  if (fs::path(output).extension() != ".exr")
    throw Error(fmt::format("-o: merge writes a multilayer EXR: the output '{}' must end in .exr", output));
  if (std::string problem = image_output_problem(output); !problem.empty())
    throw Error(fmt::format("-o: {}", problem));
  MergeResult merged = merge_parts(parts);
  for (const auto& note : merged.notes) std::fprintf(stderr, "note: %s\n", note.c_str());
  write_layered_exr(output, merged.image);
  std::fprintf(stderr, "merged %zu parts (%d of %d samples per pixel) into %s\n", parts.size(), merged.samples,
               merged.spp_total, output.c_str());
  return 0;
}

int run_plugins(const std::vector<std::string>& dirs_in) {
  Registry registry(dirs_in.empty() ? Registry::default_search_dirs() : dirs_in);
  std::vector<std::string> errors;
  std::vector<LoadedPlugin> plugins = registry.load_all(&errors);
  std::printf("Plugin search path:\n");
  for (const auto& d : registry.search_dirs()) std::printf("  %s\n", d.c_str());
  for (PluginKind kind :
       {PluginKind::Integrator, PluginKind::Sampler, PluginKind::Bsdf, PluginKind::Light, PluginKind::Texture}) {
    for (const LoadedPlugin& p : plugins) {
      const PluginInfo& info = *p.info;
      if (info.kind != kind) continue;
      std::string aliases;
      for (const char* const* a = info.aliases; a && *a; ++a) aliases += fmt::format(" (alias '{}')", *a);
      std::printf("\n%s '%s'%s: %s\n  %s\n", plugin_kind_name(kind), info.name, aliases.c_str(), info.doc,
                  p.path.c_str());
      for (size_t i = 0; i < info.param_count; ++i) {
        const ParamSpec& s = info.params[i];
        if (std::string(s.type) == "unsupported") continue;
        std::string def = s.default_value && *s.default_value ? fmt::format(" = {}", s.default_value) : "";
        std::printf("    %-10s %-18s %-s%s\n", s.type, s.name, s.doc, def.empty() ? "" : fmt::format("  [default{}]", def).c_str());
      }
    }
  }
  for (const auto& e : errors) std::fprintf(stderr, "error: %s\n", e.c_str());
  return errors.empty() ? 0 : 1;
}

}  // namespace penumbra::cli
