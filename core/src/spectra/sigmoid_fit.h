// Smooth reflectance spectra for RGB colours (spectral transport, docs/spectral.md).
//
// A reflectance in [0, 1]^3 becomes the spectrum s(l) = S(c0 t^2 + c1 t + c2), with
// t = (l - 360 nm) / 470 nm in [0, 1] and S(x) = 1/2 + x / (2 sqrt(1 + x^2)) (Jakob and Hanika,
// "A Low-Dimensional Function Space for Efficient Spectral Upsampling", 2019): bounded in (0, 1),
// smooth, and three numbers per colour. The coefficients are chosen so that the spectrum lit by
// D65 has the given colour (the reflectance_to_rgb() rule of spectrum.h): Gauss-Newton on the
// CIELAB difference, starting from a neighbour's solution.
//
// Fitting is slow (microseconds per colour), so the build fits a table once
// (make_rgb_to_spectrum_table, rgb_to_spectrum.h reads it); this header is the fitter itself.
#pragma once

#include <glm/glm.hpp>

#include <array>

namespace penumbra::spectra {

using SigmoidCoefficients = std::array<float, 3>;

/// S(c0 t^2 + c1 t + c2) at wavelength `lambda_nm`; +-infinite polynomials give 1 or 0.
float sigmoid_spectrum(const SigmoidCoefficients& c, float lambda_nm);

/// Linear Rec.709 colour of the sigmoid spectrum lit by D65 (white (1, 1, 1) for s = 1), from the
/// fitter's quadrature (1 nm steps over 360..830 nm).
glm::dvec3 sigmoid_spectrum_rgb(const SigmoidCoefficients& c);

/// Coefficients whose spectrum has colour `rgb` (each channel in [0, 1]), starting from `guess`.
/// Returns the CIELAB distance reached (below 1e-3 for every colour of the table's grid).
double fit_sigmoid(const glm::dvec3& rgb, SigmoidCoefficients& coefficients);

/// The constant spectrum v (c0 = c1 = 0), exact; v = 0 and v = 1 give infinite c2.
SigmoidCoefficients constant_sigmoid(float v);

}  // namespace penumbra::spectra
