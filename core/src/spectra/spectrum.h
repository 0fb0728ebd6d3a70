// Spectra in an RGB renderer: pbrt-v4 scenes give reflectances, indices of refraction and emission
// as spectra (named measured tables, (lambda, value) pairs, .spd files, blackbodies). Penumbra
// renders in linear Rec.709 RGB, so each spectrum becomes one RGB triple when the scene is read, by
// integrating it against the CIE 1931 2-degree colour-matching functions:
//
//   reflectance-like (materials, textures: reflectance, eta, k, ...):
//     RGB = M * integral S(l) W(l) cmf(l) dl / integral W(l) y(l) dl,  W = CIE illuminant D65
//     the colour of S lit by the reference white, so a constant spectrum c gives (c, c, c);
//   emission (LightSource, AreaLightSource):
//     RGB = M * integral S(l) cmf(l) dl / integral S(l) y(l) dl
//     the colour of S at luminance 1, which is what pbrt-v4's photometric normalisation of light
//     spectra makes of it (an "rgb L" emits as given: pbrt-v4's RGB-illuminant round trip).
//
// M is the XYZ -> linear Rec.709 matrix built from the Rec.709 primaries and the white point of the
// tabulated D65 itself, so D65 maps to (1, 1, 1) exactly. Integrals are exact for the piecewise
// linear functions involved (see spectrum.cpp). docs/scene-format.md states the rules for users.
#pragma once

#include <penumbra/color.h>

#include <glm/glm.hpp>

#include <string>
#include <vector>

namespace penumbra::spectra {

/// Shortest and longest wavelength of the colour-matching functions (nm).
constexpr double kLambdaMin = 360.0, kLambdaMax = 830.0;

/// A spectrum piecewise linear between its samples and zero outside them (pbrt-v4's meaning of
/// tabulated spectra), or a blackbody.
class Spectrum {
 public:
  /// From (lambda, value) samples; lambdas must increase strictly (checked by the callers that
  /// read user input).
  Spectrum(std::vector<double> lambda, std::vector<double> value);
  /// Planck's law at temperature T (kelvin), normalised to 1 at its peak as pbrt-v4 does.
  static Spectrum blackbody(double kelvin);

  double operator()(double lambda) const;
  /// Wavelengths where the spectrum has a kink (its samples), for exact integration.
  const std::vector<double>& breakpoints() const { return lambda_; }
  /// Scales the values (used to normalise illuminants to luminance 1).
  Spectrum scaled(double factor) const;

 private:
  Spectrum() = default;
  std::vector<double> lambda_, value_;
  double kelvin_ = 0.0;  // > 0: a blackbody; lambda_ then holds a dense grid of breakpoints
  double blackbody_peak_ = 1.0;
};

/// The CIE 1931 2-degree colour-matching functions (x, y, z) at `lambda` nm, linear between their
/// 1 nm samples, zero outside [360, 830].
glm::dvec3 cmf_at(double lambda);

/// Planck's law: spectral radiance of a blackbody at `lambda_nm` and `kelvin`, in W / (m^2 sr m).
double planck(double lambda_nm, double kelvin);

/// integral S(l) W(l) {x,y,z}(l) dl over [360, 830] nm with W = 1 (emission) or W = D65.
glm::dvec3 spectrum_to_xyz(const Spectrum& s, bool under_d65);

/// XYZ -> linear Rec.709 (white point of the tabulated D65).
glm::dmat3 xyz_to_rec709();

/// The two conversions described at the top of this file.
Rgb reflectance_to_rgb(const Spectrum& s);
Rgb emission_to_rgb(const Spectrum& s);

/// CIE standard illuminant D65 as tabulated in data/spectra (relative power, 100 at 560 nm).
const Spectrum& d65();

}  // namespace penumbra::spectra
