// libFuzzer target for the scene parser: any input must either parse or raise penumbra::Error with a
// message; a crash, a hang, an out-of-memory, a sanitizer report or any other exception is a bug.
// Built and run by scripts/fuzz.sh (clang, -fsanitize=fuzzer,address,undefined).
#include "parser/scene_description.h"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  try {
    penumbra::SceneDescription d = penumbra::parse_scene_string(text, "fuzz.pbrt");
    // Exercise the parameter sets the parser produced.
    for (const auto& shape : d.shapes)
      for (const auto& p : shape.params.params()) (void)shape.params.loc_of(p.name);
  } catch (const penumbra::Error& e) {
    if (e.formatted().empty()) __builtin_trap();  // every error says something
  }
  return 0;
}
