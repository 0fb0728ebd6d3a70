// An image pyramid for texture lookups (pbrt-v4's MIPMap semantics): level 0 is the image resized up
// to powers of two, each further level averages 2x2 texels of the one before, down to 1x1. Lookups
// take (s, t) with t = 0 at the top row and the footprint's two axes in (s, t).
#pragma once

#include <penumbra/color.h>
#include <penumbra/math.h>

#include <vector>

namespace imagemap {

using penumbra::Rgb;
using penumbra::Vec2;

enum class WrapMode { Repeat, Black, Clamp };
enum class Filter { Point, Bilinear, Trilinear, Ewa };

/// One level: RGB texels, row 0 at the top.
struct Level {
  int width = 0, height = 0;
  std::vector<Rgb> texels;
};

class MipMap {
 public:
  /// `texels` are linear (already decoded) RGB of a width x height image.
  MipMap(int width, int height, std::vector<Rgb> texels, WrapMode wrap);

  int levels() const { return static_cast<int>(levels_.size()); }
  const Level& level(int i) const { return levels_[i]; }

  /// Texel (x, y) of a level with the wrap mode applied (black: zero outside).
  Rgb texel(int level, int x, int y) const;
  /// Bilinear interpolation between the four texel centres around (s, t) on one level.
  Rgb bilerp(int level, Vec2 st) const;
  /// The filtered value over the footprint (dst0 = d(s,t)/dx, dst1 = d(s,t)/dy). Point, bilinear and
  /// trilinear choose the level from the footprint's widest extent, as pbrt-v4 does (point and
  /// bilinear use the finer of the two neighbouring levels); EWA filters the footprint's ellipse.
  Rgb filter(Filter f, Vec2 st, Vec2 dst0, Vec2 dst1, float max_anisotropy) const;

 private:
  Rgb ewa(int level, Vec2 st, Vec2 dst0, Vec2 dst1) const;
  std::vector<Level> levels_;
  WrapMode wrap_;
};

}  // namespace imagemap
