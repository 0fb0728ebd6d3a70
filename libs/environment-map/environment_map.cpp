#include "environment_map.h"

#include "equal_area.h"

#include <cmath>

namespace penumbra::envmap {

const char* mapping_name(Mapping m) { return m == Mapping::EqualArea ? "equalarea" : "equirectangular"; }

std::optional<Mapping> parse_mapping(std::string_view name) {
  if (name == "equalarea") return Mapping::EqualArea;
  if (name == "equirectangular") return Mapping::Equirectangular;
  return std::nullopt;
}

std::optional<Mapping> mapping_from_shape(int width, int height) {
  if (width == height) return Mapping::EqualArea;
  if (width == 2 * height) return Mapping::Equirectangular;
  return std::nullopt;
}

Vec2 direction_to_uv(Mapping m, const Vec3& w) {
  Vec2 uv;
  if (m == Mapping::EqualArea) {
    uv = equal_area_sphere_to_square(w);
  } else {
    float theta = std::acos(std::clamp(w.z, -1.f, 1.f));
    float phi = std::atan2(w.y, w.x);
    if (phi < 0.f) phi += 2.f * Pi;
    uv = Vec2(phi * Inv2Pi, theta * InvPi);
  }
  return Vec2(std::clamp(uv.x, 0.f, OneMinusEpsilon), std::clamp(uv.y, 0.f, OneMinusEpsilon));
}

Vec3 uv_to_direction(Mapping m, Vec2 uv) {
  if (m == Mapping::EqualArea) return equal_area_square_to_sphere(uv);
  float theta = uv.y * Pi, phi = uv.x * 2.f * Pi;
  float sin_theta = std::sin(theta);
  return Vec3(sin_theta * std::cos(phi), sin_theta * std::sin(phi), std::cos(theta));
}

Rgb lookup_nearest(const ImageRgb& img, Vec2 uv) {
  int x = std::clamp(static_cast<int>(uv.x * img.width), 0, img.width - 1);
  int y = std::clamp(static_cast<int>(uv.y * img.height), 0, img.height - 1);
  const float* p = &img.pixels[3 * (static_cast<size_t>(y) * img.width + x)];
  return Rgb(p[0], p[1], p[2]);
}

double texel_solid_angle(Mapping m, int width, int height, int y) {
  constexpr double pi = 3.14159265358979323846;
  if (m == Mapping::EqualArea) return 4.0 * pi / (static_cast<double>(width) * height);
  double theta0 = pi * y / height, theta1 = pi * (y + 1) / height;
  return 2.0 * pi / width * (std::cos(theta0) - std::cos(theta1));
}

RgbD sphere_mean(const ImageRgb& img, Mapping m) {
  RgbD sum;
  for (int y = 0; y < img.height; ++y) {
    double row[3] = {0.0, 0.0, 0.0};
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < 3; ++c) row[c] += img.pixels[3 * (static_cast<size_t>(y) * img.width + x) + c];
    double omega = texel_solid_angle(m, img.width, img.height, y);
    sum.r += row[0] * omega;
    sum.g += row[1] * omega;
    sum.b += row[2] * omega;
  }
  constexpr double four_pi = 4.0 * 3.14159265358979323846;
  return RgbD{sum.r / four_pi, sum.g / four_pi, sum.b / four_pi};
}

namespace {

// The input texel each of the n x n points of an output texel falls in, with the point's share of
// the output texel's solid angle (equal for equal-area output, proportional to sin theta for
// equirectangular output). Calls visit(input_texel_index, solid_angle).
template <typename Visit>
void for_each_point(const ImageRgb& in, Mapping from, Mapping to, int width, int height, int x, int y, int n,
                    Visit&& visit) {
  double omega = texel_solid_angle(to, width, height, y);
  double row_weights = 0.0;
  for (int j = 0; j < n; ++j) row_weights += to == Mapping::EqualArea ? 1.0 : std::sin(Pi * (y + (j + 0.5f) / n) / height);
  for (int j = 0; j < n; ++j) {
    float v = (y + (j + 0.5f) / n) / height;
    double w = omega / n * ((to == Mapping::EqualArea ? 1.0 : std::sin(Pi * v)) / row_weights);
    for (int i = 0; i < n; ++i) {
      Vec2 uv((x + (i + 0.5f) / n) / width, v);
      Vec2 src = direction_to_uv(from, uv_to_direction(to, uv));
      int sx = std::clamp(static_cast<int>(src.x * in.width), 0, in.width - 1);
      int sy = std::clamp(static_cast<int>(src.y * in.height), 0, in.height - 1);
      visit(static_cast<size_t>(sy) * in.width + sx, w);
    }
  }
}

}  // namespace

ImageRgb resample(const ImageRgb& in, Mapping from, Mapping to, int width, int height, int supersample) {
  const int n = std::max(1, supersample);
  // Pass 1: the solid angle the output's points give each input texel. Point sampling gets a small
  // texel's share wrong by up to a point's footprint, which for a sun a few texels wide is a percent
  // of the whole map's flux; pass 2 therefore scales each input texel's contributions by its true
  // solid angle over the one it received, so that every input texel hands on exactly its flux.
  std::vector<double> received(static_cast<size_t>(in.width) * in.height, 0.0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for_each_point(in, from, to, width, height, x, y, n, [&](size_t i, double w) { received[i] += w; });

  std::vector<double> flux(3 * static_cast<size_t>(width) * height, 0.0);
  auto texel = [&](size_t i) { return &in.pixels[3 * i]; };
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      double* f = &flux[3 * (static_cast<size_t>(y) * width + x)];
      for_each_point(in, from, to, width, height, x, y, n, [&](size_t i, double w) {
        double share = w * texel_solid_angle(from, in.width, in.height, static_cast<int>(i / in.width)) / received[i];
        for (int c = 0; c < 3; ++c) f[c] += share * texel(i)[c];
      });
    }
  // Input texels no point reached (tiny equirectangular texels at a pole, under coarse sampling)
  // hand their flux to the output texel around their centre.
  for (int sy = 0; sy < in.height; ++sy)
    for (int sx = 0; sx < in.width; ++sx) {
      size_t i = static_cast<size_t>(sy) * in.width + sx;
      if (received[i] > 0.0) continue;
      Vec2 uv = direction_to_uv(to, uv_to_direction(from, Vec2((sx + 0.5f) / in.width, (sy + 0.5f) / in.height)));
      int x = std::clamp(static_cast<int>(uv.x * width), 0, width - 1);
      int y = std::clamp(static_cast<int>(uv.y * height), 0, height - 1);
      double omega = texel_solid_angle(from, in.width, in.height, sy);
      for (int c = 0; c < 3; ++c) flux[3 * (static_cast<size_t>(y) * width + x) + c] += omega * texel(i)[c];
    }

  ImageRgb out;
  out.width = width;
  out.height = height;
  out.pixels.resize(flux.size());
  for (int y = 0; y < height; ++y) {
    double omega = texel_solid_angle(to, width, height, y);
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c) {
        size_t k = 3 * (static_cast<size_t>(y) * width + x) + c;
        out.pixels[k] = static_cast<float>(flux[k] / omega);
      }
  }
  return out;
}

std::pair<int, int> default_size(Mapping to, int in_width, int in_height) {
  double texels = static_cast<double>(in_width) * in_height;
  if (to == Mapping::EqualArea) {
    int n = std::max(1, static_cast<int>(std::lround(std::sqrt(texels))));
    return {n, n};
  }
  int h = std::max(1, static_cast<int>(std::lround(std::sqrt(texels / 2.0))));
  return {2 * h, h};
}

}  // namespace penumbra::envmap
