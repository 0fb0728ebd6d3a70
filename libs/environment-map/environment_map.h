// Environment images in either of the two mappings Penumbra reads: pbrt-v4's equal-area octahedral
// square (the format's own) and the equirectangular (latitude-longitude) layout that converted scenes
// often carry. Light space is z-up in both. Shared by the "infinite" light plugin and the
// `penumbra envmap` converter; docs/environment-maps.md describes the rules.
#pragma once

#include <penumbra/color.h>
#include <penumbra/image.h>
#include <penumbra/math.h>

#include <optional>
#include <string>
#include <string_view>

namespace penumbra::envmap {

enum class Mapping {
  /// Square image, Clarberg's equal-area octahedral map (equal_area.h); every texel covers
  /// 4 pi / (width height) steradians.
  EqualArea,
  /// Column u = phi / 2 pi, row v = theta / pi (row 0 is +z), w = (sin theta cos phi,
  /// sin theta sin phi, cos theta).
  Equirectangular,
};

/// "equalarea" or "equirectangular" (the names pbrt-v4's spherical camera uses for the same mappings).
const char* mapping_name(Mapping m);
std::optional<Mapping> parse_mapping(std::string_view name);

/// The mapping an image's shape implies when nothing says which: square -> equal area (pbrt-v4's
/// rule), exactly 2:1 -> equirectangular (a guess: pbrt-v4 refuses such images); anything else none.
std::optional<Mapping> mapping_from_shape(int width, int height);

/// Point of [0,1)^2 (u to the right, v down the rows) of a unit direction in light space.
Vec2 direction_to_uv(Mapping m, const Vec3& w);
/// Unit direction in light space of a point of [0,1]^2.
Vec3 uv_to_direction(Mapping m, Vec2 uv);

/// The texel containing uv (no filtering: the light's radiance is constant over each texel).
Rgb lookup_nearest(const ImageRgb& img, Vec2 uv);

/// Solid angle of one texel of row y (exact: 2 pi / w (cos theta_y - cos theta_y+1) for
/// equirectangular rows, 4 pi / (w h) for every equal-area texel).
double texel_solid_angle(Mapping m, int width, int height, int y);

/// Mean radiance over the sphere, (1 / 4 pi) * integral of L d(omega), exact for the piecewise-
/// constant image; in double.
struct RgbD {
  double r = 0.0, g = 0.0, b = 0.0;
};
RgbD sphere_mean(const ImageRgb& img, Mapping m);

/// Resamples an environment into another mapping (or size) by exact area weighting: each output
/// texel is the mean radiance over its solid angle of the input read as lookup_nearest() reads it,
/// i.e. the sum over the input texels it overlaps of radiance times overlap solid angle, over its own
/// solid angle. The overlaps are computed exactly (polygon clipping in the equal-area square, where
/// an equirectangular texel is a trapezoid in each octant), so a constant map stays constant and the
/// sphere mean is kept to rounding, even for a sun a few texels wide (docs/environment-maps.md).
ImageRgb resample(const ImageRgb& in, Mapping from, Mapping to, int width, int height);

/// The output size that keeps the texel count about equal: equal area -> N x N with N = round(sqrt(w h)),
/// equirectangular -> 2H x H with 2 H^2 about N^2.
std::pair<int, int> default_size(Mapping to, int in_width, int in_height);

}  // namespace penumbra::envmap
