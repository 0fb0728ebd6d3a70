// libpenumbra-oiio.so: the image codecs of core/src/image/image_codecs.h through OpenImageIO, in a
// library of their own so that only a process that reads or writes an image file loads OpenImageIO
// and the shared libraries it links.
#include "image/image_codecs.h"

#include <penumbra/error.h>

#include <OpenImageIO/imageio.h>
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

void write(const std::string& path, const std::string& temporary, const RasterToWrite& r) {
  OIIO::ImageSpec spec(r.width, r.height, int(r.channel_names.size()),
                       r.floats ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
  spec.channelnames = r.channel_names;
  spec.alpha_channel = -1;  // "A" among AOV layers is not an alpha to premultiply by
  for (const auto& [key, value] : r.attributes) spec.attribute(key, value);
  auto out = OIIO::ImageOutput::create(path);
  if (!out) throw Error(fmt::format("cannot write image '{}': {}", path, OIIO::geterror()));
  const void* data = r.floats ? static_cast<const void*>(r.floats) : static_cast<const void*>(r.bytes);
  if (!out->open(temporary, spec) || !out->write_image(spec.format, data) || !out->close())
    throw Error(fmt::format("cannot write image '{}': {}", path, out->geterror()));
}

std::unique_ptr<OIIO::ImageInput> open_checked(const std::string& path) {
  use_openexr_core_reader();
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw Error(fmt::format("cannot read image '{}': {}", path, OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  constexpr double kMaxPixels = 268435456.0;  // 2^28 pixels: 3 GiB as RGB floats
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.nchannels > kMaxImageChannels ||
      spec.depth > 1 || static_cast<double>(spec.width) * spec.height > kMaxPixels)
    throw Error(fmt::format("cannot read image '{}': {}x{} pixels{} with {} channels is outside what Penumbra reads "
                            "(2D images of at most {:.0f} pixels and {} channels)",
                            path, spec.width, spec.height,
                            spec.depth > 1 ? fmt::format(" x {} slices", spec.depth) : std::string(),
                            spec.nchannels, kMaxPixels, kMaxImageChannels));
  return in;
}

// The result grows with the rows actually decoded, in bands of at least 64 rows (whole tile rows
// for a tiled file), so a header that claims a huge image in a small or damaged file fails at its
// first bad band instead of making the reader allocate the claimed size first.
std::vector<float> read_channels(OIIO::ImageInput& in, const std::string& path, int channels) {
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

RasterRead read(const std::string& path, int max_channels) {
  auto in = open_checked(path);
  const OIIO::ImageSpec& spec = in->spec();
  RasterRead r;
  r.width = spec.width;
  r.height = spec.height;
  r.file_channels = spec.nchannels;
  r.integer = !spec.format.is_floating_point();
  int n = std::clamp(max_channels, 1, spec.nchannels);
  for (int c = 0; c < n; ++c) r.channel_names.push_back(c < int(spec.channelnames.size()) ? spec.channelnames[c] : "");
  r.pixels = read_channels(*in, path, n);
  for (const auto& attr : spec.extra_attribs)
    if (attr.type() == OIIO::TypeDesc::STRING) r.attributes.emplace_back(attr.name().string(), attr.get_string());
  in->close();
  return r;
}

const ImageCodecs kCodecs{kImageCodecsVersion, write, read};

}  // namespace

}  // namespace penumbra

extern "C" __attribute__((visibility("default"))) const penumbra::ImageCodecs* penumbra_image_codecs() {
  return &penumbra::kCodecs;
}
