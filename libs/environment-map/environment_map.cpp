#include "environment_map.h"

#include <penumbra/equal_area.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

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

constexpr double kPi = 3.14159265358979323846;

// A convex polygon in the equal-area square, clipped by Sutherland and Hodgman's algorithm.
using Polygon = std::vector<glm::dvec2>;

Polygon clip(const Polygon& poly, int axis, double bound, bool keep_below) {
  Polygon out;
  for (size_t k = 0; k < poly.size(); ++k) {
    const glm::dvec2 &p = poly[k], &q = poly[(k + 1) % poly.size()];
    bool p_in = keep_below ? p[axis] <= bound : p[axis] >= bound;
    bool q_in = keep_below ? q[axis] <= bound : q[axis] >= bound;
    if (p_in) out.push_back(p);
    if (p_in != q_in) out.push_back(p + (q - p) * ((bound - p[axis]) / (q[axis] - p[axis])));
  }
  return out;
}

double area(const Polygon& poly) {
  double twice = 0.0;
  for (size_t k = 0; k < poly.size(); ++k) {
    const glm::dvec2 &p = poly[k], &q = poly[(k + 1) % poly.size()];
    twice += p.x * q.y - q.x * p.y;
  }
  return 0.5 * std::abs(twice);
}

// Calls visit(equal_area_texel, solid_angle) for each texel of an n x n equal-area map that overlaps
// texel (x, y) of a w x h equirectangular map, with the solid angle of the overlap, exactly: within
// one octant (a quadrant of azimuth in one hemisphere) the equal-area map sends lines of constant
// azimuth and lines of constant theta to straight lines in the square (docs/environment-maps.md), so
// the texel's piece in each octant is a trapezoid, clipped against the equal-area texels it meets.
template <typename Visit>
void equirect_texel_in_equal_area(int x, int y, int w, int h, int n, Visit&& visit) {
  const double phi0 = 2.0 * kPi * x / w, phi1 = 2.0 * kPi * (x + 1) / w;
  const double theta0 = kPi * y / h, theta1 = kPi * (y + 1) / h;
  for (int quadrant = 0; quadrant < 4; ++quadrant) {
    double q0 = std::max(phi0, quadrant * kPi / 2), q1 = std::min(phi1, (quadrant + 1) * kPi / 2);
    if (q1 <= q0) continue;
    const double sx = (quadrant == 0 || quadrant == 3) ? 1.0 : -1.0, sy = quadrant < 2 ? 1.0 : -1.0;
    // Fraction of the quadrant's azimuth from the x axis towards the y axis, as the map measures it.
    auto t_of = [&](double phi) {
      double local = phi - quadrant * kPi / 2;
      return (quadrant % 2 == 0 ? local : kPi / 2 - local) / (kPi / 2);
    };
    for (int south = 0; south < 2; ++south) {
      double h0 = south ? std::max(theta0, kPi / 2) : theta0, h1 = south ? theta1 : std::min(theta1, kPi / 2);
      if (h1 <= h0) continue;
      auto corner = [&](double phi, double theta) {
        double t = t_of(phi);
        double r = std::sqrt(std::max(0.0, south ? 1.0 + std::cos(theta) : 1.0 - std::cos(theta)));
        double A = south ? 1.0 - t * r : (1.0 - t) * r, B = south ? 1.0 - (1.0 - t) * r : t * r;
        return glm::dvec2(0.5 * (1.0 + sx * A), 0.5 * (1.0 + sy * B));
      };
      Polygon piece{corner(q0, h0), corner(q1, h0), corner(q1, h1), corner(q0, h1)};
      glm::dvec2 lo = piece[0], hi = piece[0];
      for (const auto& p : piece) lo = glm::min(lo, p), hi = glm::max(hi, p);
      int cx0 = std::clamp(static_cast<int>(lo.x * n), 0, n - 1), cx1 = std::clamp(static_cast<int>(hi.x * n), 0, n - 1);
      int cy0 = std::clamp(static_cast<int>(lo.y * n), 0, n - 1), cy1 = std::clamp(static_cast<int>(hi.y * n), 0, n - 1);
      for (int cy = cy0; cy <= cy1; ++cy)
        for (int cx = cx0; cx <= cx1; ++cx) {
          Polygon p = clip(clip(piece, 0, double(cx) / n, false), 0, double(cx + 1) / n, true);
          p = clip(clip(p, 1, double(cy) / n, false), 1, double(cy + 1) / n, true);
          double a = p.size() >= 3 ? area(p) : 0.0;
          if (a > 0.0) visit(static_cast<size_t>(cy) * n + cx, 4.0 * kPi * a);
        }
    }
  }
}

// Overlap of [a0, a1] and [b0, b1].
double overlap(double a0, double a1, double b0, double b1) { return std::max(0.0, std::min(a1, b1) - std::max(a0, b0)); }

// Calls visit(out_texel, in_texel, solid_angle) for every pair of overlapping texels.
template <typename Visit>
void for_each_overlap(Mapping from, int in_w, int in_h, Mapping to, int out_w, int out_h, Visit&& visit) {
  if (from == Mapping::Equirectangular && to == Mapping::EqualArea) {
    for (int y = 0; y < in_h; ++y)
      for (int x = 0; x < in_w; ++x)
        equirect_texel_in_equal_area(x, y, in_w, in_h, out_w, [&](size_t o, double omega) {
          visit(o, static_cast<size_t>(y) * in_w + x, omega);
        });
  } else if (from == Mapping::EqualArea && to == Mapping::Equirectangular) {
    for (int y = 0; y < out_h; ++y)
      for (int x = 0; x < out_w; ++x)
        equirect_texel_in_equal_area(x, y, out_w, out_h, in_w, [&](size_t i, double omega) {
          visit(static_cast<size_t>(y) * out_w + x, i, omega);
        });
  } else {
    // The same mapping at another size: texels are rectangles in (u, v) for equal area, in
    // (phi, cos theta) for equirectangular, and solid angle is proportional to area there.
    auto row_edge = [&](int y, int h) { return from == Mapping::EqualArea ? double(y) / h : -std::cos(kPi * y / h); };
    double scale = from == Mapping::EqualArea ? 4.0 * kPi : 2.0 * kPi;
    for (int oy = 0; oy < out_h; ++oy)
      for (int iy = 0; iy < in_h; ++iy) {
        double dv = overlap(row_edge(oy, out_h), row_edge(oy + 1, out_h), row_edge(iy, in_h), row_edge(iy + 1, in_h));
        if (dv <= 0.0) continue;
        for (int ox = 0; ox < out_w; ++ox) {
          int ix0 = ox * in_w / out_w, ix1 = std::min(in_w - 1, ((ox + 1) * in_w + out_w - 1) / out_w);
          for (int ix = ix0; ix <= ix1; ++ix) {
            double du = overlap(double(ox) / out_w, double(ox + 1) / out_w, double(ix) / in_w, double(ix + 1) / in_w);
            if (du > 0.0) visit(static_cast<size_t>(oy) * out_w + ox, static_cast<size_t>(iy) * in_w + ix, scale * du * dv);
          }
        }
      }
  }
}

}  // namespace

ImageRgb resample(const ImageRgb& in, Mapping from, Mapping to, int width, int height) {
  std::vector<double> flux(3 * static_cast<size_t>(width) * height, 0.0);
  for_each_overlap(from, in.width, in.height, to, width, height, [&](size_t o, size_t i, double omega) {
    for (int c = 0; c < 3; ++c) flux[3 * o + c] += omega * in.pixels[3 * i + c];
  });
  ImageRgb out;
  out.width = width;
  out.height = height;
  out.pixels.resize(flux.size());
  for (int y = 0; y < height; ++y) {
    double omega = texel_solid_angle(to, width, height, y);
    for (size_t k = 3 * static_cast<size_t>(y) * width; k < 3 * static_cast<size_t>(y + 1) * width; ++k)
      out.pixels[k] = static_cast<float>(flux[k] / omega);
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
