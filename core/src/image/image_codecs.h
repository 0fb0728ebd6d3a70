// Image files are encoded and decoded by OpenImageIO in a library of their own,
// lib/penumbra/libpenumbra-oiio.so (core/oiio/), which the core opens the first time a process reads
// or writes an image file. Debian's OpenImageIO links about 260 shared libraries (OpenCV, GDAL,
// DICOM, HEIF, ...), most of them bound at load time: linked into the core, they cost every process
// about 0.35 s before main() (docs/architecture.md, "Image files"), whether it touches an image or
// not. Everything else about images (formats, OpenColorIO, PFM, safe replacement of the output file)
// stays in the core; the library only moves pixels between memory and a file.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace penumbra {

using ImageAttributes = std::vector<std::pair<std::string, std::string>>;

/// Pixels to write: one value per channel per pixel, interleaved, row 0 = top; either 32-bit floats
/// or 8-bit values.
struct RasterToWrite {
  int width = 0, height = 0;
  std::vector<std::string> channel_names;  // one per channel, in order
  const float* floats = nullptr;
  const uint8_t* bytes = nullptr;          // used when floats is null
  ImageAttributes attributes;              // string attributes of the file (metadata, compression)
};

/// Pixels read from the first subimage of a file, as floats, interleaved, row 0 = top.
struct RasterRead {
  int width = 0, height = 0;
  int file_channels = 0;                   // channels the file has
  bool integer = false;                    // the file stores integers (read as value / max)
  std::vector<std::string> channel_names;  // of the channels read: the first min(file_channels, asked)
  std::vector<float> pixels;
  ImageAttributes attributes;              // the file's string attributes
};

/// What the codec library provides, through the one function it exports (kImageCodecsSymbol).
struct ImageCodecs {
  int version;  // kImageCodecsVersion of the build that made the library
  /// Writes the raster to the file `temporary` in the format that `path`'s extension names (the
  /// caller renames it to `path`). Throws Error naming `path`.
  void (*write)(const std::string& path, const std::string& temporary, const RasterToWrite& raster);
  /// Reads channels [0, min(file channels, max_channels)). Throws Error naming `path` when the file
  /// cannot be decoded, or when its header claims more decoded values (pixels x channels read) than a
  /// 16384 x 8192 RGB image, more than 2 GiB of uncompressed pixel data in the file (or more than
  /// 256 MiB in a file under 1/4096 of it), more than kMaxImageChannels channels or a volume (a
  /// damaged or hostile header must not make anyone allocate).
  RasterRead (*read)(const std::string& path, int max_channels);
};

constexpr int kImageCodecsVersion = 1;
constexpr int kMaxImageChannels = 64;  // a file with more is refused as damaged or hostile
constexpr const char* kImageCodecsSymbol = "penumbra_image_codecs";
constexpr const char* kImageCodecsLibrary = "penumbra/libpenumbra-oiio.so";  // relative to the core's folder

/// Why image files could not be read or written in this process ("" when they can): the codec library
/// is missing. Cheap (the library is looked for, not loaded), so a render can ask before it starts.
std::string image_codecs_problem();

/// Writes through a temporary file renamed into place (the old file survives a failure).
void write_raster(const std::string& path, const RasterToWrite& raster);

/// Checks that `path` is a readable regular file, then decodes it.
RasterRead read_raster(const std::string& path, int max_channels);

}  // namespace penumbra

/// Exported by libpenumbra-oiio.so (or linked into a program that wants no dlopen, such as the fuzzers).
extern "C" const penumbra::ImageCodecs* penumbra_image_codecs();
