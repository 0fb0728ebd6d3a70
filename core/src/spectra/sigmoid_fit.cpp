#include "spectra/sigmoid_fit.h"

#include <cmath>
#include <limits>
#include <vector>

#include "spectra/spectrum.h"

namespace penumbra::spectra {

namespace {

constexpr double kStep = 5.0;  // nm between the fitter's quadrature nodes
constexpr int kNodes = static_cast<int>((kLambdaMax - kLambdaMin) / kStep) + 1;

// Quadrature of integral s(l) D65(l) cmf(l) dl / integral D65 y dl for smooth s: the exact 1 nm
// integrand of D65 * cmf is gathered onto nodes 5 nm apart with hat functions, so that the sum is
// exact for any s linear between nodes (and within about 1e-4 for the smooth sigmoids).
struct Quadrature {
  std::vector<double> t;           // normalised wavelength of each node
  std::vector<glm::dvec3> weight;  // XYZ weight of each node
  glm::dmat3 xyz_to_rgb, rgb_to_xyz;
  glm::dvec3 white;                // XYZ of s = 1 (D65, Y = 1)

  Quadrature() : t(kNodes), weight(kNodes, glm::dvec3(0.0)) {
    for (int k = 0; k < kNodes; ++k) t[k] = k * kStep / (kLambdaMax - kLambdaMin);
    double y_sum = 0.0;
    for (int l = static_cast<int>(kLambdaMin); l <= static_cast<int>(kLambdaMax); ++l) {
      double end = (l == kLambdaMin || l == kLambdaMax) ? 0.5 : 1.0;  // trapezoid ends
      glm::dvec3 w = cmf_at(l) * (d65()(l) * end);
      y_sum += w.y;
      double x = (l - kLambdaMin) / kStep;
      int k = std::min(static_cast<int>(x), kNodes - 2);
      double f = x - k;
      weight[k] += (1.0 - f) * w;
      weight[k + 1] += f * w;
    }
    for (glm::dvec3& w : weight) w /= y_sum;
    xyz_to_rgb = xyz_to_rec709();
    rgb_to_xyz = glm::inverse(xyz_to_rgb);
    white = rgb_to_xyz * glm::dvec3(1.0);
  }
};

const Quadrature& quadrature() {
  static const Quadrature q;
  return q;
}

double sigmoid(double x) {
  if (std::isinf(x)) return x > 0.0 ? 1.0 : 0.0;
  return 0.5 + x / (2.0 * std::sqrt(1.0 + x * x));
}

// CIELAB of XYZ (white: D65 at Y = 1) and its derivative with respect to XYZ.
double lab_f(double v) {
  constexpr double d = 6.0 / 29.0;
  return v > d * d * d ? std::cbrt(v) : v / (3.0 * d * d) + 4.0 / 29.0;
}
double lab_df(double v) {
  constexpr double d = 6.0 / 29.0;
  return v > d * d * d ? 1.0 / (3.0 * std::cbrt(v * v)) : 1.0 / (3.0 * d * d);
}
glm::dvec3 lab(const glm::dvec3& xyz, const glm::dvec3& white) {
  double fx = lab_f(xyz.x / white.x), fy = lab_f(xyz.y / white.y), fz = lab_f(xyz.z / white.z);
  return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}
glm::dmat3 lab_jacobian(const glm::dvec3& xyz, const glm::dvec3& white) {
  double dx = lab_df(xyz.x / white.x) / white.x, dy = lab_df(xyz.y / white.y) / white.y,
         dz = lab_df(xyz.z / white.z) / white.z;
  glm::dmat3 j(0.0);  // j[column][row]: column = XYZ component, row = L, a, b
  j[0] = glm::dvec3(0.0, 500.0 * dx, 0.0);
  j[1] = glm::dvec3(116.0 * dy, -500.0 * dy, 200.0 * dy);
  j[2] = glm::dvec3(0.0, 0.0, -200.0 * dz);
  return j;
}

// XYZ of the sigmoid spectrum, and its derivatives with respect to the three coefficients.
glm::dvec3 spectrum_xyz(const SigmoidCoefficients& c, glm::dmat3* d_xyz_dc) {
  const Quadrature& q = quadrature();
  glm::dvec3 xyz(0.0);
  glm::dmat3 d(0.0);
  for (int k = 0; k < kNodes; ++k) {
    double t = q.t[k];
    double x = (c[0] * t + c[1]) * t + c[2];
    if (std::isinf(x)) {
      xyz += q.weight[k] * sigmoid(x);
      continue;
    }
    double r = 1.0 / std::sqrt(1.0 + x * x);
    xyz += q.weight[k] * (0.5 + 0.5 * x * r);
    if (d_xyz_dc) {
      glm::dvec3 g = q.weight[k] * (0.5 * r * r * r);  // S'(x) = 1 / (2 (1 + x^2)^(3/2))
      d[0] += g * (t * t);
      d[1] += g * t;
      d[2] += g;
    }
  }
  if (d_xyz_dc) *d_xyz_dc = d;
  return xyz;
}

}  // namespace

float sigmoid_spectrum(const SigmoidCoefficients& c, float lambda_nm) {
  float t = (lambda_nm - static_cast<float>(kLambdaMin)) / static_cast<float>(kLambdaMax - kLambdaMin);
  float x = (c[0] * t + c[1]) * t + c[2];
  if (std::isinf(x)) return x > 0.f ? 1.f : 0.f;
  return 0.5f + x / (2.f * std::sqrt(1.f + x * x));
}

glm::dvec3 sigmoid_spectrum_rgb(const SigmoidCoefficients& c) {
  return quadrature().xyz_to_rgb * spectrum_xyz(c, nullptr);
}

SigmoidCoefficients constant_sigmoid(float v) {
  // S(x) = v  <=>  x = (v - 1/2) / sqrt(v (1 - v))
  if (v <= 0.f) return {0.f, 0.f, -std::numeric_limits<float>::infinity()};
  if (v >= 1.f) return {0.f, 0.f, std::numeric_limits<float>::infinity()};
  return {0.f, 0.f, (v - 0.5f) / std::sqrt(v * (1.f - v))};
}

double fit_sigmoid(const glm::dvec3& rgb, SigmoidCoefficients& coefficients) {
  const Quadrature& q = quadrature();
  const glm::dvec3 target = lab(q.rgb_to_xyz * rgb, q.white);
  glm::dvec3 c(coefficients[0], coefficients[1], coefficients[2]);
  auto as_coefficients = [](const glm::dvec3& v) {
    return SigmoidCoefficients{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
  };
  glm::dmat3 d_xyz;
  glm::dvec3 xyz = spectrum_xyz(as_coefficients(c), &d_xyz);
  glm::dvec3 r = lab(xyz, q.white) - target;
  double err = glm::length(r);
  for (int iteration = 0; iteration < 50 && err > 1e-6; ++iteration) {
    glm::dmat3 j = lab_jacobian(xyz, q.white) * d_xyz;  // d Lab / d c
    if (std::abs(glm::determinant(j)) < 1e-30) break;
    glm::dvec3 step = glm::inverse(j) * r;
    // Damped Gauss-Newton: halve the step until the CIELAB distance falls.
    double scale = 1.0;
    bool improved = false;
    for (int halving = 0; halving < 20; ++halving, scale *= 0.5) {
      glm::dvec3 trial = c - scale * step;
      glm::dmat3 d_trial;
      glm::dvec3 xyz_trial = spectrum_xyz(as_coefficients(trial), &d_trial);
      glm::dvec3 r_trial = lab(xyz_trial, q.white) - target;
      double err_trial = glm::length(r_trial);
      if (err_trial < err) {
        c = trial, xyz = xyz_trial, d_xyz = d_trial, r = r_trial, err = err_trial;
        improved = true;
        break;
      }
    }
    if (!improved) break;
  }
  coefficients = as_coefficients(c);
  return err;
}

}  // namespace penumbra::spectra
