// Warping functions from [0,1)^2 to common domains, with their densities. Each one is tested by a
// chi-square test against its pdf (tests/sampling_warps_test.cpp).
#pragma once

#include <penumbra/math.h>

#include <span>
#include <vector>

namespace penumbra {

/// Concentric map of the square to the unit disk (Shirley-Chiu); uniform density 1/pi.
Vec2 sample_uniform_disk_concentric(Vec2 u);

/// Cosine-weighted direction on the +z hemisphere; pdf = cos(theta)/pi.
Vec3 sample_cosine_hemisphere(Vec2 u);
inline float cosine_hemisphere_pdf(float cos_theta) { return std::max(cos_theta, 0.f) * InvPi; }

/// Uniform direction on the unit sphere; pdf = 1/(4 pi).
Vec3 sample_uniform_sphere(Vec2 u);
inline float uniform_sphere_pdf() { return Inv4Pi; }

/// Uniform direction inside a cone around +z with cos(half angle) = cos_max; pdf = 1/(2 pi (1-cos_max)).
Vec3 sample_uniform_cone(Vec2 u, float cos_max);
inline float uniform_cone_pdf(float cos_max) { return 1.f / (2.f * Pi * (1.f - cos_max)); }

/// Uniform barycentrics (b0, b1) on a triangle (pbrt-v4's low-distortion map); pdf = 1/area.
Vec2 sample_uniform_triangle(Vec2 u);

/// Power heuristic with beta = 2 for MIS of two strategies (nf, ng sample counts).
inline float power_heuristic(int nf, float f_pdf, int ng, float g_pdf) {
  float f = nf * f_pdf, g = ng * g_pdf;
  if (std::isinf(f * f)) return 1.f;
  if (f == 0.f && g == 0.f) return 0.f;
  return (f * f) / (f * f + g * g);
}

/// Piecewise-constant 1D distribution over n equal bins of [0,1) (pbrt's PiecewiseConstant1D).
/// All-zero functions become uniform.
class Distribution1D {
 public:
  Distribution1D() = default;
  explicit Distribution1D(std::span<const float> f);
  size_t size() const { return func_.size(); }
  /// Integral of |f| over [0,1) before normalisation.
  float integral() const { return integral_; }
  /// Continuous sample in [0,1); `pdf` is the density there, `offset` the bin.
  float sample_continuous(float u, float* pdf, size_t* offset = nullptr) const;
  /// Discrete sample of a bin with probability f[i]/sum(f); `u_remapped` gets u rescaled to [0,1).
  size_t sample_discrete(float u, float* pmf = nullptr, float* u_remapped = nullptr) const;
  float discrete_pmf(size_t i) const;

 private:
  std::vector<float> func_, cdf_;
  float integral_ = 0.f;
};

/// Piecewise-constant 2D distribution over an nu x nv grid on [0,1)^2 (row-major f, v = row):
/// a marginal over rows and a conditional per row (pbrt's PiecewiseConstant2D).
class Distribution2D {
 public:
  Distribution2D() = default;
  Distribution2D(std::span<const float> f, size_t nu, size_t nv);
  /// A point in [0,1)^2 with density `pdf` (per unit area of the square).
  Vec2 sample_continuous(Vec2 u, float* pdf) const;
  /// Density of sample_continuous() at p.
  float pdf(Vec2 p) const;
  float integral() const { return marginal_.integral(); }

 private:
  std::vector<Distribution1D> conditional_;
  Distribution1D marginal_;
};

}  // namespace penumbra
