#include "image/exr_layers.h"

#include "image/image_codecs.h"

#include <penumbra/error.h>

#include <fmt/core.h>

namespace penumbra {

const ImageLayer* LayeredImage::find(const std::string& name) const {
  for (const auto& l : layers)
    if (l.name == name) return &l;
  return nullptr;
}

std::string LayeredImage::meta(const std::string& key) const {
  for (const auto& [k, v] : metadata)
    if (k == key) return v;
  return "";
}

void LayeredImage::set_meta(const std::string& key, const std::string& value) {
  for (auto& [k, v] : metadata)
    if (k == key) {
      v = value;
      return;
    }
  metadata.emplace_back(key, value);
}

void write_layered_exr(const std::string& path, const LayeredImage& image) {
  size_t npix = size_t(image.width) * size_t(image.height);
  std::vector<std::string> names;
  for (const auto& l : image.layers) {
    if (l.channels.empty() || l.pixels.size() != npix * l.channels.size())
      throw Error(fmt::format("cannot write image '{}': layer '{}' has {} values for {} channels of {}x{}",
                              path, l.name, l.pixels.size(), l.channels.size(), image.width, image.height));
    for (const auto& c : l.channels) names.push_back(l.name.empty() ? c : l.name + "." + c);
  }
  if (names.empty() || npix == 0) throw Error(fmt::format("cannot write image '{}': it is empty", path));

  RasterToWrite raster;
  raster.width = image.width;
  raster.height = image.height;
  raster.channel_names = names;
  raster.attributes = {{"compression", "zip"}};
  raster.attributes.insert(raster.attributes.end(), image.metadata.begin(), image.metadata.end());

  std::vector<float> buffer(npix * names.size());
  size_t offset = 0;
  for (const auto& l : image.layers) {
    size_t n = l.channels.size();
    for (size_t p = 0; p < npix; ++p)
      for (size_t c = 0; c < n; ++c) buffer[p * names.size() + offset + c] = l.pixels[p * n + c];
    offset += n;
  }
  raster.floats = buffer.data();
  write_raster(path, raster);
}

LayeredImage read_layered_exr(const std::string& path) {
  RasterRead r = read_raster(path, kMaxImageChannels);
  size_t nch = r.channel_names.size(), npix = size_t(r.width) * size_t(r.height);

  LayeredImage image;
  image.width = r.width;
  image.height = r.height;
  std::vector<std::pair<size_t, size_t>> where(nch);  // channel -> (layer, index in layer)
  for (size_t c = 0; c < nch; ++c) {
    const std::string& full = r.channel_names[c];
    size_t dot = full.rfind('.');
    std::string layer = dot == std::string::npos ? "" : full.substr(0, dot);
    std::string channel = dot == std::string::npos ? full : full.substr(dot + 1);
    size_t li = 0;
    while (li < image.layers.size() && image.layers[li].name != layer) ++li;
    if (li == image.layers.size()) image.layers.push_back(ImageLayer{layer, {}, {}});
    where[c] = {li, image.layers[li].channels.size()};
    image.layers[li].channels.push_back(channel);
  }
  for (auto& l : image.layers) l.pixels.resize(npix * l.channels.size());
  for (size_t p = 0; p < npix; ++p)
    for (size_t c = 0; c < nch; ++c) {
      ImageLayer& l = image.layers[where[c].first];
      l.pixels[p * l.channels.size() + where[c].second] = r.pixels[p * nch + c];
    }
  image.metadata = std::move(r.attributes);
  return image;
}

}  // namespace penumbra
