// The shared microfacet header: normalisation of D and of the visible normals, visible-normal
// sampling against its density (chi-square), masking bounds, Fresnel and refraction identities.
#include "support/bsdf_harness.h"
#include "support/chi_square.h"

#include <penumbra/microfacet.h>

#include <gtest/gtest.h>

#include <complex>

#include <vector>

namespace penumbra {
namespace {

using test::spherical_direction;

struct Alphas {
  float x, y;
};
const Alphas kAlphas[] = {{0.05f, 0.05f}, {0.3f, 0.3f}, {1.f, 1.f}, {0.05f, 0.3f}, {0.4f, 0.1f}};
// Directions for the visible normals, from normal incidence to grazing, and one below the surface.
const Vec3 kViews[] = {Vec3(0.f, 0.f, 1.f), spherical_direction(0.5f, 0.7f), spherical_direction(0.01f, 2.1f),
                       spherical_direction(-0.6f, 4.f)};

// Integral of g(wm) over the upper hemisphere. theta = atan(a tan(psi)) packs the quadrature points
// where a GGX lobe of width a lives; the midpoint rule in psi and phi is then accurate to ~1e-5.
template <typename G>
double integrate_hemisphere(const G& g, double a, int n_psi = 1500, int n_phi = 600) {
  double sum = 0.0;
  for (int i = 0; i < n_psi; ++i) {
    double psi = (i + 0.5) / n_psi * (Pi / 2);
    double tan_psi = std::tan(psi);
    double theta = std::atan(a * tan_psi);
    double dtheta_dpsi = a * (1.0 + tan_psi * tan_psi) / (1.0 + a * a * tan_psi * tan_psi);
    double sin_theta = std::sin(theta), cos_theta = std::cos(theta);
    for (int j = 0; j < n_phi; ++j) {
      double phi = (j + 0.5) / n_phi * 2.0 * Pi;
      Vec3 wm(float(sin_theta * std::cos(phi)), float(sin_theta * std::sin(phi)), float(cos_theta));
      sum += g(wm) * sin_theta * dtheta_dpsi;
    }
  }
  return sum * (Pi / 2 / n_psi) * (2.0 * Pi / n_phi);
}

TEST(Microfacet, ProjectedNormalDistributionIntegratesToOne) {
  for (Alphas a : kAlphas) {
    TrowbridgeReitz d(a.x, a.y);
    double integral = integrate_hemisphere([&](const Vec3& wm) { return d.D(wm) * wm.z; }, std::sqrt(a.x * a.y));
    EXPECT_NEAR(integral, 1.0, 2e-3) << "alpha " << a.x << " x " << a.y;
  }
}

TEST(Microfacet, VisibleNormalsIntegrateToOne) {
  for (Alphas a : kAlphas)
    for (Vec3 w : kViews) {
      TrowbridgeReitz d(a.x, a.y);
      double integral = integrate_hemisphere([&](const Vec3& wm) { return d.D(w, wm); }, std::sqrt(a.x * a.y));
      EXPECT_NEAR(integral, 1.0, 3e-3) << "alpha " << a.x << " x " << a.y << ", cos theta " << w.z;
    }
}

// A histogram chart for the visible normals seen from w. Cells must not clip a region of nonzero
// density in a thin sliver that the per-cell quadrature could miss.
std::pair<Frame, test::SphereChart> visible_normal_chart(const TrowbridgeReitz& d, const Vec3& w) {
  float a_max = std::max(d.alpha_x(), d.alpha_y());
  Vec3 w_seen = w.z < 0.f ? -w : w;
  test::SphereChart chart;
  chart.max_refinements = 4;
  if (a_max < 0.15f) {
    // Narrow: a cap around the lobe, which sits near +z leaning towards the viewer. The tilt keeps
    // the pole, where cells are thin wedges, off the visibility boundary w.wm = 0 (which passes
    // next to +z for grazing w).
    chart.z_min = std::cos(5.0 * a_max);
    return {Frame(glm::normalize(Vec3(0, 0, 1) + a_max * w_seen)), chart};
  }
  // Wide: the whole sphere with the chart's poles on the horizon, so that the density's jump at
  // wm.z = 0 runs along cell edges (phi' = 90 and 270 degrees) and no pole lies on w.wm = 0.
  Vec3 h(w_seen.x, w_seen.y, 0.f);
  h = glm::dot(h, h) > 1e-6f ? glm::normalize(h) : Vec3(1, 0, 0);
  Frame frame;
  frame.n = h;
  frame.s = Vec3(0, 0, 1);
  frame.t = glm::cross(frame.n, frame.s);
  return {frame, chart};
}

TEST(Microfacet, VisibleNormalSamplingMatchesItsDensity) {
  const int num_tests = int(std::size(kAlphas) * std::size(kViews));
  const double alpha = test::sidak_alpha(0.01, num_tests);
  uint64_t seed = 1;
  for (Alphas a : kAlphas)
    for (Vec3 w : kViews) {
      TrowbridgeReitz d(a.x, a.y);
      auto [frame_, chart] = visible_normal_chart(d, w);
      const Frame frame = frame_;  // a named variable, so the lambdas can capture it
      auto r = test::chi_square_sphere(
          [&](Vec2 u, float) -> std::optional<Vec3> { return frame.to_local(d.sample_wm(w, u)); },
          [&](const Vec3& wm) -> double { return d.pdf(w, frame.to_world(wm)); }, 200'000, 20, 40, seed++, chart);
      EXPECT_TRUE(r.passes(alpha)) << "alpha " << a.x << " x " << a.y << ", w " << w.x << " " << w.y << " " << w.z
                                   << ": " << r.summary();
      EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3) << r.summary();
    }
}

TEST(Microfacet, MaskingIsBoundedAndFiniteAtTheEdges) {
  TrowbridgeReitz d(0.3f, 0.1f);
  for (Vec3 w : {Vec3(0, 0, 1), Vec3(0, 0, -1), Vec3(1, 0, 0), Vec3(0, 1, 0), spherical_direction(1e-6f, 1.f),
                 spherical_direction(0.3f, 2.f), spherical_direction(-0.9f, 5.f)}) {
    float g1 = d.G1(w);
    EXPECT_TRUE(g1 >= 0.f && g1 <= 1.f) << g1;
    EXPECT_FALSE(std::isnan(d.lambda(w)));
    EXPECT_TRUE(std::isfinite(d.D(w)));
    EXPECT_TRUE(std::isfinite(d.D(w, Vec3(0, 0, 1))));
    for (Vec3 v : {Vec3(0, 0, 1), spherical_direction(0.2f, 0.3f)}) {
      float g = d.G(w, v);
      EXPECT_TRUE(g >= 0.f && g <= std::min(d.G1(w), d.G1(v)) + 1e-6f) << g;
    }
  }
  EXPECT_EQ(d.G1(Vec3(1, 0, 0)), 0.f);  // grazing: fully masked (the limit)
  EXPECT_EQ(d.G1(Vec3(0, 0, 1)), 1.f);
  // The clamp keeps alpha = 0 finite; such a distribution is a delta for the BSDFs.
  TrowbridgeReitz zero(0.f, 0.f);
  EXPECT_TRUE(zero.effectively_smooth());
  EXPECT_TRUE(std::isfinite(zero.D(Vec3(0, 0, 1))));
  EXPECT_TRUE(is_finite(zero.sample_wm(Vec3(1, 0, 0), Vec2(0.3f, 0.8f))));
  EXPECT_FALSE(TrowbridgeReitz(1e-3f, 1e-3f).effectively_smooth());
  // Sampling exactly at the pole and at the horizon.
  for (Vec3 w : {Vec3(0, 0, 1), Vec3(1, 0, 0), Vec3(0, 0, -1)})
    for (Vec2 u : {Vec2(0.f), Vec2(0.5f), Vec2(OneMinusEpsilon)}) {
      Vec3 wm = d.sample_wm(w, u);
      EXPECT_TRUE(is_finite(wm) && wm.z > 0.f && std::abs(glm::length(wm) - 1.f) < 1e-5f);
    }
}

TEST(Microfacet, RoughnessRemapAndRegularize) {
  EXPECT_FLOAT_EQ(TrowbridgeReitz::roughness_to_alpha(0.25f), 0.5f);
  TrowbridgeReitz d(0.01f, 0.5f);
  d.regularize();
  EXPECT_FLOAT_EQ(d.alpha_x(), 0.1f);
  EXPECT_FLOAT_EQ(d.alpha_y(), 0.5f);
}

TEST(Fresnel, DielectricValues) {
  EXPECT_NEAR(fresnel_dielectric(1.f, 1.5f), 0.04f, 1e-6f);
  EXPECT_NEAR(fresnel_dielectric(1.f, 1.f), 0.f, 1e-7f);
  EXPECT_FLOAT_EQ(fresnel_dielectric(0.f, 1.5f), 1.f);  // grazing reflects everything
  // From the other side the interface has eta inverted.
  for (float c : {0.1f, 0.5f, 0.9f, 1.f})
    EXPECT_FLOAT_EQ(fresnel_dielectric(-c, 1.5f), fresnel_dielectric(c, 1.f / 1.5f));
  // Total internal reflection beyond the critical angle asin(1/1.5) (cos < 0.745).
  EXPECT_EQ(fresnel_dielectric(-0.7f, 1.5f), 1.f);
  EXPECT_LT(fresnel_dielectric(-0.8f, 1.5f), 1.f);
  // The same interface crossed either way reflects the same fraction (Stokes relations).
  for (float c : {0.2f, 0.6f, 0.95f}) {
    float etap;
    Vec3 wt;
    Vec3 wi = spherical_direction(c, 0.4f);
    ASSERT_TRUE(refract(wi, Vec3(0, 0, 1), 1.5f, &etap, &wt));
    EXPECT_NEAR(fresnel_dielectric(c, 1.5f), fresnel_dielectric(wt.z, 1.5f), 1e-5f);
  }
}

TEST(Fresnel, ComplexReducesToDielectricWithoutAbsorption) {
  for (float eta : {1.1f, 1.5f, 2.5f})
    for (float c : {0.f, 0.05f, 0.3f, 0.7f, 1.f})
      EXPECT_NEAR(fresnel_conductor(c, eta, 0.f), fresnel_dielectric(c, eta), 1e-5f)
          << "eta " << eta << " cos " << c;
  // pbrt-v4's reflectance parameterisation: eta = 1, k = 2 sqrt(R)/sqrt(1 - R) gives F(0 deg) = R.
  for (float R : {0.1f, 0.5f, 0.9f}) {
    float k = 2.f * std::sqrt(R) / std::sqrt(1.f - R);
    EXPECT_NEAR(fresnel_conductor(1.f, 1.f, k), R, 1e-5f);
  }
  Rgb copper = fresnel_complex(1.f, Rgb(0.200438f, 0.924033f, 1.102212f), Rgb(3.912949f, 2.452848f, 2.142188f));
  EXPECT_GT(copper.r, copper.g);
  EXPECT_GT(copper.g, copper.b);
  EXPECT_TRUE(copper.r < 1.f && copper.b > 0.4f);
  EXPECT_NEAR(fresnel_conductor(0.f, 1.f, 0.f), 1.f, 1e-6f);  // no NaN at 0/0
}

// The textbook form with complex amplitudes r_s, r_p (in double), independent of the closed form.
static double fresnel_by_complex_amplitudes(double cos_i, std::complex<double> eta) {
  using C = std::complex<double>;
  C sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
  C cos_t = std::sqrt(C(1.0) - sin2_t);
  C r_s = (C(cos_i) - eta * cos_t) / (C(cos_i) + eta * cos_t);
  C r_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5 * (std::norm(r_s) + std::norm(r_p));
}

TEST(Fresnel, ConductorClosedFormMatchesComplexAmplitudes) {
  // Gold, silver-like, aluminium-like, a weak absorber and pbrt-v4's reflectance 0.9999 (k = 200).
  const std::pair<float, float> iors[] = {{0.143f, 3.98f}, {0.155f, 4.83f}, {1.66f, 9.22f}, {1.5f, 0.1f},
                                          {1.f, 199.99f}};
  double worst = 0.0;
  for (auto [eta, k] : iors)
    for (int i = 0; i <= 100; ++i) {
      float c = static_cast<float>(i) / 100.f;
      double want = fresnel_by_complex_amplitudes(c, {eta, k});
      double got = fresnel_conductor(c, eta, k);
      worst = std::max(worst, std::abs(got - want));
      ASSERT_NEAR(got, want, 2e-6) << "eta " << eta << " k " << k << " cos " << c;
    }
  // Negative control: a 1 % change of k moves some value by far more than the tolerance.
  double moved = 0.0;
  for (int i = 0; i <= 100; ++i)
    moved = std::max(moved, std::abs(fresnel_conductor(i / 100.f, 0.143f, 3.98f * 1.01f) -
                                      fresnel_by_complex_amplitudes(i / 100.0, {0.143, 3.98})));
  EXPECT_GT(moved, 100 * 2e-6) << "worst agreement " << worst;
}

TEST(Refraction, SnellsLawAndReversibility) {
  for (float eta : {1.33f, 1.5f, 1.f / 1.5f})
    for (float c : {1.f, 0.8f, 0.3f}) {
      Vec3 wi = spherical_direction(c, 1.2f), wt;
      float etap;
      if (!refract(wi, Vec3(0, 0, 1), eta, &etap, &wt)) {
        EXPECT_GT(1.f - c * c, eta * eta);  // only beyond the critical angle
        continue;
      }
      EXPECT_FLOAT_EQ(etap, eta);
      EXPECT_NEAR(glm::length(wt), 1.f, 1e-5f);
      EXPECT_LT(wt.z, 0.f);
      EXPECT_NEAR(std::sqrt(1.f - c * c), eta * std::sqrt(1.f - wt.z * wt.z), 1e-5f);  // sin_i = eta sin_t
      Vec3 back;
      ASSERT_TRUE(refract(wt, Vec3(0, 0, 1), eta, &etap, &back));  // from below: eta inverted
      EXPECT_FLOAT_EQ(etap, 1.f / eta);
      EXPECT_NEAR(glm::length(back - wi), 0.f, 1e-5f);
    }
  Vec3 wt;
  EXPECT_FALSE(refract(spherical_direction(-0.2f, 0.f), Vec3(0, 0, 1), 1.5f, nullptr, &wt));
  Vec3 r = reflect(spherical_direction(0.3f, 1.f), Vec3(0, 0, 1));
  EXPECT_NEAR(glm::length(r - spherical_direction(0.3f, 1.f + Pi)), 0.f, 1e-5f);
}

}  // namespace
}  // namespace penumbra
