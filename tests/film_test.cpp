// The film: filter importance sampling reproduces each filter's shape, accumulation is a weighted
// mean, and splats from many threads add up exactly.
#include "image/film_rgb.h"
#include "image/image_io.h"

#include <penumbra/rng.h>

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>
#include <vector>

using namespace penumbra;

namespace {

// A filter with its default parameters.
PixelFilter make_filter(const std::string& type) {
  ParamSet p;
  p.validate(pixel_filter_params(type), "filter");
  return PixelFilter(type, p, {});
}

// Weighted second moment of the sampled offsets, E_w[x^2] = sum w x^2 / sum w, equals the filter's
// own second moment int f x^2 / int f (computed by quadrature).
double weighted_second_moment(const PixelFilter& f, int n) {
  Pcg32 rng(1, 2);
  double wx2 = 0, w = 0;
  for (int i = 0; i < n; ++i) {
    FilterSample s = f.sample(Vec2(rng.next_float(), rng.next_float()));
    EXPECT_LE(std::abs(s.offset.x), f.radius().x);
    EXPECT_LE(std::abs(s.offset.y), f.radius().y);
    wx2 += s.weight * s.offset.x * s.offset.x;
    w += s.weight;
  }
  return wx2 / w;
}

template <typename F>
double quadrature_second_moment(F f, float r) {
  double num = 0, den = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    double x = -r + (i + 0.5) * 2.0 * r / n;
    num += f(x) * x * x;
    den += f(x);
  }
  return num / den;
}

}  // namespace

TEST(PixelFilter, BoxSamplesMatchUniformMoment) {
  PixelFilter f = make_filter("box");
  EXPECT_NEAR(weighted_second_moment(f, 200000), 0.25 / 3.0, 2e-3);
}

TEST(PixelFilter, TriangleSamplesMatchTentMoment) {
  PixelFilter f = make_filter("triangle");
  double expected = quadrature_second_moment([](double x) { return std::max(0.0, 2.0 - std::abs(x)); }, 2.f);
  EXPECT_NEAR(weighted_second_moment(f, 200000), expected, 0.01 * expected);
}

TEST(PixelFilter, GaussianSamplesMatchTruncatedGaussianMoment) {
  PixelFilter f = make_filter("gaussian");
  auto g = [](double x) {
    auto e = [](double t) { return std::exp(-t * t / (2 * 0.25)); };
    return std::max(0.0, e(x) - e(1.5));
  };
  double expected = quadrature_second_moment(g, 1.5f);
  EXPECT_NEAR(weighted_second_moment(f, 200000), expected, 0.01 * expected);
}

// The film's Gaussian is a table interpolated linearly (no exp() per sample): its normalised values
// stay within 1e-5 of the exact shifted Gaussian's (peak about 0.8) at default parameters, where a
// sigma 1 % off moves them by more than 1e-3 (the negative control).
TEST(PixelFilter, GaussianTableFollowsTheShiftedGaussian) {
  PixelFilter f = make_filter("gaussian");
  auto normalized_exact = [](double sigma) {
    auto e = [sigma](double t) { return std::exp(-t * t / (2 * sigma * sigma)); };
    auto g = [e](double x) { return std::max(0.0, e(x) - e(1.5)); };
    double integral = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) integral += g(-1.5 + (i + 0.5) * 3.0 / n) * 3.0 / n;
    return [g, integral](double x) { return g(x) / integral; };
  };
  auto exact = normalized_exact(0.5), off = normalized_exact(0.505);
  double worst = 0, worst_off = 0;
  for (int i = 0; i <= 30000; ++i) {
    double x = -1.5 + 3.0 * i / 30000;
    worst = std::max(worst, std::abs(f.normalized(static_cast<float>(x), 0) - exact(x)));
    worst_off = std::max(worst_off, std::abs(off(x) - exact(x)));
  }
  EXPECT_LT(worst, 1e-5);
  EXPECT_GT(worst_off, 1e-3);
}

TEST(PixelFilter, UnknownFilterIsAnError) {
  EXPECT_THROW(PixelFilter("mitchell", ParamSet{}, {}), Error);
}

TEST(FilmRgb, PixelIsWeightedMeanOfItsSamples) {
  FilmRgb film(Point2i(2, 1), make_filter("box"));
  film.add_sample(Point2i(0, 0), Rgb(1, 2, 3), 1.f);
  film.add_sample(Point2i(0, 0), Rgb(3, 2, 1), 3.f);
  ImageRgb img = film.image(1.0);
  EXPECT_FLOAT_EQ(img.pixels[0], 2.5f);
  EXPECT_FLOAT_EQ(img.pixels[1], 2.f);
  EXPECT_FLOAT_EQ(img.pixels[2], 1.5f);
  EXPECT_FLOAT_EQ(img.pixels[3], 0.f);  // a pixel with no samples is black, not NaN
  EXPECT_FALSE(film.has_splats());      // the splat buffer exists only once something splats
}

TEST(FilmRgb, ConcurrentSplatsAddUpExactly) {
  FilmRgb film(Point2i(4, 4), make_filter("box"));
  const int n = 400000;
  tbb::parallel_for(0, n, [&](int i) { film.add_splat(Vec2(i % 4 + 0.5f, (i / 4) % 4 + 0.5f), Rgb(1.f, 0.5f, 0.25f)); });
  film.add_splat(Vec2(-1.f, 2.f), Rgb(100.f));  // outside: ignored
  ImageRgb img = film.image(n / 16.0);
  ASSERT_TRUE(film.has_splats());
  for (int i = 0; i < 16; ++i) {
    EXPECT_DOUBLE_EQ(img.pixels[3 * i], 1.0);
    EXPECT_DOUBLE_EQ(img.pixels[3 * i + 1], 0.5);
    EXPECT_DOUBLE_EQ(img.pixels[3 * i + 2], 0.25);
  }
}

// Splats are summed in per-thread 128-bit fixed point: the image is the same bit for bit whatever
// the order of the additions and the threads that made them, for values over 12 orders of magnitude
// (a double sum of the same values in another order differs in its last bits). Values beyond the
// fixed-point range are refused, not wrapped.
TEST(FilmRgb, SplatSumsDoNotDependOnOrderOrThreads) {
  const int n = 200000;
  std::vector<std::pair<Vec2, Rgb>> splats(n);
  uint64_t state = 12345;
  auto next = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<float>((state >> 40) * 0x1p-24);
  };
  for (auto& [p, v] : splats) {
    p = Vec2(8.f * next(), 8.f * next());
    float magnitude = std::pow(10.f, 12.f * next() - 6.f);  // 1e-6 .. 1e6
    v = Rgb(magnitude * next(), magnitude, magnitude * (next() - 0.5f));
  }
  FilmRgb serial(Point2i(8, 8), make_filter("box")), reversed(Point2i(8, 8), make_filter("box")),
      parallel(Point2i(8, 8), make_filter("box"));
  for (const auto& [p, v] : splats) serial.add_splat(p, v);
  for (auto it = splats.rbegin(); it != splats.rend(); ++it) reversed.add_splat(it->first, it->second);
  tbb::parallel_for(0, n, [&](int i) { parallel.add_splat(splats[i].first, splats[i].second); });
  ImageRgb a = serial.image(1.0), b = reversed.image(1.0), c = parallel.image(1.0);
  EXPECT_EQ(a.pixels, b.pixels);
  EXPECT_EQ(a.pixels, c.pixels);
  // The fixed-point sum is the exact sum to within the 2^-40 resolution per splat.
  std::vector<double> exact(3 * 64, 0.0);
  for (const auto& [p, v] : splats) {
    size_t i = static_cast<size_t>(static_cast<int>(p.y)) * 8 + static_cast<int>(p.x);
    for (int k = 0; k < 3; ++k) exact[3 * i + k] += static_cast<double>(v[k]);
  }
  for (size_t i = 0; i < exact.size(); ++i)
    EXPECT_NEAR(a.pixels[i], exact[i], 1e-6 * std::abs(exact[i]) + 1e-7) << i;

  SplatBuffers buffers(Point2i(2, 2));
  EXPECT_FALSE(buffers.add(0, 0, Rgb(1e30f, 0.f, 0.f)));
  EXPECT_FALSE(buffers.add(0, 0, Rgb(std::numeric_limits<float>::quiet_NaN(), 0.f, 0.f)));
  EXPECT_TRUE(buffers.add(1, 1, Rgb(1e20f, -1e20f, 1e-20f)));
  std::vector<double> t = buffers.totals();
  EXPECT_DOUBLE_EQ(t[0], 0.0);
  EXPECT_NEAR(t[9], 1e20, 1e20 * 1e-7);
  EXPECT_NEAR(t[10], -1e20, 1e20 * 1e-7);
}

// Splats are filtered as camera samples are (issue 13 found bdpt's edges sharper than path's under
// the Gaussian filter: its light-traced part went to one pixel each). With splats at uniformly random
// film positions carrying L(p) (an edge across the film), every pixel away from the border must
// measure the integral of L against its own normalised filter, computed here by quadrature with the
// filters written out independently. Negative control: the same splats put into one pixel each (the
// old behaviour) miss that integral at the edge pixels for every filter but the 0.5-pixel box.
namespace {

double reference_filter(const std::string& type, float r, double x) {
  if (std::abs(x) >= r) return 0.0;
  if (type == "box") return 1.0 / (2.0 * r);
  if (type == "triangle") return (r - std::abs(x)) / (r * r);
  auto e = [](double t) { return std::exp(-t * t / (2 * 0.25)); };
  static const double integral = [&] {  // the truncated Gaussian's (sigma 0.5) by the midpoint rule
    const int n = 20000;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) sum += std::max(0.0, e(-r + (i + 0.5) * 2.0 * r / n) - e(r));
    return sum * 2.0 * r / n;
  }();
  return std::max(0.0, e(x) - e(r)) / integral;
}

double edge_radiance(double x, double y) { return x + 0.35 * y < 5.3 ? 1.0 : 0.2; }

}  // namespace

TEST(FilmRgb, SplatsAreFilteredAsCameraSamples) {
  const int res = 12, m = 1000000;
  const double area = res * res;
  struct Case {
    std::string type;
    float radius;
  };
  for (const Case& c : {Case{"box", 0.5f}, Case{"box", 1.f}, Case{"triangle", 2.f}, Case{"gaussian", 1.5f}}) {
    ParamSet p;
    if (c.type != "gaussian") {
      for (const char* name : {"xradius", "yradius"}) {
        Param r;
        r.type = "float";
        r.name = name;
        r.numbers = {c.radius};
        p.add(r);
      }
    }
    p.validate(pixel_filter_params(c.type), "filter");
    FilmRgb film(Point2i(res, res), PixelFilter(c.type, p, {}));
    std::vector<double> single_pixel(res * res, 0.0);
    Pcg32 rng(7, 11);
    for (int i = 0; i < m; ++i) {
      Vec2 pos(res * rng.next_float(), res * rng.next_float());
      float L = static_cast<float>(edge_radiance(pos.x, pos.y));
      film.add_splat(pos, Rgb(L));
      single_pixel[static_cast<int>(pos.y) * res + static_cast<int>(pos.x)] += L;
    }
    ImageRgb img = film.image(m / area);
    // Per pixel: E[X] and E[X^2] of X = area h_j(p) L(p), p uniform, by a 200 x 200 midpoint grid over
    // the filter's support.
    const int border = static_cast<int>(std::ceil(c.radius));
    int failures = 0, control_failures = 0, edge_pixels = 0;
    for (int y = border; y < res - border; ++y)
      for (int x = border; x < res - border; ++x) {
        const int n = 200;
        double mean = 0.0, second = 0.0, cell = 2.0 * c.radius / n;
        for (int iy = 0; iy < n; ++iy)
          for (int ix = 0; ix < n; ++ix) {
            double dx = -c.radius + (ix + 0.5) * cell, dy = -c.radius + (iy + 0.5) * cell;
            double h = reference_filter(c.type, c.radius, dx) * reference_filter(c.type, c.radius, dy);
            double L = edge_radiance(x + 0.5 + dx, y + 0.5 + dy);
            mean += h * L * cell * cell;
            second += area * h * h * L * L * cell * cell;
          }
        double se = std::sqrt(std::max(second - mean * mean, 1e-12) / m);
        double got = img.pixels[3 * (y * res + x) + 1];
        double old = single_pixel[y * res + x] / (m / area);
        if (std::abs(got - mean) > 4.5 * se) ++failures;
        if (std::abs(old - mean) > 4.5 * se) ++control_failures;
        if (mean > 0.25 && mean < 0.95) ++edge_pixels;
        EXPECT_NEAR(got, mean, 4.5 * se) << c.type << " r " << c.radius << " pixel " << x << "," << y;
      }
    std::printf("  [%s r=%.1f] pixels off by > 4.5 SE: filtered %d, one pixel per splat %d (%d pixels on the edge)\n",
                c.type.c_str(), c.radius, failures, control_failures, edge_pixels);
    if (c.type == "box" && c.radius == 0.5f)
      EXPECT_EQ(control_failures, 0);  // the two are the same rule
    else
      EXPECT_GE(control_failures, 3) << c.type;  // the old rule is visibly wrong at the edge
  }
}
