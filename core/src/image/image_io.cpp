#include "image/image_io.h"

#include "image/image_codecs.h"

#include "util/output_file.h"

#include <penumbra/error.h>

#include <OpenColorIO/OpenColorIO.h>
#include <fmt/core.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>

namespace penumbra {

namespace OCIO = OCIO_NAMESPACE;
namespace fs = std::filesystem;

namespace {

enum class Encoding { Linear, Display };

struct FormatInfo {
  const char* extension;
  Encoding encoding;
};

constexpr FormatInfo kFormats[] = {{".exr", Encoding::Linear},  {".hdr", Encoding::Linear},
                                   {".tif", Encoding::Linear},  {".tiff", Encoding::Linear},
                                   {".pfm", Encoding::Linear},  {".png", Encoding::Display},
                                   {".jpg", Encoding::Display}, {".jpeg", Encoding::Display}};

std::string supported_extensions() {
  std::string list;
  for (const auto& f : kFormats) list += (list.empty() ? "" : ", ") + std::string(f.extension);
  return list;
}

const FormatInfo& format_of(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  for (const auto& f : kFormats)
    if (ext == f.extension) return f;
  if (ext.empty())
    throw Error(fmt::format("cannot write image '{}': it has no extension to choose the format by (supported: {})",
                            path, supported_extensions()));
  throw Error(fmt::format("cannot write image '{}': unknown extension '{}' (supported: {})", path, ext,
                          supported_extensions()));
}

// ---- OpenColorIO ---------------------------------------------------------------------------------

std::string shipped_ocio_config() {
  std::vector<fs::path> candidates;
  std::error_code ec;
  // Installed layout: bin/penumbra next to share/penumbra/ocio/config.ocio.
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back(exe.parent_path() / ".." / "share" / "penumbra" / "ocio" / "config.ocio");
#ifdef PENUMBRA_SOURCE_DIR
  // Build trees run without installing: fall back to the source tree's copy.
  candidates.push_back(fs::path(PENUMBRA_SOURCE_DIR) / "data" / "ocio" / "config.ocio");
#endif
  std::string tried;
  for (const auto& c : candidates) {
    if (fs::is_regular_file(c, ec)) return c.lexically_normal().string();
    tried += (tried.empty() ? "" : ", ") + c.lexically_normal().string();
  }
  throw Error(fmt::format("cannot find Penumbra's OpenColorIO config (looked in: {}); set $OCIO to a "
                          "config file",
                          tried));
}

OCIO::ConstConfigRcPtr load_config(const std::string& path, bool from_env) {
  std::string origin = from_env ? " (named by $OCIO)" : "";
  try {
    OCIO::ConstConfigRcPtr config =
        from_env ? OCIO::Config::CreateFromEnv() : OCIO::Config::CreateFromFile(path.c_str());
    config->validate();
    return config;
  } catch (const OCIO::Exception& e) {
    throw Error(fmt::format("OpenColorIO config '{}'{} is unusable: {}", path, origin, e.what()));
  }
}

OCIO::ConstConfigRcPtr current_config() {
  const char* env = std::getenv("OCIO");
  if (env && *env) return load_config(env, true);
  return load_config(shipped_ocio_config(), false);
}

// Scene-linear pixels to 8-bit display code values through the config's default display.
std::vector<uint8_t> encode_for_display(const std::string& path, const ImageRgb& img, const std::string& view) {
  OCIO::ConstConfigRcPtr config;
  try {
    config = current_config();
  } catch (const Error& e) {
    throw Error(fmt::format("cannot write image '{}': {}", path, e.what()));
  }
  std::vector<float> buffer = img.pixels;
  try {
    const char* display = config->getDefaultDisplay();
    std::string chosen = view.empty() ? config->getDefaultView(display) : view;
    std::string views;
    bool known = false;
    for (int i = 0; i < config->getNumViews(display); ++i) {
      std::string v = config->getView(display, i);
      known = known || v == chosen;
      views += (views.empty() ? "" : ", ") + v;
    }
    if (!known)
      throw Error(fmt::format("cannot write image '{}': display '{}' has no view '{}' (views: {})", path,
                              display, chosen, views));
    OCIO::ConstProcessorRcPtr processor =
        config->getProcessor(OCIO::ROLE_SCENE_LINEAR, display, chosen.c_str(), OCIO::TRANSFORM_DIR_FORWARD);
    OCIO::PackedImageDesc desc(buffer.data(), img.width, img.height, 3);
    processor->getDefaultCPUProcessor()->apply(desc);
  } catch (const OCIO::Exception& e) {
    throw Error(fmt::format("cannot write image '{}': OpenColorIO: {}", path, e.what()));
  }
  std::vector<uint8_t> bytes(buffer.size());
  for (size_t i = 0; i < buffer.size(); ++i) {
    float v = buffer[i];
    // NaN fails both comparisons and becomes black rather than undefined behaviour in lround.
    v = v > 0.f ? std::min(v, 1.f) : 0.f;
    bytes[i] = uint8_t(std::lround(v * 255.f));
  }
  return bytes;
}

// ---- PFM -----------------------------------------------------------------------------------------

// OpenImageIO 2.4 reads PFM but cannot write it, and the format is a header plus raw floats.
void write_pfm_to(const std::string& path, const std::string& temporary, const ImageRgb& img) {
  std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
  // A negative scale marks little-endian data; rows run bottom to top.
  static_assert(std::endian::native == std::endian::little, "PFM writer assumes a little-endian host");
  out << "PF\n" << img.width << " " << img.height << "\n-1.0\n";
  size_t row = size_t(img.width) * 3;
  for (int y = img.height - 1; y >= 0; --y)
    out.write(reinterpret_cast<const char*>(img.pixels.data() + size_t(y) * row),
              std::streamsize(row * sizeof(float)));
  out.close();
  if (!out) throw Error(fmt::format("cannot write image '{}': {}", path, std::strerror(errno)));
}

void write_pfm(const std::string& path, const ImageRgb& img) {
  write_atomically(path, [&](const std::string& temporary) { write_pfm_to(path, temporary, img); });
}

}  // namespace

std::string ocio_config_path() {
  const char* env = std::getenv("OCIO");
  if (env && *env) return env;
  return shipped_ocio_config();
}

void check_ocio_config(const std::string& path) { load_config(path, false); }

std::string image_output_problem(const std::string& path) {
  try {
    const FormatInfo& format = format_of(path);
    std::string problem = output_path_problem(path);
    if (!problem.empty()) return fmt::format("cannot write image '{}': {}", path, problem);
    // 8-bit formats need a usable OpenColorIO config, and all but PFM the image library: find that
    // out now, not after the render.
    if (format.encoding == Encoding::Display) current_config();
    if (std::string(format.extension) != ".pfm") problem = image_codecs_problem();
    if (!problem.empty()) return fmt::format("cannot write image '{}': {}", path, problem);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

bool is_exr_path(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".exr";
}

void write_image(const std::string& path, const ImageRgb& img,
                 const std::vector<std::pair<std::string, std::string>>& metadata, const std::string& view) {
  const FormatInfo& format = format_of(path);
  if (img.width <= 0 || img.height <= 0 || img.pixels.size() != size_t(img.width) * img.height * 3)
    throw Error(fmt::format("cannot write image '{}': {}x{} image has {} values, expected {}", path, img.width,
                            img.height, img.pixels.size(), size_t(std::max(img.width, 0)) *
                                                                   size_t(std::max(img.height, 0)) * 3));

  bool display = format.encoding == Encoding::Display;
  std::string ext = format.extension;
  if (ext == ".pfm") {
    write_pfm(path, img);
    return;
  }
  RasterToWrite raster;
  raster.width = img.width;
  raster.height = img.height;
  raster.channel_names = {"R", "G", "B"};
  raster.attributes = metadata;
  if (ext == ".exr") raster.attributes.emplace_back("compression", "zip");
  if (ext == ".jpg" || ext == ".jpeg") raster.attributes.emplace_back("Compression", "jpeg:95");
  std::vector<uint8_t> bytes;
  if (display) {
    bytes = encode_for_display(path, img, view);
    raster.bytes = bytes.data();
  } else {
    raster.floats = img.pixels.data();
  }
  write_raster(path, raster);
}

ImageRgb read_image(const std::string& path, ImageFileInfo* info) {
  // Only the channels used: the first three, or the one grey channel repeated.
  RasterRead r = read_raster(path, 3);
  if (info) {
    info->integer = r.integer;
    info->channels = r.file_channels;
  }
  size_t used = r.channel_names.size();
  ImageRgb img;
  img.width = r.width;
  img.height = r.height;
  img.pixels.resize(size_t(img.width) * img.height * 3);
  for (size_t p = 0; p < size_t(img.width) * img.height; ++p)
    for (size_t c = 0; c < 3; ++c)
      img.pixels[3 * p + c] = r.pixels[p * used + (used == 3 ? c : 0)];
  return img;
}

}  // namespace penumbra
