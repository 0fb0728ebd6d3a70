// libFuzzer target for the PLY reader (plymesh): any file must either load as a valid mesh (indices
// in range, one normal and uv per position when present) or raise penumbra::Error naming the file;
// a crash, hang, out-of-memory or sanitizer report is a bug. Built and run by scripts/fuzz.sh.
#include "fuzz/file_fuzzer.h"
#include "parser/ply_reader.h"

#include <penumbra/error.h>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string path = penumbra::fuzz::write_input(data, size, ".ply");
  try {
    penumbra::TriangleMeshData m = penumbra::read_ply(path, penumbra::FileLoc{});
    if (m.indices.size() % 3 != 0) __builtin_trap();
    for (int i : m.indices)
      if (i < 0 || static_cast<size_t>(i) >= m.P.size()) __builtin_trap();
    if (!m.N.empty() && m.N.size() != m.P.size()) __builtin_trap();
    if (!m.uv.empty() && m.uv.size() != m.P.size()) __builtin_trap();
  } catch (const penumbra::Error& e) {
    if (std::string(e.what()).find(path) == std::string::npos) __builtin_trap();  // names the file
  }
  return 0;
}
