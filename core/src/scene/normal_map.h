// Normal maps as pbrt-v4 reads them (`"string normalmap" "file"` on a material): a tangent-space RGB
// image whose values in [0, 1] map to normal components in [-1, 1]. 8- and 16-bit files are read as
// value / max (linear, no sRGB decoding, as pbrt-v4 reads normal maps); float files as stored. Each
// file is read once per process and shared by every material that names it.
#pragma once

#include <penumbra/error.h>
#include <penumbra/math.h>

#include <memory>
#include <string>
#include <vector>

namespace penumbra {

class NormalMapImage {
 public:
  NormalMapImage(int width, int height, std::vector<Vec3> texels);
  int width() const { return width_; }
  int height() const { return height_; }
  /// The stored RGB, bilinearly interpolated at (s, t) in [0, 1]^2 (t = 0 the top row, texel
  /// centres at (i + 0.5) / width), wrapping around (repeat), as pbrt-v4's Image::Bilerp does.
  Vec3 bilerp(Vec2 st) const;

 private:
  const Vec3& texel(int x, int y) const;
  int width_, height_;
  std::vector<Vec3> texels_;  // row 0 = top
};

/// Reads `path` (or returns the copy already read); an unreadable or empty image is an error at `loc`.
std::shared_ptr<const NormalMapImage> load_normal_map(const std::string& path, const FileLoc& loc);

}  // namespace penumbra
