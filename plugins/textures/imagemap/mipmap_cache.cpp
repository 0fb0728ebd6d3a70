#include "mipmap_cache.h"

#include <penumbra/image.h>

#include <fmt/core.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <mutex>
#include <sstream>
#include <tuple>

namespace imagemap {

using namespace penumbra;

Encoding parse_encoding(const std::string& text, const FileLoc& loc) {
  Encoding e;
  if (text == "sRGB") {
    e.kind = Encoding::Kind::Srgb;
    return e;
  }
  if (text == "linear") {
    e.kind = Encoding::Kind::Linear;
    return e;
  }
  std::istringstream in(text);
  std::string word, extra;
  float g = 0.f;
  if (in >> word && word == "gamma" && in >> g && !(in >> extra) && g > 0.f && std::isfinite(g)) {
    e.kind = Encoding::Kind::Gamma;
    e.gamma = g;
    return e;
  }
  throw Error(loc, fmt::format("unknown encoding \"{}\"; use \"sRGB\", \"linear\" or \"gamma G\" (G > 0)", text));
}

namespace {

float srgb_to_linear(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

std::mutex cache_mutex;
std::map<std::tuple<std::string, int, float, int>, std::weak_ptr<const MipMap>> cache;
int built = 0;

}  // namespace

std::shared_ptr<const MipMap> load_mipmap(const std::string& path, const Encoding& encoding, WrapMode wrap,
                                          const FileLoc& loc) {
  std::error_code ec;
  std::string key_path = std::filesystem::weakly_canonical(path, ec).string();
  if (ec) key_path = path;
  auto key = std::make_tuple(key_path, static_cast<int>(encoding.kind), encoding.gamma, static_cast<int>(wrap));
  std::lock_guard<std::mutex> lock(cache_mutex);
  if (auto it = cache.find(key); it != cache.end())
    if (auto shared = it->second.lock()) return shared;

  ImageRgb img;
  ImageFileInfo info;
  try {
    img = read_image(path, &info);
  } catch (const Error& e) {
    throw Error(loc, e.what());
  }
  if (img.width <= 0 || img.height <= 0) throw Error(loc, fmt::format("image '{}' is empty", path));
  std::vector<Rgb> texels(static_cast<size_t>(img.width) * img.height);
  for (size_t i = 0; i < texels.size(); ++i) {
    Rgb v(img.pixels[3 * i], img.pixels[3 * i + 1], img.pixels[3 * i + 2]);
    if (info.integer) {
      for (int c = 0; c < 3; ++c) {
        switch (encoding.kind) {
          case Encoding::Kind::Srgb: v[c] = srgb_to_linear(v[c]); break;
          case Encoding::Kind::Gamma: v[c] = std::pow(v[c], encoding.gamma); break;
          case Encoding::Kind::Linear: break;
        }
      }
    }
    texels[i] = v;
  }
  auto mip = std::make_shared<const MipMap>(img.width, img.height, std::move(texels), wrap);
  cache[key] = mip;
  ++built;
  return mip;
}

int mipmaps_built() {
  std::lock_guard<std::mutex> lock(cache_mutex);
  return built;
}

}  // namespace imagemap
