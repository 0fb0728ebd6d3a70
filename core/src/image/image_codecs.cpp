#include "image/image_codecs.h"

#include "util/input_file.h"
#include "util/output_file.h"

#include <penumbra/error.h>

#include <fmt/core.h>

#include <dlfcn.h>

#include <filesystem>

// Weak: a program that links the codecs in (the image fuzzer) has it; the shared core does not, and
// opens the library instead.
extern "C" const penumbra::ImageCodecs* penumbra_image_codecs() __attribute__((weak));

namespace penumbra {

namespace {

// The library sits in the core library's own folder (build and install trees alike), so it is found
// from wherever the core was loaded, whatever program loaded it.
std::string codec_library_path() {
  Dl_info info{};
  if (!dladdr(reinterpret_cast<const void*>(&codec_library_path), &info) || !info.dli_fname)
    throw Error("cannot find the folder of libpenumbra-core to load the image library from");
  std::error_code ec;
  std::filesystem::path core = std::filesystem::absolute(info.dli_fname, ec);
  return (core.parent_path() / kImageCodecsLibrary).lexically_normal().string();
}

const ImageCodecs* load_codecs() {
  const ImageCodecs* codecs = nullptr;
  std::string where;
  if (penumbra_image_codecs) {
    codecs = penumbra_image_codecs();
    where = "this program";
  } else {
    where = codec_library_path();
    // Never closed: the codecs keep OpenImageIO's state (format plugins, caches) for the process.
    void* handle = dlopen(where.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) throw Error(fmt::format("cannot load Penumbra's image library: {}", dlerror()));
    auto entry = reinterpret_cast<const ImageCodecs* (*)()>(dlsym(handle, kImageCodecsSymbol));
    if (!entry) throw Error(fmt::format("image library '{}' does not export {}", where, kImageCodecsSymbol));
    codecs = entry();
  }
  if (!codecs || codecs->version != kImageCodecsVersion)
    throw Error(fmt::format("image library '{}' is version {}, this core needs {}: reinstall Penumbra", where,
                            codecs ? codecs->version : 0, kImageCodecsVersion));
  return codecs;
}

// Loaded once per process, on first use; a failed load throws (naming the image `doing` is about)
// and the next call tries again.
const ImageCodecs& codecs(const std::string& doing) {
  try {
    static const ImageCodecs* loaded = load_codecs();
    return *loaded;
  } catch (const Error& e) {
    throw Error(fmt::format("{}: {}", doing, e.what()));
  }
}

}  // namespace

std::string image_codecs_problem() {
  if (penumbra_image_codecs) return "";
  try {
    std::string path = codec_library_path();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
      return fmt::format("Penumbra's image library '{}' is missing: reinstall Penumbra", path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

void write_raster(const std::string& path, const RasterToWrite& raster) {
  const ImageCodecs& c = codecs(fmt::format("cannot write image '{}'", path));
  write_atomically(path, [&](const std::string& temporary) { c.write(path, temporary, raster); });
}

RasterRead read_raster(const std::string& path, int max_channels) {
  if (std::string problem = input_file_problem(path); !problem.empty())
    throw Error(fmt::format("cannot read image '{}': {}", path, problem));
  return codecs(fmt::format("cannot read image '{}'", path)).read(path, max_channels);
}

}  // namespace penumbra
