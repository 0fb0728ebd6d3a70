// Finds plugin libraries by file name and loads them on demand (dlopen). A plugin is opened only
// when a scene names it; `penumbra plugins` is the one place that opens them all.
#pragma once

#include <penumbra/error.h>
#include <penumbra/plugin.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace penumbra {

/// A plugin that was opened and accepted.
struct LoadedPlugin {
  const PluginInfo* info = nullptr;
  std::string path;
};

class Registry {
 public:
  /// Searches `dirs` in order (the first file found for a name wins).
  explicit Registry(std::vector<std::string> dirs);
  /// The folder next to the executable (../lib/penumbra/plugins), then $PENUMBRA_PLUGIN_PATH.
  static std::vector<std::string> default_search_dirs();

  /// Loads the plugin of `kind` called `name` (or an alias of it). Throws Error at `loc` if there is
  /// none (listing the available ones) or if the file is unusable (wrong SDK version, no entry point).
  const LoadedPlugin& load(PluginKind kind, const std::string& name, const FileLoc& loc = {});

  /// Validates `params` against the plugin's table, then runs its factory. The object is checked to
  /// be of the expected kind.
  template <typename T>
  std::unique_ptr<T> create(PluginKind kind, const std::string& name, ParamSet& params,
                            CreateContext ctx_template, const FileLoc& loc);

  /// Names (canonical and alias file names) of the plugins of a kind found on the search path.
  std::vector<std::string> available(PluginKind kind) const;
  /// Opens every plugin on the search path. Files that cannot be used are reported in `errors`.
  std::vector<LoadedPlugin> load_all(std::vector<std::string>* errors);
  /// "kind/name" of every plugin loaded so far, in load order.
  const std::vector<std::string>& loaded() const { return loaded_names_; }
  const std::vector<std::string>& search_dirs() const { return dirs_; }

 private:
  Object* create_object(const LoadedPlugin& plugin, ParamSet& params, CreateContext ctx,
                        const FileLoc& loc);
  std::string find_file(PluginKind kind, const std::string& name) const;
  const LoadedPlugin& open(const std::string& path, const FileLoc& loc);

  std::vector<std::string> dirs_;
  std::map<std::string, LoadedPlugin> by_path_;  // canonical path -> plugin
  std::vector<std::string> loaded_names_;
};

/// Thrown-away objects whose kind does not match are a programming error in the plugin.
template <typename T>
std::unique_ptr<T> Registry::create(PluginKind kind, const std::string& name, ParamSet& params,
                                    CreateContext ctx_template, const FileLoc& loc) {
  const LoadedPlugin& plugin = load(kind, name, loc);
  Object* obj = create_object(plugin, params, ctx_template, loc);
  T* typed = dynamic_cast<T*>(obj);
  if (!typed) {
    delete obj;
    throw Error(loc, "plugin '" + std::string(plugin.info->name) + "' (" + plugin.path +
                         ") created an object that is not a " + plugin_kind_name(kind));
  }
  return std::unique_ptr<T>(typed);
}

}  // namespace penumbra
