// libpenumbra-oiio.so: the image codecs of core/src/image/image_codecs.h through OpenImageIO, in a
// library of their own so that only a process that reads or writes an image file loads OpenImageIO
// and the shared libraries it links.
#include "image/image_codecs.h"

#include <penumbra/error.h>

#include <OpenImageIO/imageio.h>
#include <fmt/core.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <vector>

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

// What Penumbra reads: 2D images of at most 64 channels whose decoded values (pixels x channels read,
// as floats) fit in 1.5 GiB, the size of a 16384 x 8192 RGB environment map, and whose pixel data in
// the file's own format (all channels, uncompressed) is at most 2 GiB. The second bound is what a
// decoder allocates for one chunk at worst (a whole image in one OpenEXR chunk or tile, a PNG or TGA
// reader's whole-image buffer), so a damaged or hostile header cannot make anyone allocate more than
// that before the file turns out to be short (scripts/fuzz.sh image, 6 Dec: a 2.6 KB OpenEXR file
// whose data window claimed 18175319 x 12 pixels made the reader allocate 2.6 GB).
//
// Within those bounds a decoder still allocates a whole chunk before it finds the chunk's data short:
// a 2.6 KB file claiming 8000000 x 12 float RGB pixels peaked at 2.2 GB. A file whose header claims
// more than 256 MiB of pixel data must therefore hold at least 1/4096 of it: no format read here
// compresses pixels that far (deflate, in PNG, TIFF and OpenEXR's ZIP, stops near 1032:1; the
// run-length formats near 128:1), so only a damaged or hostile file is refused.
constexpr double kMaxDecodedValues = 3.0 * 16384 * 8192;
constexpr double kMaxFileBytes = 2147483648.0;
constexpr double kRatioCheckedAbove = 268435456.0;
constexpr double kMaxCompressionRatio = 4096.0;

std::unique_ptr<OIIO::ImageInput> open_checked(const std::string& path, int channels_wanted, int* channels_read) {
  use_openexr_core_reader();
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw Error(fmt::format("cannot read image '{}': {}", path, OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  *channels_read = std::clamp(channels_wanted, 1, std::max(spec.nchannels, 1));
  double pixels = static_cast<double>(spec.width) * spec.height;
  double file_bytes = static_cast<double>(spec.image_bytes(/*native=*/true));  // saturates, never wraps
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.nchannels > kMaxImageChannels ||
      spec.depth > 1 || pixels * *channels_read > kMaxDecodedValues || file_bytes > kMaxFileBytes)
    throw Error(fmt::format("cannot read image '{}': {}x{} pixels{} with {} channels is outside what Penumbra reads "
                            "(2D, at most {} channels, at most {:.0f} floats for the channels read as in 16384x8192 RGB, "
                            "at most 2 GiB of uncompressed pixel data)",
                            path, spec.width, spec.height,
                            spec.depth > 1 ? fmt::format(" x {} slices", spec.depth) : std::string(),
                            spec.nchannels, kMaxImageChannels, kMaxDecodedValues));
  std::error_code ec;
  double size = static_cast<double>(std::filesystem::file_size(path, ec));
  if (!ec && file_bytes > kRatioCheckedAbove && file_bytes > size * kMaxCompressionRatio)
    throw Error(fmt::format("cannot read image '{}': its header claims {:.0f} MiB of pixel data ({}x{} pixels, {} "
                            "channels) in a file of {:.0f} bytes, more than {:.0f} times its size: the file is "
                            "damaged or not an image",
                            path, file_bytes / 1048576.0, spec.width, spec.height, spec.nchannels, size,
                            kMaxCompressionRatio));
  return in;
}

// The result is reserved at its full size but filled only with the rows actually decoded, in bands
// of about 64 rows (whole tile rows for a tiled file, fewer rows when a row is very wide), each
// decoded into an uninitialised buffer first: a header that claims a large image in a small or
// damaged file fails at its first bad band having touched little more than that band.
std::vector<float> read_channels(OIIO::ImageInput& in, const std::string& path, int channels) {
  const OIIO::ImageSpec& spec = in.spec();
  const size_t row = size_t(spec.width) * size_t(channels);
  const bool tiled = spec.tile_width > 0 && spec.tile_height > 0;
  constexpr size_t kBandValues = size_t(1) << 24;  // 64 MiB of floats
  const int rows_wanted = int(std::clamp<size_t>(kBandValues / row, 1, 64));
  const int band = tiled ? spec.tile_height * std::max(1, (rows_wanted + spec.tile_height - 1) / spec.tile_height)
                         : rows_wanted;
  std::vector<float> pixels;
  pixels.reserve(row * size_t(spec.height));
  auto decoded = std::make_unique_for_overwrite<float[]>(row * size_t(std::min(band, spec.height)));
  for (int y = 0; y < spec.height; y += band) {
    int rows = std::min(band, spec.height - y);
    int ybegin = spec.y + y, yend = ybegin + rows;
    bool ok = tiled ? in.read_tiles(0, 0, spec.x, spec.x + spec.width, ybegin, yend, spec.z, spec.z + 1,
                                    0, channels, OIIO::TypeDesc::FLOAT, decoded.get())
                    : in.read_scanlines(0, 0, ybegin, yend, spec.z, 0, channels, OIIO::TypeDesc::FLOAT, decoded.get());
    if (!ok) throw Error(fmt::format("cannot read image '{}': {}", path, in.geterror()));
    pixels.insert(pixels.end(), decoded.get(), decoded.get() + size_t(rows) * row);
  }
  return pixels;
}

RasterRead read(const std::string& path, int max_channels) {
  int n = 0;
  auto in = open_checked(path, max_channels, &n);
  const OIIO::ImageSpec& spec = in->spec();
  RasterRead r;
  r.width = spec.width;
  r.height = spec.height;
  r.file_channels = spec.nchannels;
  r.integer = !spec.format.is_floating_point();
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
