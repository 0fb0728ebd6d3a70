// Spectral transport (docs/spectral.md). Penumbra's colours are linear Rec.709 RGB. In a spectral
// render each pixel sample instead carries three wavelengths, and every Rgb along its path holds
// the values of the spectrum at those three wavelengths (.x at lambda[0], ...): reflectances,
// throughputs and radiance multiply per wavelength, as a spectral renderer multiplies spectra, and
// the film turns the three values back into a colour. Scene colours become smooth spectra with the
// same colour (a reflectance lit by D65, an emission at D65's white point), as pbrt-v4 makes them.
//
// Plugins meet this only through SampledWavelengths: the render loop hands one to each pixel
// sample (PixelSample::wavelengths, null in an RGB render), textures see it in TextureEvalContext
// (TexturedRgb converts on evaluation), and integrators convert what lights emit with
// emission_at() (which calls illuminant() when there are wavelengths).
#pragma once

#include <penumbra/color.h>
#include <penumbra/math.h>

namespace penumbra {

class SampledWavelengths {
 public:
  /// Three wavelengths in [360, 830] nm from one uniform number: u, u + 1/3 and u + 2/3 (mod 1)
  /// through the inverse distribution of x + y + z (CIE 1931), so each is distributed with pdf().
  static SampledWavelengths sample(float u);
  /// Density (per nm) with which sample() draws each wavelength.
  static float pdf(float lambda_nm);

  float lambda(int i) const { return lambda_[i]; }

  /// The colour (linear Rec.709) of spectral radiance `L` given at these wavelengths: the
  /// one-sample estimate of M * integral L(l) cmf(l) dl / integral D65(l) y(l) dl, so that
  /// illuminant(c) averages to c over wavelengths.
  Rgb to_rgb(const Rgb& L) const;

  /// A reflectance-like colour (clamped to [0, 1]) as its smooth spectrum at these wavelengths.
  Rgb albedo(const Rgb& rgb) const;
  /// An unbounded non-negative quantity (index of refraction, absorption, scale): the smooth
  /// spectrum of rgb / (2 max) times 2 max.
  Rgb unbounded(const Rgb& rgb) const;
  /// Emitted radiance of colour `rgb`: unbounded(rgb) times D65 (relative, 100 at 560 nm).
  Rgb illuminant(const Rgb& rgb) const;

 private:
  float lambda_[3] = {0.f, 0.f, 0.f};
  float pdf_[3] = {0.f, 0.f, 0.f};
};

/// What a light emits (RGB radiance or intensity, as Light returns it) as the transport carries it:
/// its illuminant spectrum at `wavelengths` in a spectral render, the RGB itself when they are null.
/// Integrators call this wherever emission enters a path.
inline Rgb emission_at(const SampledWavelengths* wavelengths, const Rgb& Le) {
  return wavelengths ? wavelengths->illuminant(Le) : Le;
}

}  // namespace penumbra
