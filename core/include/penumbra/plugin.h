// The plugin contract. A plugin is a shared library `penumbra-<kind>-<name>.so` exporting one C
// function, penumbra_plugin_info(), that describes it: the SDK version and compiler it was built
// with, its kind, name and aliases, a one-line description, its parameter table and a factory.
// Write it with the PENUMBRA_PLUGIN macro:
//
//   static const penumbra::ParamSpec kParams[] = {
//       {"integer", "maxdepth", "5", "longest path, in bounces"}};
//   static penumbra::Object* create(const penumbra::CreateContext& ctx) { return new MyPath(ctx); }
//   PENUMBRA_PLUGIN(Integrator, "mypath", "My path tracer", kParams, create)
#pragma once

#include <penumbra/error.h>
#include <penumbra/math.h>
#include <penumbra/object.h>
#include <penumbra/params.h>
#include <penumbra/shape.h>
#include <penumbra/texture.h>
#include <penumbra/version.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>

namespace penumbra {

enum class PluginKind : uint32_t { Integrator = 0, Sampler = 1, Bsdf = 2, Light = 3, Texture = 4 };

/// "integrator", "sampler", "bsdf", "light" or "texture".
const char* plugin_kind_name(PluginKind kind);

class TextureTable;  // the scene's named textures (the core fills it; factories read it through inputs)

/// Everything a factory gets. Parameters have been validated against the plugin's table.
struct CreateContext {
  const ParamSet& params;
  FileLoc loc;                    // where the scene names the plugin
  std::string scene_dir;          // folder of the scene file, for relative file names
  Mat4 to_world{1.f};             // transform in effect at the directive (lights)
  const Shape* shape = nullptr;   // area lights: the primitive they are attached to
  float shape_area = 0.f;         // area lights: the area of the whole shape (all of a mesh's
                                  // triangles), for pbrt-v4's "power"
  bool reverse_orientation = false;
  const TextureTable* textures = nullptr;  // named textures defined so far (materials, textures)
  bool spectrum_texture = false;  // texture plugins: the directive asked for "spectrum" (else "float")
  bool spectral = false;          // the render is spectral (penumbra/spectrum.h): materials evaluate
                                  // their colours per hit (TexturedRgb::evaluate), constants included

  /// A texturable parameter: the named texture for `"texture NAME" "tex"`, else the float value
  /// (or the table's default). An undefined texture, or a spectrum texture where a float one is
  /// needed, is an error at the parameter.
  TexturedFloat float_input(const std::string& name) const;
  /// Same for colours: an "rgb"/"spectrum" value or a spectrum texture, of the given kind.
  TexturedRgb rgb_input(const std::string& name, RgbKind kind = RgbKind::Albedo) const;
  /// float_input() or rgb_input() by the value type T (float or Rgb).
  template <typename T>
  typename TextureOf<T>::Input input(const std::string& name) const {
    if constexpr (std::is_same_v<T, float>) return float_input(name);
    else return rgb_input(name);
  }
};

using PluginFactory = Object* (*)(const CreateContext& ctx);

/// The first two fields keep their layout in every SDK version, so that the loader can read them
/// from a plugin built for another version or compiler and refuse it; it reads nothing else until
/// both match. (SDK version 1 had no compiler field: such plugins are refused on the version.)
struct PluginInfo {
  uint32_t sdk_version;
  const char* compiler;  // PENUMBRA_COMPILER_ID of the plugin's build
  PluginKind kind;
  const char* name;
  const char* const* aliases;  // null-terminated list, may be null
  const char* doc;
  const ParamSpec* params;
  size_t param_count;
  PluginFactory create;
};

}  // namespace penumbra

#define PENUMBRA_PLUGIN_ENTRY penumbra_plugin_info

#define PENUMBRA_PLUGIN_WITH_ALIASES(KIND, NAME, DOC, PARAMS, FACTORY, ALIASES)                 \
  extern "C" __attribute__((visibility("default"))) const ::penumbra::PluginInfo*               \
  penumbra_plugin_info() {                                                                     \
    static const ::penumbra::PluginInfo info{PENUMBRA_SDK_VERSION, PENUMBRA_COMPILER_ID,          \
                                             ::penumbra::PluginKind::KIND, NAME, ALIASES, DOC,  \
                                             PARAMS, sizeof(PARAMS) / sizeof(PARAMS[0]),        \
                                             FACTORY};                                          \
    return &info;                                                                              \
  }

#define PENUMBRA_PLUGIN(KIND, NAME, DOC, PARAMS, FACTORY) \
  PENUMBRA_PLUGIN_WITH_ALIASES(KIND, NAME, DOC, PARAMS, FACTORY, nullptr)
