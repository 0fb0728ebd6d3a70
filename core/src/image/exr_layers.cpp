#include "image/exr_layers.h"

#include "image/image_input.h"

#include "util/output_file.h"

#include <penumbra/error.h>

#include <OpenImageIO/imageio.h>
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

  OIIO::ImageSpec spec(image.width, image.height, int(names.size()), OIIO::TypeDesc::FLOAT);
  spec.channelnames = names;
  spec.alpha_channel = -1;
  spec.attribute("compression", "zip");
  for (const auto& [key, value] : image.metadata) spec.attribute(key, value);

  std::vector<float> buffer(npix * names.size());
  size_t offset = 0;
  for (const auto& l : image.layers) {
    size_t n = l.channels.size();
    for (size_t p = 0; p < npix; ++p)
      for (size_t c = 0; c < n; ++c) buffer[p * names.size() + offset + c] = l.pixels[p * n + c];
    offset += n;
  }
  // Through a temporary file renamed into place: the old image survives a failure.
  write_atomically(path, [&](const std::string& temporary) {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw Error(fmt::format("cannot write image '{}': {}", path, OIIO::geterror()));
    if (!out->open(temporary, spec) || !out->write_image(OIIO::TypeDesc::FLOAT, buffer.data()) || !out->close())
      throw Error(fmt::format("cannot write image '{}': {}", path, out->geterror()));
  });
}

LayeredImage read_layered_exr(const std::string& path) {
  auto in = open_image_input(path);
  const OIIO::ImageSpec& spec = in->spec();
  size_t nch = size_t(spec.nchannels), npix = size_t(spec.width) * size_t(spec.height);
  std::vector<float> all = read_image_channels(*in, path, spec.nchannels);

  LayeredImage image;
  image.width = spec.width;
  image.height = spec.height;
  std::vector<std::pair<size_t, size_t>> where(nch);  // channel -> (layer, index in layer)
  for (size_t c = 0; c < nch; ++c) {
    std::string full = spec.channelnames[c];
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
      l.pixels[p * l.channels.size() + where[c].second] = all[p * nch + c];
    }
  for (const auto& attr : spec.extra_attribs)
    if (attr.type() == OIIO::TypeDesc::STRING) image.metadata.emplace_back(attr.name().string(), attr.get_string());
  in->close();
  return image;
}

}  // namespace penumbra
