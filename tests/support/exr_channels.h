// Reads an EXR with OpenImageIO's own reader, channel by channel and by name, so that tests check
// what any tool would see rather than what Penumbra's reader makes of the file.
#pragma once

#include <OpenImageIO/imageio.h>

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace penumbra::test {

struct ExrChannels {
  int width = 0, height = 0;
  std::vector<std::string> names;                      // in file order
  std::map<std::string, std::vector<float>> channels;  // one value per pixel, row 0 = top
  std::map<std::string, std::string> meta;             // string attributes

  bool has(const std::string& name) const { return channels.count(name) != 0; }
  float at(const std::string& name, int x, int y) const { return channels.at(name)[size_t(y) * width + x]; }
};

inline ExrChannels read_exr_channels(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw std::runtime_error("cannot open " + path + ": " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  ExrChannels out;
  out.width = spec.width;
  out.height = spec.height;
  size_t n = size_t(spec.width) * spec.height, nc = size_t(spec.nchannels);
  std::vector<float> all(n * nc);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
    throw std::runtime_error("cannot read " + path + ": " + in->geterror());
  for (size_t c = 0; c < nc; ++c) {
    out.names.push_back(spec.channelnames[c]);
    std::vector<float>& v = out.channels[spec.channelnames[c]];
    v.resize(n);
    for (size_t p = 0; p < n; ++p) v[p] = all[p * nc + c];
  }
  for (const auto& a : spec.extra_attribs)
    if (a.type() == OIIO::TypeDesc::STRING) out.meta[a.name().string()] = a.get_string();
  return out;
}

}  // namespace penumbra::test
