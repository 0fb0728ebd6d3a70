#include "image/image_input.h"

#include "util/input_file.h"

#include <penumbra/error.h>

#include <fmt/core.h>

#include <algorithm>

namespace penumbra {

namespace {

// OpenImageIO 2.4 reads OpenEXR through the C++ library by default. That library trusts the sizes
// in a header: a 1.2 KB file whose attribute claims 1.9 GB of string data makes it allocate and zero
// 1.9 GB before it finds the file too short (found by scripts/fuzz.sh image). OpenEXR's core library
// checks each size against the file and refuses such a file at once, so it is used for every read.
void use_openexr_core_reader() {
  static const bool done = [] { return OIIO::attribute("openexr:core", 1); }();
  (void)done;
}

}  // namespace

std::unique_ptr<OIIO::ImageInput> open_image_input(const std::string& path) {
  if (std::string problem = input_file_problem(path); !problem.empty())
    throw Error(fmt::format("cannot read image '{}': {}", path, problem));
  use_openexr_core_reader();
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw Error(fmt::format("cannot read image '{}': {}", path, OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  constexpr double kMaxPixels = 268435456.0;  // 2^28 pixels: 3 GiB as RGB floats
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.nchannels > 64 || spec.depth > 1 ||
      static_cast<double>(spec.width) * spec.height > kMaxPixels)
    throw Error(fmt::format("cannot read image '{}': {}x{} pixels{} with {} channels is outside what Penumbra reads "
                            "(2D images of at most {:.0f} pixels and 64 channels)",
                            path, spec.width, spec.height,
                            spec.depth > 1 ? fmt::format(" x {} slices", spec.depth) : std::string(),
                            spec.nchannels, kMaxPixels));
  return in;
}

std::vector<float> read_image_channels(OIIO::ImageInput& in, const std::string& path, int channels) {
  const OIIO::ImageSpec& spec = in.spec();
  const size_t row = size_t(spec.width) * size_t(channels);
  const bool tiled = spec.tile_width > 0 && spec.tile_height > 0;
  const int band = tiled ? spec.tile_height * std::max(1, (64 + spec.tile_height - 1) / spec.tile_height) : 64;
  std::vector<float> pixels;
  for (int y = 0; y < spec.height; y += band) {
    int rows = std::min(band, spec.height - y);
    size_t at = pixels.size();
    pixels.resize(at + rows * row);
    int ybegin = spec.y + y, yend = ybegin + rows;
    bool ok = tiled ? in.read_tiles(0, 0, spec.x, spec.x + spec.width, ybegin, yend, spec.z, spec.z + 1,
                                    0, channels, OIIO::TypeDesc::FLOAT, pixels.data() + at)
                    : in.read_scanlines(0, 0, ybegin, yend, spec.z, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data() + at);
    if (!ok) throw Error(fmt::format("cannot read image '{}': {}", path, in.geterror()));
  }
  return pixels;
}

}  // namespace penumbra
