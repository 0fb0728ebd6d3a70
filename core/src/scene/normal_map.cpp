#include "scene/normal_map.h"

#include <penumbra/image.h>

#include <fmt/core.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <mutex>

namespace penumbra {

NormalMapImage::NormalMapImage(int width, int height, std::vector<Vec3> texels)
    : width_(width), height_(height), texels_(std::move(texels)) {}

const Vec3& NormalMapImage::texel(int x, int y) const {
  auto wrap = [](int i, int n) {
    int r = i % n;
    return r < 0 ? r + n : r;
  };
  return texels_[static_cast<size_t>(wrap(y, height_)) * width_ + wrap(x, width_)];
}

Vec3 NormalMapImage::bilerp(Vec2 st) const {
  float x = st.x * width_ - 0.5f, y = st.y * height_ - 0.5f;
  if (!std::isfinite(x) || !std::isfinite(y)) return texel(0, 0);
  float fx = std::floor(x), fy = std::floor(y);
  // Keep the integer coordinates small before the modulo (huge uv would overflow an int).
  fx = std::fmod(fx, float(width_)), fy = std::fmod(fy, float(height_));
  float dx = x - std::floor(x), dy = y - std::floor(y);
  int xi = static_cast<int>(fx), yi = static_cast<int>(fy);
  return (1.f - dx) * (1.f - dy) * texel(xi, yi) + dx * (1.f - dy) * texel(xi + 1, yi) +
         (1.f - dx) * dy * texel(xi, yi + 1) + dx * dy * texel(xi + 1, yi + 1);
}

namespace {
std::mutex cache_mutex;
std::map<std::string, std::weak_ptr<const NormalMapImage>> cache;
}  // namespace

std::shared_ptr<const NormalMapImage> load_normal_map(const std::string& path, const FileLoc& loc) {
  std::error_code ec;
  std::string key = std::filesystem::weakly_canonical(path, ec).string();
  if (ec) key = path;
  std::lock_guard<std::mutex> lock(cache_mutex);
  if (auto it = cache.find(key); it != cache.end())
    if (auto shared = it->second.lock()) return shared;
  ImageRgb img;
  try {
    img = read_image(path);
  } catch (const Error& e) {
    throw Error(loc, fmt::format("cannot read the normal map: {}", e.what()));
  }
  if (img.width <= 0 || img.height <= 0) throw Error(loc, fmt::format("normal map '{}' is empty", path));
  std::vector<Vec3> texels(static_cast<size_t>(img.width) * img.height);
  for (size_t i = 0; i < texels.size(); ++i)
    texels[i] = Vec3(img.pixels[3 * i], img.pixels[3 * i + 1], img.pixels[3 * i + 2]);
  auto image = std::make_shared<const NormalMapImage>(img.width, img.height, std::move(texels));
  cache[key] = image;
  return image;
}

}  // namespace penumbra
