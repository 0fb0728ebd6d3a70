// libFuzzer target for the glTF loader: any .glb or .gltf must either load as valid primitives
// (indices in range, attribute counts matching) or raise penumbra::Error naming the file. The
// first input byte picks the container (binary .glb or text .gltf). Built and run by scripts/fuzz.sh.
#include "fuzz/file_fuzzer.h"
#include "scene/gltf_loader.h"

#include <penumbra/error.h>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  std::string path = penumbra::fuzz::write_input(data + 1, size - 1, (data[0] & 1) ? ".glb" : ".gltf");
  try {
    for (const penumbra::GltfPrimitive& p : penumbra::load_gltf(path, penumbra::FileLoc{})) {
      if (p.indices.size() % 3 != 0) __builtin_trap();
      for (int i : p.indices)
        if (i < 0 || static_cast<size_t>(i) >= p.P.size()) __builtin_trap();
      if (!p.N.empty() && p.N.size() != p.P.size()) __builtin_trap();
      if (!p.uv.empty() && p.uv.size() != p.P.size()) __builtin_trap();
    }
  } catch (const penumbra::Error& e) {
    if (std::string(e.what()).find(path) == std::string::npos) __builtin_trap();
  }
  return 0;
}
