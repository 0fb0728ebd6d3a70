// A plugin as SDK version 1 laid it out (no compiler field after the version), written by hand: the
// loader must refuse it on the version without reading the fields that moved.
#include <cstddef>
#include <cstdint>

namespace {
struct PluginInfoV1 {
  uint32_t sdk_version;
  uint32_t kind;
  const char* name;
  const char* const* aliases;
  const char* doc;
  const void* params;
  size_t param_count;
  void* create;
};
const PluginInfoV1 kInfo{1, 0, "oldsdk", nullptr, "built for SDK version 1", nullptr, 0, nullptr};
}  // namespace

extern "C" __attribute__((visibility("default"))) const void* penumbra_plugin_info() { return &kInfo; }
