#include "spectra/spectrum.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "spectra/spectrum_tables.h"

namespace penumbra::spectra {

// Colour-matching functions, linear between their 1 nm samples.
glm::dvec3 cmf_at(double lambda) {
  const CmfTable& t = kCmf;
  double x = lambda - t.first_lambda;
  if (x < 0.0 || x > t.count - 1) return glm::dvec3(0.0);
  int i = std::min(static_cast<int>(x), t.count - 2);
  double f = x - i;
  auto lerp = [&](const float* v) { return (1.0 - f) * v[i] + f * v[i + 1]; };
  return {lerp(t.x), lerp(t.y), lerp(t.z)};
}

namespace {

// Sorted union of the CMF grid and the breakpoints of s and w inside [360, 830].
std::vector<double> merged_breakpoints(const Spectrum& s, const Spectrum* w) {
  std::vector<double> b;
  for (double l = kLambdaMin; l <= kLambdaMax; l += 1.0) b.push_back(l);
  auto add = [&](const std::vector<double>& v) {
    for (double l : v)
      if (l > kLambdaMin && l < kLambdaMax) b.push_back(l);
  };
  add(s.breakpoints());
  if (w) add(w->breakpoints());
  std::sort(b.begin(), b.end());
  b.erase(std::unique(b.begin(), b.end()), b.end());
  return b;
}

}  // namespace

Spectrum::Spectrum(std::vector<double> lambda, std::vector<double> value)
    : lambda_(std::move(lambda)), value_(std::move(value)) {}

double planck(double lambda_nm, double kelvin) {
  if (kelvin <= 0.0) return 0.0;
  const double c = 299792458.0, h = 6.62606957e-34, kb = 1.3806488e-23;
  double l = lambda_nm * 1e-9;
  return (2.0 * h * c * c) / (std::pow(l, 5) * (std::exp((h * c) / (l * kb * kelvin)) - 1.0));
}

Spectrum Spectrum::blackbody(double kelvin) {
  Spectrum s;
  s.kelvin_ = kelvin;
  // Wien's displacement law gives the peak; pbrt-v4 divides by the radiance there.
  double peak_nm = 2.8977721e-3 / kelvin * 1e9;
  s.blackbody_peak_ = planck(peak_nm, kelvin);
  return s;
}

double Spectrum::operator()(double lambda) const {
  if (kelvin_ > 0.0) return planck(lambda, kelvin_) / blackbody_peak_;
  if (lambda_.empty() || lambda < lambda_.front() || lambda > lambda_.back()) return 0.0;
  auto it = std::upper_bound(lambda_.begin(), lambda_.end(), lambda);
  if (it == lambda_.end()) return value_.back();
  size_t i = static_cast<size_t>(it - lambda_.begin()) - 1;
  double t = (lambda - lambda_[i]) / (lambda_[i + 1] - lambda_[i]);
  return (1.0 - t) * value_[i] + t * value_[i + 1];
}

Spectrum Spectrum::scaled(double factor) const {
  Spectrum s = *this;
  if (kelvin_ > 0.0) {
    s.blackbody_peak_ /= factor;
  } else {
    for (double& v : s.value_) v *= factor;
  }
  return s;
}

// Between consecutive breakpoints every factor (S, W, each CMF) is linear, or smooth for a
// blackbody, so the integrand is a polynomial of degree at most 3 there and Simpson's rule on each
// interval is exact (for blackbodies its error is far below float precision at 1 nm spacing).
glm::dvec3 spectrum_to_xyz(const Spectrum& s, bool under_d65) {
  const Spectrum* w = under_d65 ? &d65() : nullptr;
  auto integrand = [&](double l) { return cmf_at(l) * (s(l) * (w ? (*w)(l) : 1.0)); };
  std::vector<double> b = merged_breakpoints(s, w);
  glm::dvec3 sum(0.0);
  for (size_t i = 0; i + 1 < b.size(); ++i) {
    // The ends are taken just inside the interval: a tabulated spectrum jumps to 0 where its
    // samples end, and the interval must see its one-sided limit there.
    double a = b[i], c = b[i + 1], e = 1e-9 * (c - a);
    sum += (c - a) / 6.0 * (integrand(a + e) + 4.0 * integrand(0.5 * (a + c)) + integrand(c - e));
  }
  return sum;
}

glm::dmat3 xyz_to_rec709() {
  static const glm::dmat3 m = [] {
    glm::dvec3 white = spectrum_to_xyz(Spectrum({kLambdaMin, kLambdaMax}, {1.0, 1.0}), true);
    white /= white.y;
    // Rec.709 / sRGB primaries (ITU-R BT.709).
    const double xy[3][2] = {{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}};
    glm::dmat3 primaries;  // columns: XYZ of each primary with Y = 1
    for (int c = 0; c < 3; ++c)
      primaries[c] = glm::dvec3(xy[c][0] / xy[c][1], 1.0, (1.0 - xy[c][0] - xy[c][1]) / xy[c][1]);
    glm::dvec3 scale = glm::inverse(primaries) * white;  // so that RGB (1, 1, 1) is the white
    glm::dmat3 rgb_to_xyz = primaries;
    for (int c = 0; c < 3; ++c) rgb_to_xyz[c] *= scale[c];
    return glm::inverse(rgb_to_xyz);
  }();
  return m;
}

Rgb reflectance_to_rgb(const Spectrum& s) {
  static const double white_y = spectrum_to_xyz(Spectrum({kLambdaMin, kLambdaMax}, {1.0, 1.0}), true).y;
  return Rgb(xyz_to_rec709() * (spectrum_to_xyz(s, true) / white_y));
}

Rgb emission_to_rgb(const Spectrum& s) {
  glm::dvec3 xyz = spectrum_to_xyz(s, false);
  if (!(xyz.y > 0.0)) return Rgb(0.f);
  return Rgb(xyz_to_rec709() * (xyz / xyz.y));
}

const Spectrum& d65() {
  static const Spectrum s = [] {
    const TabulatedSpectrum* t = kNamedTables;
    while (std::strcmp(t->name, "stdillum-D65") != 0) ++t;  // always present (data/spectra)
    std::vector<double> l(t->lambda, t->lambda + t->count), v(t->value, t->value + t->count);
    return Spectrum(std::move(l), std::move(v));
  }();
  return s;
}

}  // namespace penumbra::spectra
