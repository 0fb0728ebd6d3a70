// SampledWavelengths (penumbra/spectrum.h): wavelength sampling, the film's conversion and the
// upsampling of colours to smooth spectra (rgb_to_spectrum_table.h).
#include <penumbra/sampling.h>
#include <penumbra/spectrum.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "spectra/rgb_to_spectrum_table.h"
#include "spectra/spectrum.h"
#include "spectra/spectrum_tables.h"

namespace penumbra {

namespace {

constexpr int kFirst = static_cast<int>(spectra::kLambdaMin);
constexpr int kBins = static_cast<int>(spectra::kLambdaMax - spectra::kLambdaMin);  // 1 nm each

// Everything a wavelength needs, at 1 nm from 360 to 830 nm, linear in between.
struct Tables {
  std::vector<Vec3> cmf_over_y;  // cmf / integral D65 y: the film's weights
  std::vector<float> d65;        // D65, relative (100 at 560 nm)
  Distribution1D distribution;   // of x + y + z, one bin per nm

  Tables() : cmf_over_y(kBins + 1), d65(kBins + 1) {
    double y_d65 = spectra::spectrum_to_xyz(spectra::Spectrum({spectra::kLambdaMin, spectra::kLambdaMax}, {1.0, 1.0}),
                                            true).y;
    std::vector<float> f(kBins);
    for (int i = 0; i <= kBins; ++i) {
      glm::dvec3 c = spectra::cmf_at(kFirst + i);
      cmf_over_y[i] = Vec3(c / y_d65);
      d65[i] = static_cast<float>(spectra::d65()(kFirst + i));
    }
    for (int i = 0; i < kBins; ++i) {
      glm::dvec3 a = spectra::cmf_at(kFirst + i), b = spectra::cmf_at(kFirst + i + 1);
      f[i] = static_cast<float>(0.5 * (a.x + a.y + a.z + b.x + b.y + b.z));
    }
    distribution = Distribution1D(f);
  }
};

const Tables& tables() {
  static const Tables t;
  return t;
}

template <class T>
T lerp_at(const std::vector<T>& table, float lambda) {
  float x = std::clamp(lambda - kFirst, 0.f, static_cast<float>(kBins));
  int i = std::min(static_cast<int>(x), kBins - 1);
  float f = x - i;
  return (1.f - f) * table[i] + f * table[i + 1];
}

// The coefficients of a reflectance colour. Colours repeat from hit to hit (a material's constant, a
// light's emission), so each thread keeps the last colours it looked up, 16 slots chosen by a hash of
// the colour's bits: a repeated colour costs a compare instead of the table's trilinear lookup.
const spectra::SigmoidCoefficients& coefficients_of(const Rgb& rgb) {
  struct Entry {
    bool valid = false;
    Rgb rgb{0.f};
    spectra::SigmoidCoefficients c{};
  };
  thread_local Entry cache[16];
  uint32_t bits[3];
  std::memcpy(bits, &rgb, sizeof bits);
  uint32_t h = (bits[0] * 0x9E3779B1u) ^ (bits[1] * 0x85EBCA77u) ^ (bits[2] * 0xC2B2AE3Du);
  Entry& e = cache[h >> 28];
  if (!e.valid || e.rgb != rgb) {
    e.c = spectra::RgbToSpectrumTable::built_in()(rgb.r, rgb.g, rgb.b);
    e.rgb = rgb;
    e.valid = true;
  }
  return e.c;
}

}  // namespace

SampledWavelengths SampledWavelengths::sample(float u) {
  const Tables& t = tables();
  SampledWavelengths w;
  for (int i = 0; i < 3; ++i) {
    float ui = u + i / 3.f;
    if (ui >= 1.f) ui -= 1.f;
    float pdf_unit = 0.f;
    float x = t.distribution.sample_continuous(std::min(ui, OneMinusEpsilon), &pdf_unit);
    w.lambda_[i] = spectra::kLambdaMin + x * kBins;
    w.pdf_[i] = pdf_unit / kBins;
  }
  return w;
}

float SampledWavelengths::pdf(float lambda_nm) {
  if (!(lambda_nm >= spectra::kLambdaMin && lambda_nm < spectra::kLambdaMax)) return 0.f;
  const Tables& t = tables();
  size_t bin = std::min(static_cast<size_t>(lambda_nm - kFirst), static_cast<size_t>(kBins - 1));
  return t.distribution.discrete_pmf(bin);  // pmf of a 1 nm bin = density per nm
}

Rgb SampledWavelengths::to_rgb(const Rgb& L) const {
  const Tables& t = tables();
  Vec3 xyz(0.f);
  for (int i = 0; i < 3; ++i)
    if (pdf_[i] > 0.f) xyz += lerp_at(t.cmf_over_y, lambda_[i]) * (L[i] / (3.f * pdf_[i]));
  static const glm::mat3 m(spectra::xyz_to_rec709());
  return m * xyz;
}

Rgb SampledWavelengths::albedo(const Rgb& rgb) const {
  const spectra::SigmoidCoefficients& c = coefficients_of(rgb);
  return {spectra::sigmoid_spectrum(c, lambda_[0]), spectra::sigmoid_spectrum(c, lambda_[1]),
          spectra::sigmoid_spectrum(c, lambda_[2])};
}

Rgb SampledWavelengths::unbounded(const Rgb& rgb) const {
  float m = std::max(0.f, max_component(rgb));
  if (m == 0.f) return Rgb(0.f);
  float scale = 2.f * m;
  Rgb c = glm::max(rgb, Rgb(0.f)) / scale;
  return scale * albedo(c);
}

Rgb SampledWavelengths::illuminant(const Rgb& rgb) const {
  const Tables& t = tables();
  Rgb s = unbounded(rgb);
  return {s.x * lerp_at(t.d65, lambda_[0]), s.y * lerp_at(t.d65, lambda_[1]), s.z * lerp_at(t.d65, lambda_[2])};
}

}  // namespace penumbra
