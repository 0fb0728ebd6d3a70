// The stochastic layered BxDF (libs/bxdf/layered_bxdf.h) against independent references: the mean of
// many f() estimates against an explicit Monte Carlo simulation of the slab (photons followed event
// by event with the interfaces' own sampling, isotropic phase sampling weighted by Henyey-Greenstein,
// no connections or MIS), sample_f()'s directions against the mean of pdf() estimates (chi-square),
// white furnaces, and the closed form of a Lambertian under a smooth dielectric. Seeds are fixed;
// tolerances are 4 standard errors measured from the samples themselves, and each test shows that a
// 2 % bias would fail it.
#include "support/bsdf_harness.h"

#include <layered_bxdf.h>

#include <penumbra/sampling.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace penumbra {
namespace {

using namespace bxdf;
using test::spherical_direction;
constexpr TransportMode kRadiance = TransportMode::Radiance;

Vec2 next2(Pcg32& rng) {
  float a = rng.next_float();
  return Vec2(a, rng.next_float());
}

// Mean and standard error of a stream of numbers.
struct Mean {
  double sum = 0.0, sum2 = 0.0;
  long n = 0;
  void add(double x) {
    sum += x;
    sum2 += x * x;
    ++n;
  }
  double mean() const { return sum / n; }
  double error() const { return std::sqrt(std::max(0.0, sum2 / n - mean() * mean()) / n); }
};

// Passes if |a - b| is within 4 combined standard errors; the negative control (a scaled by 2 %)
// must then be outside them, or the test could not see such a bias.
void expect_agree(const Mean& a, const Mean& b, const std::string& what) {
  double sigma = std::hypot(a.error(), b.error());
  EXPECT_LT(std::abs(a.mean() - b.mean()), 4.0 * sigma) << what << ": " << a.mean() << " vs " << b.mean();
  // Negative control: the tolerance is below 1.5 % of the value, and a 2 % bias (away from b) fails.
  EXPECT_LT(4.0 * sigma, 0.015 * std::abs(b.mean())) << what << ": too noisy to see a 2 % bias";
  double biased = (a.mean() >= b.mean() ? 1.02 : 0.98) * a.mean();
  EXPECT_GT(std::abs(biased - b.mean()), 4.0 * sigma) << what << ": a 2 % bias would pass";
  std::printf("  [%s] %.5f +- %.5f vs %.5f +- %.5f (ratio %.4f)\n", what.c_str(), a.mean(), a.error(), b.mean(),
              b.error(), a.mean() / b.mean());
}

// Henyey-Greenstein written from its formula, in terms of the propagation directions.
double hg(double g, const Vec3& w, const Vec3& w_out) {
  double c = glm::dot(w, w_out), d = 1.0 + g * g - 2.0 * g * c;
  return (1.0 - g * g) / (4.0 * 3.14159265358979323846 * d * std::sqrt(d));
}

// An explicit simulation of the slab: a photon enters from wo (weight 1) and is followed through every
// event until it leaves through the top; returns where it leaves and its weight, or nothing when it is
// absorbed or still inside after kMaxEvents. A delta reflection off the top is left out, as f() leaves
// it out. Free flights are sampled in the medium (unit extinction);
// without a medium the weight takes the transmittance instead.
template <class Bottom>
std::optional<std::pair<Vec3, Rgb>> simulate(const LayeredBxdf<Bottom>& b, const Vec3& wo, Pcg32& rng) {
  constexpr int kMaxEvents = 400;
  const LayerParams& p = b.params();
  const double h = p.thickness;
  const bool medium = !is_black(p.albedo);
  std::optional<BsdfSample> s = b.top().sample_f(wo, rng.next_float(), next2(rng), kRadiance);
  if (!s || !(s->pdf > 0.f) || (s->wi.z > 0.f && s->is_specular())) return std::nullopt;
  Rgb weight = s->f * std::abs(s->wi.z) / s->pdf;
  if (s->wi.z > 0.f) return std::make_pair(s->wi, weight);
  Vec3 w = s->wi;
  double z = h;
  for (int event = 0; event < kMaxEvents; ++event) {
    if (medium) {
      double zp = z + (-std::log(1.0 - rng.next_float())) * w.z;  // optical depth 1 per unit length
      if (zp > 0.0 && zp < h) {
        Vec3 wn = sample_uniform_sphere(next2(rng));
        weight *= p.albedo * static_cast<float>(hg(p.g, w, wn) * 4.0 * 3.14159265358979323846);
        w = wn;
        z = zp;
        continue;
      }
    } else {
      weight *= static_cast<float>(std::exp(-h / std::abs(w.z)));
    }
    z = w.z > 0.f ? h : 0.0;
    std::optional<BsdfSample> e = z == 0.0 ? b.bottom().sample_f(-w, rng.next_float(), next2(rng), kRadiance)
                                           : b.top().sample_f(-w, rng.next_float(), next2(rng), kRadiance);
    if (!e || !(e->pdf > 0.f)) return std::nullopt;
    weight *= e->f * std::abs(e->wi.z) / e->pdf;
    w = e->wi;
    if (z == h && w.z > 0.f) return std::make_pair(w, weight);
  }
  return std::nullopt;
}

LayerParams layer(float thickness, Rgb albedo = Rgb(0.f), float g = 0.f, int max_depth = 100) {
  LayerParams p;
  p.thickness = thickness;
  p.albedo = albedo;
  p.g = g;
  p.max_depth = max_depth;
  return p;
}

const Rgb kCuEta(0.200438f, 0.924033f, 1.102212f), kCuK(3.912949f, 2.452848f, 2.142188f);
DielectricBxdf coat(float alpha, float eta = 1.5f) { return DielectricBxdf(eta, TrowbridgeReitz(alpha, alpha)); }

// ---- mean f against the simulation -----------------------------------------------------------------

// The integral of f cos over a cone of directions around wi, two ways: the mean of f() estimates at
// uniform points of the cone, and the simulation's weight landing in the cone.
template <class Bottom>
void expect_f_matches_simulation(const LayeredBxdf<Bottom>& b, const Vec3& wo, const Vec3& wi, const std::string& what,
                                 uint64_t seed) {
  const float cos_cone = std::cos(radians(20.f));
  const double solid_angle = 2.0 * 3.14159265358979323846 * (1.0 - cos_cone);
  Frame frame(wi);
  Mean by_f, by_sim;
  Pcg32 rng(seed, 1);
  for (int i = 0; i < 100'000; ++i) {
    Vec3 w = frame.to_world(sample_uniform_cone(next2(rng), cos_cone));
    by_f.add(luminance(b.f(wo, w, kRadiance, rng)) * w.z * solid_angle);
  }
  Pcg32 sim_rng(seed, 2);
  for (int i = 0; i < 3'000'000; ++i) {
    std::optional<std::pair<Vec3, Rgb>> out = simulate(b, wo, sim_rng);
    by_sim.add(out && glm::dot(out->first, wi) >= cos_cone ? luminance(out->second) : 0.0);
  }
  expect_agree(by_f, by_sim, what);
}

const Vec3 kWo[] = {spherical_direction(0.9f, 0.4f), spherical_direction(0.4f, 1.f)};
const Vec3 kWi[] = {spherical_direction(0.7f, 2.5f), spherical_direction(0.5f, 1.f + 3.14159265f)};

TEST(LayeredBxdf, MeanFMatchesSimulationSmoothCoatOverDiffuse) {
  CoatedDiffuseBxdf b(coat(0.f), DiffuseBxdf(Rgb(0.8f, 0.5f, 0.2f)), layer(0.05f));
  for (int k = 0; k < 2; ++k) expect_f_matches_simulation(b, kWo[k], kWi[k], "smooth/diffuse " + std::to_string(k), 10 + k);
}

TEST(LayeredBxdf, MeanFMatchesSimulationRoughCoatScatteringMedium) {
  CoatedDiffuseBxdf b(coat(0.3f), DiffuseBxdf(Rgb(0.7f)), layer(0.3f, Rgb(0.6f, 0.8f, 0.9f), 0.4f));
  for (int k = 0; k < 2; ++k) expect_f_matches_simulation(b, kWo[k], kWi[k], "rough/medium/diffuse " + std::to_string(k), 20 + k);
}

TEST(LayeredBxdf, MeanFMatchesSimulationRoughCoatOverRoughConductor) {
  CoatedConductorBxdf b(coat(0.2f), ConductorBxdf(TrowbridgeReitz(0.25f, 0.25f), kCuEta / 1.5f, kCuK / 1.5f),
                        layer(0.02f));
  for (int k = 0; k < 2; ++k) expect_f_matches_simulation(b, kWo[k], kWi[k], "rough/conductor " + std::to_string(k), 30 + k);
}

TEST(LayeredBxdf, MeanFMatchesSimulationSmoothCoatOverRoughConductor) {
  CoatedConductorBxdf b(coat(0.f), ConductorBxdf(TrowbridgeReitz(0.3f, 0.3f), kCuEta / 1.5f, kCuK / 1.5f),
                        layer(0.01f, Rgb(0.5f), 0.f));
  for (int k = 0; k < 2; ++k) expect_f_matches_simulation(b, kWo[k], kWi[k], "smooth/medium/conductor " + std::to_string(k), 40 + k);
}

// ---- sample_f's directions against the mean of pdf() ----------------------------------------------

// Chi-square over nt x np cells of equal solid angle on the upper hemisphere: observed counts of
// sample_f()'s non-specular directions against N times the integral of pdf() over each cell, from
// the mean of m_cell estimates at jittered points. The estimates' own variance goes into the
// statistic, sum (o - e)^2 / (e + var(e)), so that a noisy expectation is not mistaken for a bad
// sampler; the p-value is then the chi-square distribution's (the harness's chi_square_p_value).
struct LayeredChiSquare {
  double p_value = 0.0, biased_p_value = 0.0;  // with the expected counts scaled by 1.02
  int dof = 0;
  double pdf_integral = 0.0, pdf_integral_error = 0.0, nonspecular_fraction = 0.0;
};

template <class Bottom>
LayeredChiSquare layered_chi_square(const LayeredBxdf<Bottom>& b, const Vec3& wo, uint64_t seed) {
  constexpr int nt = 8, np = 16, n = 1'000'000, side = 96;  // side^2 pdf estimates per cell
  std::vector<double> observed(nt * np, 0.0), expected(nt * np, 0.0), variance(nt * np, 0.0);
  Pcg32 rng(seed, 3);
  long nonspecular = 0;
  for (int i = 0; i < n; ++i) {
    std::optional<BsdfSample> s = b.sample_walk(wo, rng.next_float(), next2(rng), kRadiance, rng);
    if (!s || s->is_specular()) continue;
    EXPECT_GT(s->wi.z, 0.f) << "a reflection-only layer sampled a direction below the surface";
    if (!(s->wi.z > 0.f)) continue;
    ++nonspecular;
    double phi = std::atan2(s->wi.y, s->wi.x);
    if (phi < 0.0) phi += 2.0 * 3.14159265358979323846;
    int it = std::min(nt - 1, static_cast<int>(s->wi.z * nt));
    int ip = std::min(np - 1, static_cast<int>(phi / (2.0 * 3.14159265358979323846) * np));
    observed[it * np + ip] += 1.0;
  }
  const double dz = 1.0 / nt, dphi = 2.0 * 3.14159265358979323846 / np;
  Pcg32 prng(seed, 4);
  LayeredChiSquare r;
  for (int it = 0; it < nt; ++it)
    for (int ip = 0; ip < np; ++ip) {
      Mean m;
      for (int j = 0; j < side * side; ++j) {
        double z = (it + (j / side + prng.next_float()) / side) * dz;
        double phi = (ip + (j % side + prng.next_float()) / side) * dphi;
        double sin_t = std::sqrt(std::max(0.0, 1.0 - z * z));
        Vec3 w(static_cast<float>(sin_t * std::cos(phi)), static_cast<float>(sin_t * std::sin(phi)), static_cast<float>(z));
        m.add(b.pdf(wo, w, kRadiance, prng));
      }
      double area = dz * dphi;
      expected[it * np + ip] = n * m.mean() * area;
      variance[it * np + ip] = sqr(n * m.error() * area);
      r.pdf_integral += m.mean() * area;
      r.pdf_integral_error = std::hypot(r.pdf_integral_error, m.error() * area);
    }
  double stat = 0.0, biased = 0.0;
  for (int c = 0; c < nt * np; ++c) {
    EXPECT_GT(expected[c], 20.0) << "cell " << c << ": refine the chart";
    stat += sqr(observed[c] - expected[c]) / (expected[c] + variance[c]);
    biased += sqr(observed[c] - 1.02 * expected[c]) / (1.02 * expected[c] + sqr(1.02) * variance[c]);
  }
  r.dof = nt * np - 1;
  r.p_value = test::chi_square_p_value(stat, r.dof);
  r.biased_p_value = test::chi_square_p_value(biased, r.dof);
  r.nonspecular_fraction = static_cast<double>(nonspecular) / n;
  return r;
}

template <class Bottom>
void expect_sampling_matches_pdf(const LayeredBxdf<Bottom>& b, const Vec3& wo, const std::string& what, uint64_t seed) {
  const double alpha = test::sidak_alpha(0.01, 5);
  LayeredChiSquare r = layered_chi_square(b, wo, seed);
  EXPECT_GE(r.p_value, alpha) << what;
  EXPECT_LT(r.biased_p_value, alpha) << what << ": a 2 % bias in pdf() would pass";
  // The pdf integrates to the probability of a non-specular sample (deltas and lost walks excluded).
  EXPECT_NEAR(r.pdf_integral, r.nonspecular_fraction, 4.0 * r.pdf_integral_error + 1e-3) << what;
  std::printf("  [%s] p = %.3f (2 %% bias: p = %.2g), int pdf = %.4f +- %.4f, non-specular samples %.4f\n",
              what.c_str(), r.p_value, r.biased_p_value, r.pdf_integral, r.pdf_integral_error, r.nonspecular_fraction);
}

TEST(LayeredBxdf, SamplingMatchesMeanPdfSmoothCoatOverDiffuse) {
  CoatedDiffuseBxdf b(coat(0.f), DiffuseBxdf(Rgb(0.8f, 0.5f, 0.2f)), layer(0.1f, Rgb(0.f), 0.f, 10));
  expect_sampling_matches_pdf(b, spherical_direction(0.6f, 0.5f), "smooth/diffuse", 51);
}

TEST(LayeredBxdf, SamplingMatchesMeanPdfRoughCoatScatteringMedium) {
  CoatedDiffuseBxdf b(coat(0.3f), DiffuseBxdf(Rgb(0.7f)), layer(0.3f, Rgb(0.6f), 0.4f, 10));
  expect_sampling_matches_pdf(b, spherical_direction(0.3f, 2.f), "rough/medium/diffuse", 52);
}

TEST(LayeredBxdf, SamplingMatchesMeanPdfRoughCoatOverRoughConductor) {
  CoatedConductorBxdf b(coat(0.2f), ConductorBxdf(TrowbridgeReitz(0.25f, 0.4f), kCuEta / 1.5f, kCuK / 1.5f),
                        layer(0.01f, Rgb(0.f), 0.f, 10));
  expect_sampling_matches_pdf(b, spherical_direction(0.8f, 1.f), "rough/conductor", 53);
}

TEST(LayeredBxdf, SamplingMatchesMeanPdfRoughCoatOverMirror) {
  CoatedConductorBxdf b(coat(0.3f), ConductorBxdf(TrowbridgeReitz(0.f, 0.f), kCuEta / 1.5f, kCuK / 1.5f),
                        layer(0.01f, Rgb(0.f), 0.f, 10));
  expect_sampling_matches_pdf(b, spherical_direction(0.5f, 3.f), "rough/mirror", 55);
}

TEST(LayeredBxdf, SamplingMatchesMeanPdfSmoothCoatMediumOverMirror) {
  // Only the medium makes this layer non-specular; walks reach wi through the mirror base as well.
  CoatedConductorBxdf b(coat(0.f), ConductorBxdf(TrowbridgeReitz(0.f, 0.f), kCuEta / 1.5f, kCuK / 1.5f),
                        layer(0.5f, Rgb(0.7f), -0.3f, 10));
  expect_sampling_matches_pdf(b, spherical_direction(0.7f, 4.f), "smooth/medium/mirror", 54);
}

// ---- furnaces --------------------------------------------------------------------------------------

// Directional albedo three ways: sample_f()'s weights, the mean of f() cos over uniform directions
// (plus the delta reflection's Fresnel weight, which f() leaves out), and the simulation's weights.
struct Albedos {
  Mean sampled, integrated, simulated;
};

template <class Bottom>
Albedos albedos(const LayeredBxdf<Bottom>& b, const Vec3& wo, uint64_t seed, int n = 400'000) {
  Albedos a;
  Pcg32 rng(seed, 5);
  float delta_reflection = b.top().specular() ? fresnel_dielectric(wo.z, b.top().eta()) : 0.f;
  for (int i = 0; i < n; ++i) {
    std::optional<BsdfSample> s = b.sample_walk(wo, rng.next_float(), next2(rng), kRadiance, rng);
    a.sampled.add(s ? luminance(s->f) * std::abs(s->wi.z) / s->pdf : 0.0);
    Vec3 w = sample_uniform_sphere(next2(rng));
    w.z = std::abs(w.z);
    a.integrated.add(delta_reflection + luminance(b.f(wo, w, kRadiance, rng)) * w.z * 2.0 * 3.14159265358979323846);
    std::optional<std::pair<Vec3, Rgb>> out = simulate(b, wo, rng);
    a.simulated.add(out ? luminance(out->second) : 0.0);
  }
  return a;
}

TEST(LayeredBxdf, WhiteFurnaceRoughCoatOverWhiteDiffuse) {
  // No absorption anywhere but the rough coat's single scattering: the albedo stays below 1 and the
  // three estimates agree. (The simulation leaves the delta reflection out; a rough coat has none.)
  CoatedDiffuseBxdf b(coat(0.3f), DiffuseBxdf(Rgb(1.f)), layer(0.f));
  for (float c : {0.9f, 0.4f}) {
    Vec3 wo = spherical_direction(c, 0.7f);
    Albedos a = albedos(b, wo, 60 + static_cast<uint64_t>(10 * c));
    EXPECT_LT(a.sampled.mean(), 1.0 + 4.0 * a.sampled.error());
    expect_agree(a.sampled, a.simulated, "rough white furnace, sampled vs simulated, cos " + std::to_string(c));
    expect_agree(a.integrated, a.simulated, "rough white furnace, f vs simulated, cos " + std::to_string(c));
  }
}

TEST(LayeredBxdf, WhiteFurnaceSmoothCoatOverWhiteDiffuseIsOne) {
  // Every walk carries weight exactly 1 (the coat's 1/eta^2 going in is undone coming out), so the
  // albedo is the fraction of walks that leave within maxdepth: 1 to 1e-4 at maxdepth 100.
  CoatedDiffuseBxdf b(coat(0.f), DiffuseBxdf(Rgb(1.f)), layer(0.f));
  for (float c : {1.f, 0.5f, 0.1f}) {
    Vec3 wo = spherical_direction(c, 0.2f);
    Albedos a = albedos(b, wo, 70, 200'000);
    EXPECT_NEAR(a.sampled.mean(), 1.0, 1e-4) << c;
    EXPECT_GT(std::abs(0.98 * a.sampled.mean() - 1.0), 1e-4);  // a 2 % bias would fail
    EXPECT_NEAR(a.integrated.mean(), 1.0, 4.0 * a.integrated.error()) << c;
    EXPECT_LT(4.0 * a.integrated.error(), 0.015) << "too noisy to see a 2 % bias";
    std::printf("  [smooth white furnace cos %.1f] sampled %.6f, f %.4f +- %.4f\n", c, a.sampled.mean(),
                a.integrated.mean(), a.integrated.error());
  }
}

TEST(LayeredBxdf, PerfectConductorUnderCoatLosesOnlyTheCoatsSingleScattering) {
  const Rgb white_k = k_from_reflectance(Rgb(1.f));  // eta 1: F = 0.9999 at every angle
  // Smooth coat, mirror base: energy is conserved (to the base's 1e-4 per bounce).
  CoatedConductorBxdf smooth(coat(0.f), ConductorBxdf(TrowbridgeReitz(0.f, 0.f), Rgb(1.f), white_k), layer(0.f));
  // Rough coat: what is lost is the coat's single-scattering GGX loss, paid going in and at every
  // visit of the top from inside (light trapped by total internal reflection visits it often): the
  // albedo stays below the coat's own energy albedo from wo, and matches the simulation.
  CoatedConductorBxdf rough(coat(0.4f), ConductorBxdf(TrowbridgeReitz(0.f, 0.f), Rgb(1.f), white_k), layer(0.f));
  for (float c : {0.9f, 0.4f}) {
    Vec3 wo = spherical_direction(c, 1.3f);
    Mean smooth_albedo, coat_albedo;
    Pcg32 rng(80, 6);
    for (int i = 0; i < 200'000; ++i) {
      std::optional<BsdfSample> s = smooth.sample_walk(wo, rng.next_float(), next2(rng), kRadiance, rng);
      smooth_albedo.add(s ? luminance(s->f) * std::abs(s->wi.z) / s->pdf : 0.0);
      // The coat's energy albedo: importance transport, whose refraction weights carry no 1/eta^2.
      std::optional<BsdfSample> t = rough.top().sample_f(wo, rng.next_float(), next2(rng), TransportMode::Importance);
      coat_albedo.add(t ? luminance(t->f) * std::abs(t->wi.z) / t->pdf : 0.0);
    }
    EXPECT_NEAR(smooth_albedo.mean(), 1.0, 2e-3) << c;
    EXPECT_GT(std::abs(0.98 * smooth_albedo.mean() - 1.0), 2e-3);
    Albedos a = albedos(rough, wo, 81, 1'500'000);
    EXPECT_LT(a.sampled.mean(), coat_albedo.mean() + 4.0 * std::hypot(a.sampled.error(), coat_albedo.error())) << c;
    expect_agree(a.sampled, a.simulated, "rough coat over mirror, sampled vs simulated, cos " + std::to_string(c));
    expect_agree(a.integrated, a.simulated, "rough coat over mirror, f vs simulated, cos " + std::to_string(c));
    std::printf("  [mirror under coat, cos %.1f] smooth %.5f; rough %.4f, coat alone %.4f\n", c, smooth_albedo.mean(),
                a.sampled.mean(), coat_albedo.mean());
  }
}

// ---- the closed form of a Lambertian under a smooth dielectric ----------------------------------------

// Unpolarised Fresnel reflectance of a dielectric, written out in double (not the SDK's).
double fresnel(double cos_i, double eta) {
  double sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0) return 1.0;
  double cos_t = std::sqrt(1.0 - sin2_t);
  double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t), rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

TEST(LayeredBxdf, SmoothCoatOverLambertianMatchesClosedForm) {
  // Light entering at normal incidence passes with 1 - F0, is spread by the base into a cosine
  // distribution, and leaves through the coat with probability 1 - r_i, where r_i is the coat's
  // hemispherical (cosine-weighted) reflectance from inside, total internal reflection included; the
  // rest returns to the base (albedo rho) and tries again:
  //   albedo(normal) = F0 + (1 - F0) rho (1 - r_i) / (1 - rho r_i).
  // Etendue links r_i to the outside hemispherical reflectance r_e: 1 - r_i = (1 - r_e) / eta^2. The
  // BRDF at normal incidence and exit has the same series, with the base's radiance rho / pi leaving
  // through (1 - F0) and compressed by 1/eta^2 into the outside solid angle:
  //   f(normal, normal) = (1 - F0)^2 rho / (pi eta^2 (1 - rho r_i)).
  const double eta = 1.5, rho = 0.6;
  double r_e = 0.0;
  constexpr int kSteps = 200'000;
  for (int i = 0; i < kSteps; ++i) {
    double mu = (i + 0.5) / kSteps;
    r_e += fresnel(mu, eta) * 2.0 * mu / kSteps;
  }
  double r_i = 1.0 - (1.0 - r_e) / (eta * eta), f0 = fresnel(1.0, eta);
  double albedo = f0 + (1.0 - f0) * rho * (1.0 - r_i) / (1.0 - rho * r_i);
  double f_nn = sqr(1.0 - f0) * rho / (3.14159265358979323846 * eta * eta * (1.0 - rho * r_i));
  std::printf("  [closed form] r_e %.5f, r_i %.5f, albedo %.5f, f(n, n) %.5f\n", r_e, r_i, albedo, f_nn);

  CoatedDiffuseBxdf b(coat(0.f), DiffuseBxdf(Rgb(static_cast<float>(rho))), layer(0.f, Rgb(0.f), 0.f, 200));
  const Vec3 n(0.f, 0.f, 1.f);
  Mean a, f;
  Pcg32 rng(90, 7);
  for (int i = 0; i < 400'000; ++i) {
    std::optional<BsdfSample> s = b.sample_walk(n, rng.next_float(), next2(rng), kRadiance, rng);
    a.add(s ? s->f.r * std::abs(s->wi.z) / s->pdf : 0.0);
    f.add(b.f(n, n, kRadiance, rng).r);
  }
  for (auto [m, expected, what] : {std::tuple{&a, albedo, "albedo"}, std::tuple{&f, f_nn, "f(n, n)"}}) {
    double tol = std::max(4.0 * m->error(), 2e-4 * expected);
    EXPECT_NEAR(m->mean(), expected, tol) << what;
    EXPECT_GT(std::abs(1.02 * m->mean() - expected), tol) << what << ": a 2 % bias would pass";
    std::printf("  [closed form %s] %.5f +- %.5f vs %.5f (ratio %.5f)\n", what, m->mean(), m->error(), expected,
                m->mean() / expected);
  }
}

}  // namespace
}  // namespace penumbra
