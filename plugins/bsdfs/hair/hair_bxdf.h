// The hair scattering model of pbrt-v4's HairBxDF (Chiang, Bitterli, Tappan and Burley 2016, after
// d'Eon et al. 2011 and Marschner et al. 2003): a fibre as a rough dielectric cylinder whose
// interior absorbs with coefficient sigma_a (per unit of fibre diameter). Light leaves after p
// internal path segments: R (p = 0), TT (1), TRT (2), and all longer paths summed in closed form
// (p = 3). Each term is a product
//   M_p(theta_o, theta_i)  longitudinal scattering: a normalised von Mises-Fisher-like lobe of
//                          variance v_p, its centre shifted by the cuticle tilt alpha (2^k alpha),
//   A_p(theta_o, h)        attenuation: Fresnel at the fibre's surface and absorption inside,
//   N_p(phi)               azimuthal scattering: a trimmed logistic of scale s around the exit
//                          azimuth Phi(p, h) of a smooth cylinder.
// Local frame: x along the fibre (the shading frame's dp/du axis), so sin(theta) = w.x, and the
// azimuth phi = atan2(w.z, w.y) around the fibre. h in [-1, 1] is where across the fibre the ray
// arrived (pbrt-v4: -1 + 2 v at a curve hit). f() includes the 1/|cos theta| of the BSDF frame that
// the integrator's |cos| cancels, as pbrt-v4's; pdf() is the solid-angle density of sample_f().
// With sigma_a = 0 the model conserves energy (sum of A_p is 1), and sampling is exact: every
// sample's weight f |cos| / pdf is 1 (tests/hair_bsdf_test.cpp checks both).
#pragma once

#include <penumbra/color.h>
#include <penumbra/math.h>
#include <penumbra/microfacet.h>

#include <array>
#include <cmath>
#include <optional>

namespace penumbra::hair {

constexpr int kPMax = 3;

/// What the roughnesses and the cuticle tilt make of the lobes: the same at every hit of a material
/// whose beta_m, beta_n and alpha are constant, so it is made once for such a material.
struct HairLobes {
  std::array<float, kPMax + 1> v{};     // longitudinal variances of the terms
  float s = 0.f;                        // scale of the azimuthal logistic
  std::array<float, 3> sin2k_alpha{}, cos2k_alpha{};  // the tilt 2^k alpha, k = 0, 1, 2
  /// beta_m, beta_n in (0, 1]; alpha in degrees.
  static HairLobes from(float beta_m, float beta_n, float alpha);
};

/// Absorption of a fibre whose multiple scattering looks like colour `c` (pbrt-v4's fit to
/// simulated fibres, Chiang et al. 2016, eq. 9).
Rgb sigma_a_from_reflectance(const Rgb& c, float beta_n);
/// Absorption from melanin concentrations (pbrt-v4's eumelanin and pheomelanin coefficients).
Rgb sigma_a_from_concentration(float eumelanin, float pheomelanin);

struct HairSample {
  Vec3 wi;
  Rgb f;
  float pdf;
};

class HairBxdf {
 public:
  /// The fibre at a hit: offset h in [-1, 1] across it, index of refraction eta, absorption sigma_a
  /// per fibre diameter.
  HairBxdf(const HairLobes& lobes, float h, float eta, const Rgb& sigma_a);
  Rgb f(const Vec3& wo, const Vec3& wi) const;
  std::optional<HairSample> sample_f(const Vec3& wo, float uc, Vec2 u) const;
  float pdf(const Vec3& wo, const Vec3& wi) const;
  /// A_p for a ray arriving with cos(theta_o): what leaves after each number of internal segments.
  std::array<Rgb, kPMax + 1> attenuation(float cos_theta_o) const;

 private:
  // The lobe of term p: sin and cos of theta_o rotated by the cuticle tilt of that term.
  void tilt(int p, float sin_theta_o, float cos_theta_o, float* sin_p, float* cos_p) const;
  std::array<float, kPMax + 1> attenuation_pdf(float cos_theta_o) const;
  // The azimuth gamma_t of the refracted ray inside the fibre.
  float gamma_t(float sin_theta_o, float cos_theta_o) const;
  template <class T>
  T lobe_sum(const Vec3& wo, const Vec3& wi, const std::array<T, kPMax + 1>& weight) const;

  HairLobes lobes_;
  float h_, eta_;
  Rgb sigma_a_;
  float gamma_o_;
};

}  // namespace penumbra::hair
