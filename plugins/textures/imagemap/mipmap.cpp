#include "mipmap.h"

#include <algorithm>
#include <cmath>

namespace imagemap {

namespace {

bool is_power_of_2(int v) { return v > 0 && (v & (v - 1)) == 0; }
int round_up_power_of_2(int v) {
  int p = 1;
  while (p < v) p *= 2;
  return p;
}

}  // namespace

Rgb MipMap::texel(int level, int x, int y) const {
  const Level& l = levels_[level];
  switch (wrap_) {
    case WrapMode::Repeat:
      x = ((x % l.width) + l.width) % l.width;
      y = ((y % l.height) + l.height) % l.height;
      break;
    case WrapMode::Clamp:
      x = std::clamp(x, 0, l.width - 1);
      y = std::clamp(y, 0, l.height - 1);
      break;
    case WrapMode::Black:
      if (x < 0 || y < 0 || x >= l.width || y >= l.height) return Rgb(0.f);
      break;
  }
  return l.texels[static_cast<size_t>(y) * l.width + x];
}

Rgb MipMap::bilerp(int level, Vec2 st) const {
  const Level& l = levels_[level];
  float x = st.x * l.width - 0.5f, y = st.y * l.height - 0.5f;
  float fx0 = std::floor(x), fy0 = std::floor(y);
  int x0 = static_cast<int>(fx0), y0 = static_cast<int>(fy0);
  float dx = x - fx0, dy = y - fy0;
  return (1.f - dx) * (1.f - dy) * texel(level, x0, y0) + dx * (1.f - dy) * texel(level, x0 + 1, y0) +
         (1.f - dx) * dy * texel(level, x0, y0 + 1) + dx * dy * texel(level, x0 + 1, y0 + 1);
}

MipMap::MipMap(int width, int height, std::vector<Rgb> texels, WrapMode wrap) : wrap_(wrap) {
  Level base{width, height, std::move(texels)};
  if (!is_power_of_2(width) || !is_power_of_2(height)) {
    // Resized up by sampling the original bilinearly (with its wrap mode) at the centres of the new
    // texels; pbrt-v4 uses a windowed sinc here. Both keep the image's mean.
    levels_.push_back(std::move(base));
    int w = round_up_power_of_2(width), h = round_up_power_of_2(height);
    Level up{w, h, std::vector<Rgb>(static_cast<size_t>(w) * h)};
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        up.texels[static_cast<size_t>(y) * w + x] = bilerp(0, Vec2((x + 0.5f) / w, (y + 0.5f) / h));
    levels_.clear();
    base = std::move(up);
  }
  levels_.push_back(std::move(base));
  // Box-filter 2x2 blocks down to 1x1; a dimension that is already 1 is averaged over the other only.
  while (levels_.back().width > 1 || levels_.back().height > 1) {
    const Level& prev = levels_.back();
    int w = std::max(1, prev.width / 2), h = std::max(1, prev.height / 2);
    Level next{w, h, std::vector<Rgb>(static_cast<size_t>(w) * h)};
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        int x0 = std::min(2 * x, prev.width - 1), x1 = std::min(2 * x + 1, prev.width - 1);
        int y0 = std::min(2 * y, prev.height - 1), y1 = std::min(2 * y + 1, prev.height - 1);
        auto at = [&](int xx, int yy) { return prev.texels[static_cast<size_t>(yy) * prev.width + xx]; };
        next.texels[static_cast<size_t>(y) * w + x] = 0.25f * (at(x0, y0) + at(x1, y0) + at(x0, y1) + at(x1, y1));
      }
    levels_.push_back(std::move(next));
  }
}

Rgb MipMap::filter(Filter f, Vec2 st, Vec2 dst0, Vec2 dst1, float max_anisotropy) const {
  const int n = levels();
  if (f != Filter::Ewa) {
    float width = 2.f * std::max({std::abs(dst0.x), std::abs(dst0.y), std::abs(dst1.x), std::abs(dst1.y)});
    // The level whose texels are `width` wide: level 0's texels are 2^-(n-1) wide.
    float lod = n - 1 + std::log2(std::max(width, 1e-8f));
    if (lod >= n - 1) return texel(n - 1, 0, 0);
    int i = std::max(0, static_cast<int>(std::floor(lod)));
    if (f == Filter::Point) {
      const Level& l = levels_[i];
      return texel(i, static_cast<int>(std::lround(st.x * l.width - 0.5f)),
                   static_cast<int>(std::lround(st.y * l.height - 0.5f)));
    }
    if (f == Filter::Bilinear || i == 0) return bilerp(i, st);
    float delta = lod - i;
    return (1.f - delta) * bilerp(i, st) + delta * bilerp(i + 1, st);
  }
  // EWA: the footprint's axes span an ellipse; its minor axis picks the level (after limiting the
  // eccentricity to max_anisotropy by widening the minor axis), and two levels are blended.
  if (glm::dot(dst0, dst0) < glm::dot(dst1, dst1)) std::swap(dst0, dst1);
  float major = glm::length(dst0), minor = glm::length(dst1);
  if (minor * max_anisotropy < major && minor > 0.f) {
    float scale = major / (minor * max_anisotropy);
    dst1 *= scale;
    minor *= scale;
  }
  if (minor == 0.f) return bilerp(0, st);
  float lod = std::max(0.f, n - 1 + std::log2(minor));
  int i = static_cast<int>(std::floor(lod));
  float delta = lod - i;
  return (1.f - delta) * ewa(i, st, dst0, dst1) + delta * ewa(i + 1, st, dst0, dst1);
}

// Heckbert's elliptical weighted average on one level: the ellipse spanned by the two footprint axes
// (in texels, grown by one texel so it never falls between texel centres) is the implicit quadric
// A x^2 + B x y + C y^2 < 1; texels inside are weighted by a Gaussian of that radius.
Rgb MipMap::ewa(int level, Vec2 st, Vec2 dst0, Vec2 dst1) const {
  if (level >= levels()) return texel(levels() - 1, 0, 0);
  const Level& l = levels_[level];
  Vec2 res(static_cast<float>(l.width), static_cast<float>(l.height));
  Vec2 c = st * res - Vec2(0.5f);
  dst0 *= res;
  dst1 *= res;
  float A = dst0.y * dst0.y + dst1.y * dst1.y + 1.f;
  float B = -2.f * (dst0.x * dst0.y + dst1.x * dst1.y);
  float C = dst0.x * dst0.x + dst1.x * dst1.x + 1.f;
  float inv_f = 1.f / (A * C - 0.25f * B * B);
  A *= inv_f, B *= inv_f, C *= inv_f;
  // Bounding box of the ellipse.
  float det = 4.f * A * C - B * B;
  float du = 2.f * std::sqrt(std::max(0.f, det * C)) / det, dv = 2.f * std::sqrt(std::max(0.f, det * A)) / det;
  int x0 = static_cast<int>(std::ceil(c.x - du)), x1 = static_cast<int>(std::floor(c.x + du));
  int y0 = static_cast<int>(std::ceil(c.y - dv)), y1 = static_cast<int>(std::floor(c.y + dv));
  constexpr float kAlpha = 2.f;
  const float floor_weight = std::exp(-kAlpha);
  Rgb sum(0.f);
  float weights = 0.f;
  for (int y = y0; y <= y1; ++y) {
    float ty = y - c.y;
    for (int x = x0; x <= x1; ++x) {
      float tx = x - c.x;
      float r2 = A * tx * tx + B * tx * ty + C * ty * ty;
      if (r2 >= 1.f) continue;
      float w = std::exp(-kAlpha * r2) - floor_weight;
      sum += w * texel(level, x, y);
      weights += w;
    }
  }
  return weights > 0.f ? sum / weights : bilerp(level, st);
}

}  // namespace imagemap
