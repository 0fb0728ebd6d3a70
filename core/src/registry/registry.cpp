#include "registry/registry.h"

#include "registry/elf_check.h"

#include <fmt/core.h>

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <set>

namespace fs = std::filesystem;

namespace penumbra {

const char* plugin_kind_name(PluginKind kind) {
  switch (kind) {
    case PluginKind::Integrator: return "integrator";
    case PluginKind::Sampler: return "sampler";
    case PluginKind::Bsdf: return "bsdf";
    case PluginKind::Light: return "light";
    case PluginKind::Texture: return "texture";
  }
  return "unknown";
}

// Folders are made absolute once, so a plugin path always names its folder and dlopen() never
// searches the library path or depends on a later change of the current folder.
Registry::Registry(std::vector<std::string> dirs) {
  for (const std::string& d : dirs) {
    std::error_code ec;
    fs::path abs = fs::absolute(d, ec);
    dirs_.push_back(ec ? d : abs.lexically_normal().string());
  }
}

std::vector<std::string> Registry::default_search_dirs() {
  std::vector<std::string> dirs;
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) dirs.push_back((exe.parent_path() / ".." / "lib" / "penumbra" / "plugins").lexically_normal());
  if (const char* env = std::getenv("PENUMBRA_PLUGIN_PATH")) {
    std::string s(env);
    size_t start = 0;
    while (start <= s.size()) {
      size_t end = s.find(':', start);
      if (end == std::string::npos) end = s.size();
      std::string dir = s.substr(start, end - start);
      // Empty entries are skipped (not "the current folder", as in $PATH), and relative ones too:
      // they would load whatever plugin the folder a render happens to start in holds.
      if (!dir.empty() && fs::path(dir).is_relative()) {
        static bool warned = false;
        if (!warned)
          warning({}, fmt::format("$PENUMBRA_PLUGIN_PATH entry '{}' is not an absolute path and is ignored", dir));
        warned = true;
      } else if (!dir.empty()) {
        dirs.push_back(dir);
      }
      start = end + 1;
    }
  }
  return dirs;
}

static std::string file_name(PluginKind kind, const std::string& name) {
  return fmt::format("penumbra-{}-{}.so", plugin_kind_name(kind), name);
}

std::string Registry::find_file(PluginKind kind, const std::string& name) const {
  for (const auto& dir : dirs_) {
    fs::path p = fs::path(dir) / file_name(kind, name);
    std::error_code ec;
    if (fs::exists(p, ec)) return p.string();
  }
  return "";
}

std::vector<std::string> Registry::available(PluginKind kind) const {
  std::set<std::string> names;
  std::string prefix = fmt::format("penumbra-{}-", plugin_kind_name(kind));
  for (const auto& dir : dirs_) {
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
      std::string f = entry.path().filename().string();
      if (f.rfind(prefix, 0) == 0 && f.size() > prefix.size() + 3 &&
          f.compare(f.size() - 3, 3, ".so") == 0)
        names.insert(f.substr(prefix.size(), f.size() - prefix.size() - 3));
    }
  }
  return {names.begin(), names.end()};
}

const LoadedPlugin& Registry::open(const std::string& path, const FileLoc& loc) {
  std::error_code ec;
  std::string key = fs::weakly_canonical(path, ec).string();
  if (auto it = by_path_.find(key); it != by_path_.end()) return it->second;

  // A truncated or corrupt file would crash the dynamic loader (SIGBUS): its headers are checked first.
  if (std::string problem = elf_file_problem(path); !problem.empty())
    throw Error(loc, fmt::format("plugin {} cannot be loaded: {}; rebuild or reinstall it", path, problem));
  // Libraries stay open for the life of the process: objects they created may outlive the registry.
  void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) throw Error(loc, fmt::format("cannot open plugin {}: {}", path, dlerror()));
  auto entry = reinterpret_cast<const PluginInfo* (*)()>(dlsym(handle, "penumbra_plugin_info"));
  if (!entry)
    throw Error(loc, fmt::format("{} is not a Penumbra plugin: it exports no penumbra_plugin_info()", path));
  const PluginInfo* info = entry();
  // Only the first field is read before the version check: the rest may be laid out differently.
  if (!info || info->sdk_version != PENUMBRA_SDK_VERSION)
    throw Error(loc, fmt::format("plugin {} was built for Penumbra SDK version {}, but this runtime "
                                 "has SDK version {}; rebuild the plugin against this SDK",
                                 path, info ? info->sdk_version : 0u, PENUMBRA_SDK_VERSION));
  // Same layout from here on, but objects crossing the boundary need the same C++ ABI as well.
  std::string compiler = info->compiler ? info->compiler : "unknown";
  if (compiler != PENUMBRA_COMPILER_ID)
    throw Error(loc, fmt::format("plugin {} was built with compiler '{}', but this runtime was built "
                                 "with '{}' (both SDK version {}); rebuild the plugin with the "
                                 "runtime's compiler",
                                 path, compiler, PENUMBRA_COMPILER_ID, PENUMBRA_SDK_VERSION));
  return by_path_.emplace(key, LoadedPlugin{info, path}).first->second;
}

const LoadedPlugin& Registry::load(PluginKind kind, const std::string& name, const FileLoc& loc) {
  std::string path = find_file(kind, name);
  if (path.empty()) {
    std::string list;
    for (const auto& n : available(kind)) list += (list.empty() ? "" : ", ") + n;
    throw Error(loc, fmt::format("unknown {} '{}'; available: {}", plugin_kind_name(kind), name,
                                 list.empty() ? "none (is the plugin folder missing?)" : list));
  }
  const LoadedPlugin& plugin = open(path, loc);
  if (plugin.info->kind != kind)
    throw Error(loc, fmt::format("plugin {} is a {}, not a {}", path,
                                 plugin_kind_name(plugin.info->kind), plugin_kind_name(kind)));
  std::string id = fmt::format("{}/{}", plugin_kind_name(kind), plugin.info->name);
  if (std::find(loaded_names_.begin(), loaded_names_.end(), id) == loaded_names_.end())
    loaded_names_.push_back(id);
  return plugin;
}

Object* Registry::create_object(const LoadedPlugin& plugin, ParamSet& params, CreateContext ctx,
                                const FileLoc& loc) {
  const PluginInfo& info = *plugin.info;
  params.validate({info.params, info.param_count},
                  fmt::format("{} '{}'", plugin_kind_name(info.kind), info.name));
  // The caller's context with the validated parameters and the location (every other field copied).
  CreateContext full{params, loc, ctx.scene_dir, ctx.to_world, ctx.shape};
  full.shape_area = ctx.shape_area;
  full.reverse_orientation = ctx.reverse_orientation;
  full.textures = ctx.textures;
  full.spectrum_texture = ctx.spectrum_texture;
  full.spectral = ctx.spectral;
  Object* obj = info.create(full);
  if (!obj) throw Error(loc, fmt::format("{} '{}' could not be created", plugin_kind_name(info.kind), info.name));
  return obj;
}

std::vector<LoadedPlugin> Registry::load_all(std::vector<std::string>* errors) {
  std::vector<LoadedPlugin> out;
  std::set<std::string> seen;
  for (const auto& dir : dirs_) {
    std::error_code ec;
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(dir, ec)) files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
      std::string name = f.filename().string();
      if (name.rfind("penumbra-", 0) != 0 || f.extension() != ".so") continue;
      std::string canon = fs::weakly_canonical(f, ec).string();
      if (!seen.insert(canon).second) continue;  // aliases are links to a plugin already listed
      try {
        out.push_back(open(f.string(), {}));
      } catch (const Error& e) {
        if (errors) errors->push_back(e.what());
      }
    }
  }
  return out;
}

}  // namespace penumbra
