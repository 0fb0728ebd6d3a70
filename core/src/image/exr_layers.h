// Multilayer EXR files through OpenImageIO: the beauty as R, G, B plus named layers of channels
// ("albedo.R", "depth.Z", "samples.count") and string metadata in the header. `penumbra render`
// writes them when AOVs are requested; `penumbra merge` reads and writes them.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace penumbra {

/// A group of channels stored as "<name>.<channel>"; the beauty layer has an empty name, so its
/// channels are plain "R", "G", "B".
struct ImageLayer {
  std::string name;
  std::vector<std::string> channels;
  std::vector<float> pixels;  // channels interleaved per pixel, row 0 = top
};

struct LayeredImage {
  int width = 0, height = 0;
  std::vector<ImageLayer> layers;
  std::vector<std::pair<std::string, std::string>> metadata;

  const ImageLayer* find(const std::string& name) const;
  /// The metadata value for `key`, or "" when absent.
  std::string meta(const std::string& key) const;
  void set_meta(const std::string& key, const std::string& value);
};

/// Writes 32-bit float channels, zip-compressed. Throws Error naming the file.
void write_layered_exr(const std::string& path, const LayeredImage& image);

/// Reads every channel and every string attribute. Channels are grouped into layers by the text
/// before their last '.', in the order the file lists them. Throws Error naming the file.
LayeredImage read_layered_exr(const std::string& path);

}  // namespace penumbra
