#include "image/film_rgb.h"

#include <algorithm>

#include "image/image_io.h"

#include <penumbra/error.h>
#include <penumbra/sampling.h>

#include <fmt/core.h>

namespace penumbra {

static const ParamSpec kBoxParams[] = {
    {"float", "xradius", "0.5", "half width of the filter in pixels"},
    {"float", "yradius", "0.5", "half height of the filter in pixels"},
};
static const ParamSpec kTriangleParams[] = {
    {"float", "xradius", "2", "half width of the filter in pixels"},
    {"float", "yradius", "2", "half height of the filter in pixels"},
};
static const ParamSpec kGaussianParams[] = {
    {"float", "xradius", "1.5", "half width of the filter in pixels"},
    {"float", "yradius", "1.5", "half height of the filter in pixels"},
    {"float", "sigma", "0.5", "standard deviation in pixels"},
};
static const ParamSpec kFilmParams[] = {
    {"integer", "xresolution", "1280", "image width in pixels"},
    {"integer", "yresolution", "720", "image height in pixels"},
    {"string", "filename", "penumbra.exr", "output image (.exr, .hdr, .tif, .png)"},
    {"string[]", "aovs", "", "auxiliary outputs written as EXR layers: albedo, normal, depth, samples, "
                             "variance, nonfinite or all (names or comma-separated lists)"},
    {"bool", "spectral", "false", "spectral transport: three sampled wavelengths per pixel sample, colours as smooth "
                                   "spectra (docs/spectral.md)"},
    {"unsupported", "cropwindow", "", ""},
    {"unsupported", "pixelbounds", "", ""},
    {"unsupported", "diagonal", "", "Penumbra's film has no physical size"},
    {"unsupported", "iso", "", "Penumbra's film has no sensor model"},
    {"unsupported", "exposuretime", "", "Penumbra's film has no sensor model"},
    {"unsupported", "whitebalance", "", "Penumbra's film has no sensor model"},
    {"unsupported", "sensor", "", "Penumbra's film has no sensor model"},
    {"unsupported", "maxcomponentvalue", "", "Penumbra never clamps samples"},
    {"unsupported", "savefp16", "", "EXR files are written in 32-bit float"},
};

std::span<const ParamSpec> film_rgb_params() { return kFilmParams; }

std::span<const ParamSpec> pixel_filter_params(const std::string& type) {
  if (type == "box") return kBoxParams;
  if (type == "triangle") return kTriangleParams;
  if (type == "gaussian") return kGaussianParams;
  return {};
}

PixelFilter::PixelFilter(const std::string& type, const ParamSet& params, const FileLoc& loc)
    : type_(type), shape_(type == "box" ? Shape::Box : type == "triangle" ? Shape::Triangle : Shape::Gaussian) {
  if (pixel_filter_params(type).empty())
    throw Error(loc, fmt::format("unsupported pixel filter '{}'; available: box, gaussian, triangle", type));
  radius_ = Vec2(params.get_float("xradius"), params.get_float("yradius"));
  if (!(radius_.x > 0.f && radius_.y > 0.f && radius_.x < 64.f && radius_.y < 64.f))
    throw Error(loc, "filter radii must be in (0, 64) pixels");
  if (type == "gaussian") {
    sigma_ = params.get_float("sigma");
    if (!(sigma_ > 0.f)) throw Error(params.loc_of("sigma"), "sigma must be > 0");
    for (int axis = 0; axis < 2; ++axis) {
      gaussian_at_radius_[axis] = std::exp(-radius_[axis] * radius_[axis] / (2.f * sigma_ * sigma_));
      std::vector<float>& table = gaussian_table_[axis];
      table.resize(kGaussianIntervals + 1);
      for (int i = 0; i <= kGaussianIntervals; ++i)
        table[i] = eval_gaussian(radius_[axis] * (2.f * i / kGaussianIntervals - 1.f), axis);
      gaussian_scale_[axis] = kGaussianIntervals / (2.f * radius_[axis]);
      const int n = 4096;
      std::vector<float> f(n);
      for (int i = 0; i < n; ++i) f[i] = eval_gaussian(radius_[axis] * (2.f * (i + 0.5f) / n - 1.f), axis);
      Distribution1D fine(f);
      std::vector<float>& inv = inverse_cdf_[axis];
      inv.resize(kInverseSize + 1);
      for (int k = 0; k <= kInverseSize; ++k) {
        float pdf;
        float t = k == kInverseSize ? 1.f : fine.sample_continuous(static_cast<float>(k) / kInverseSize, &pdf);
        inv[k] = (2.f * t - 1.f) * radius_[axis];
      }
    }
  }
  for (int axis = 0; axis < 2; ++axis) {
    const float r = radius_[axis];
    if (type == "box") {
      integral_[axis] = 2.f * r;
    } else if (type == "triangle") {
      integral_[axis] = r * r;
    } else {  // the integral of the interpolated table: the trapezoid rule on its knots, exactly
      const std::vector<float>& table = gaussian_table_[axis];
      double sum = 0.5 * (table.front() + table.back());
      for (int i = 1; i < kGaussianIntervals; ++i) sum += table[i];
      integral_[axis] = static_cast<float>(sum * 2.0 * r / kGaussianIntervals);
    }
  }
}

float PixelFilter::evaluate_axis(float x, int axis) const {
  const float r = radius_[axis];
  if (!(std::abs(x) < r)) return 0.f;
  if (shape_ == Shape::Box) return 1.f;
  if (shape_ == Shape::Triangle) return r - std::abs(x);
  return gaussian(x, axis);
}

float PixelFilter::normalized(float x, int axis) const { return evaluate_axis(x, axis) / integral_[axis]; }

// The Gaussian shifted down to reach 0 at the radius (its value there is computed once).
float PixelFilter::eval_gaussian(float x, int axis) const {
  return std::max(0.f, std::exp(-x * x / (2.f * sigma_ * sigma_)) - gaussian_at_radius_[axis]);
}

// The Gaussian as the film uses it: the table of eval_gaussian() interpolated linearly, for |x| <= radius.
float PixelFilter::gaussian(float x, int axis) const {
  const std::vector<float>& table = gaussian_table_[axis];
  float t = (x + radius_[axis]) * gaussian_scale_[axis];
  int i = std::clamp(static_cast<int>(t), 0, kGaussianIntervals - 1);
  float f = t - static_cast<float>(i);
  return std::max(0.f, table[i] + f * (table[i + 1] - table[i]));
}

// Samples one axis of the separable filter; `weight` gets f(x)/pdf(x), up to a constant factor that
// cancels in the weighted pixel mean.
float PixelFilter::sample_axis(float u, int axis, float* weight) const {
  float r = radius_[axis];
  if (shape_ == Shape::Box) {
    *weight = 1.f;
    return (2.f * u - 1.f) * r;
  }
  if (shape_ == Shape::Triangle) {
    *weight = 1.f;
    return u < 0.5f ? -r + r * std::sqrt(2.f * u) : r - r * std::sqrt(2.f - 2.f * u);
  }
  const std::vector<float>& inv = inverse_cdf_[axis];
  float t = u * kInverseSize;
  int k = std::min(static_cast<int>(t), kInverseSize - 1);
  float width = inv[k + 1] - inv[k];
  float x = inv[k] + (t - k) * width;
  // pdf(x) = 1 / (kInverseSize * width) on this interval.
  *weight = gaussian(x, axis) * kInverseSize * width;
  return x;
}

FilterSample PixelFilter::sample(Vec2 u) const {
  float wx, wy;
  float x = sample_axis(u.x, 0, &wx);
  float y = sample_axis(u.y, 1, &wy);
  return FilterSample{Vec2(x, y), wx * wy};
}

uint64_t FilmRgb::estimated_bytes(Point2i resolution, const AovSet& aovs) {
  uint64_t pixels = static_cast<uint64_t>(std::max(resolution.x, 0)) * static_cast<uint64_t>(std::max(resolution.y, 0));
  // Accumulator, the beauty image, and the writer's interleaved buffer of every float channel.
  uint64_t per_pixel = sizeof(Pixel) + 3 * sizeof(float) + FilmAovs::bytes_per_pixel(aovs) + 3 * sizeof(float);
  return pixels * per_pixel;
}

FilmRgb::FilmRgb(Point2i resolution, PixelFilter filter, AovSet aovs)
    : resolution_(resolution), filter_(std::move(filter)),
      pixels_(static_cast<size_t>(resolution.x) * resolution.y), splats_(resolution) {
  if (aovs.any()) aovs_ = std::make_unique<FilmAovs>(resolution, aovs);
}

void FilmRgb::add_sample(Point2i pixel, const Rgb& L, float weight) {
  if (max_component(L) > firefly_threshold_) fireflies_.fetch_add(1, std::memory_order_relaxed);
  size_t i = static_cast<size_t>(pixel.y) * resolution_.x + pixel.x;
  Pixel& px = pixels_[i];
  for (int c = 0; c < 3; ++c) px.rgb[c] += static_cast<double>(weight) * L[c];
  px.weight += weight;
  if (aovs_) aovs_->add_sample(i, L, weight);
}

void FilmRgb::add_surface_sample(Point2i pixel, const SurfaceSample& s, float weight) {
  if (aovs_) aovs_->add_surface(static_cast<size_t>(pixel.y) * resolution_.x + pixel.x, s, weight);
}

void FilmRgb::add_nonfinite(Point2i pixel) {
  if (aovs_ && pixel.x >= 0 && pixel.y >= 0 && pixel.x < resolution_.x && pixel.y < resolution_.y)
    aovs_->add_nonfinite(static_cast<size_t>(pixel.y) * resolution_.x + pixel.x);
}

// A splat is filtered as a camera sample is: pixel j receives v h_j(p), with h_j the filter centred
// on j and normalised to integral 1 (pbrt-v4's RGBFilm::AddSplat weights by the filter the same way).
// Camera samples estimate the pixel's filtered radiance by the weighted mean, so both sides then
// measure the same integral; a splat put in one pixel only would be box filtered while the camera
// side is, e.g., Gaussian, and edges would differ between bidirectional and unidirectional images.
void FilmRgb::add_splat(const Vec2& p_raster, const Rgb& v) {
  if (max_component(v) > firefly_threshold_) fireflies_.fetch_add(1, std::memory_order_relaxed);
  if (filter_.single_pixel()) {
    int x = static_cast<int>(std::floor(p_raster.x)), y = static_cast<int>(std::floor(p_raster.y));
    if (x < 0 || y < 0 || x >= resolution_.x || y >= resolution_.y) return;
    splats_.add(x, y, v);
    return;
  }
  // Pixels whose centre (j + 0.5) is within the radius: |p - j - 0.5| < r.
  const Vec2 r = filter_.radius();
  const int x0 = std::max(0, static_cast<int>(std::floor(p_raster.x - 0.5f - r.x)) + 1);
  const int x1 = std::min(resolution_.x - 1, static_cast<int>(std::ceil(p_raster.x - 0.5f + r.x)) - 1);
  const int y0 = std::max(0, static_cast<int>(std::floor(p_raster.y - 0.5f - r.y)) + 1);
  const int y1 = std::min(resolution_.y - 1, static_cast<int>(std::ceil(p_raster.y - 0.5f + r.y)) - 1);
  // The filter is separable: the x weights once, then one row at a time (radii are below 64 pixels).
  float wx[130];
  for (int x = x0; x <= x1; ++x) wx[x - x0] = filter_.normalized(p_raster.x - (x + 0.5f), 0);
  for (int y = y0; y <= y1; ++y) {
    float wy = filter_.normalized(p_raster.y - (y + 0.5f), 1);
    if (wy == 0.f) continue;
    for (int x = x0; x <= x1; ++x) {
      float w = wy * wx[x - x0];
      if (w != 0.f) splats_.add(x, y, v * w);
    }
  }
}

ImageRgb FilmRgb::image(double splat_spp) const {
  ImageRgb img;
  img.width = resolution_.x;
  img.height = resolution_.y;
  img.pixels.resize(3 * pixels_.size());
  const bool splats = splats_.any() && splat_spp > 0.0;
  const std::vector<double> splat_sums = splats ? splats_.totals() : std::vector<double>();
  for (size_t i = 0; i < pixels_.size(); ++i) {
    const Pixel& px = pixels_[i];
    for (int c = 0; c < 3; ++c) {
      double v = px.weight != 0.0 ? px.rgb[c] / px.weight : 0.0;
      if (splats) v += splat_sums[3 * i + c] / splat_spp;
      img.pixels[3 * i + c] = static_cast<float>(v);
    }
  }
  return img;
}

void FilmRgb::save(StateWriter& out) const {
  out.vector(pixels_);
  splats_.save(out);
  out.value<uint64_t>(fireflies_.load());
  out.value<uint8_t>(aovs_ ? 1 : 0);
  if (aovs_) aovs_->save(out);
}

void FilmRgb::load(StateReader& in) {
  in.vector(pixels_, pixels_.size());
  splats_.load(in);
  fireflies_.store(in.value<uint64_t>());
  bool had_aovs = in.value<uint8_t>() != 0;
  if (had_aovs != static_cast<bool>(aovs_)) throw Error("the checkpoint's film has other AOVs than this render's");
  if (aovs_) aovs_->load(in);
}

}  // namespace penumbra
