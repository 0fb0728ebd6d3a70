// The "disney" material: sampling against pdf by chi-square over a grid of
// parameters that switches every lobe on (with a deliberately broken variant that must fail),
// white-furnace albedos, reciprocity of the reflection lobes, and finite values at the edges
// (roughness 0, eta 1, grazing and below-the-surface directions).
#include "support/bsdf_harness.h"
#include "support/pcg32.h"

#include <penumbra/error.h>
#include <penumbra/microfacet.h>

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <thread>
#include <vector>

using namespace penumbra;
using namespace penumbra::test;

namespace {

const ShadingContext kRadiance{};

// ---- Chi-square grid -------------------------------------------------------------------------

struct ChiCase {
  const char* params;
  // 0: the harness's sphere chart (it zooms onto a dominant lobe narrower than alpha 0.15).
  // > 0: the lobe is too narrow for a sphere chart (alpha ~ 1e-3): histogram a window of this
  // half-width (in tan theta) around its peak instead; see narrow_lobe_chi_square().
  float window = 0.f;
  bool zoom = true;
};

// Every lobe appears at least once: diffuse + retro (roughness), sheen, anisotropic specular,
// metal, clearcoat at several glosses, rough transmission at eta 1.5 and 2.5, the eta ~ 1
// pass-through, and the thin-surface lobes (fake subsurface, diffuse and thin transmission).
// Roughness 0.032 is the narrowest glossy lobe (alpha 1.024e-3, just above
// TrowbridgeReitz::kSmoothAlpha; below it the lobes are deltas, tested further down).
const ChiCase kChiCases[] = {
    {R"("float metallic" [1] "float roughness" [0.032])", 0.012f},
    {R"("float metallic" [1] "float roughness" [0.3])"},
    {R"("float metallic" [1] "float roughness" [1])"},
    {R"("float metallic" [1] "float roughness" [0.3] "float anisotropic" [0.8] "rgb color" [0.9 0.6 0.2])"},
    {R"("float metallic" [1] "float roughness" [1] "float anisotropic" [0.8])"},
    {R"("float roughness" [0.3] "rgb color" [0.8 0.3 0.2])"},
    {R"("float roughness" [1] "float sheen" [1] "float sheentint" [1] "rgb color" [0.2 0.5 0.8])"},
    {R"("float roughness" [0.032])", 0.012f},
    {R"("float metallic" [0.5] "float roughness" [0.3] "float speculartint" [1] "float anisotropic" [0.8])"},
    {R"("float roughness" [0.5] "float clearcoat" [1] "float clearcoatgloss" [0])"},
    {R"("float metallic" [1] "float roughness" [0.3] "float clearcoat" [1] "float clearcoatgloss" [0.5])"},
    {R"("float metallic" [1] "float roughness" [1] "float clearcoat" [1] "float clearcoatgloss" [1])", 0.012f},
    {R"("float roughness" [0.3] "float clearcoat" [1] "float clearcoatgloss" [0.9] "rgb color" [0.1 0.1 0.1])", 0.13f},
    {R"("float spectrans" [1] "float eta" [1.5] "float roughness" [0.3] "rgb color" [1 1 1])"},
    {R"("float spectrans" [1] "float eta" [2.5] "float roughness" [0.3] "rgb color" [0.9 0.9 0.7])"},
    {R"("float spectrans" [1] "float eta" [1.5] "float roughness" [1])"},
    {R"("float spectrans" [1] "float eta" [1.5] "float roughness" [0.032])", 0.012f},
    {R"("float spectrans" [0.5] "float eta" [1.0001] "float roughness" [0.3])", 0.f, false},
    {R"("float spectrans" [1] "float eta" [1.5] "float roughness" [0.3] "float anisotropic" [0.8])"},
    {R"("float spectrans" [0.5] "float eta" [1.5] "float roughness" [0.5] "float clearcoat" [1] "float clearcoatgloss" [0.2] "float sheen" [1])"},
    {R"("bool thin" [true] "float spectrans" [0.5] "float roughness" [0.5] "float flatness" [0.5] "float difftrans" [1])"},
    {R"("bool thin" [true] "float flatness" [1] "float difftrans" [2] "float roughness" [0.7])"},
    {R"("bool thin" [true] "float spectrans" [1] "float eta" [2.5] "float roughness" [0.3])"},
    {R"("bool thin" [true] "float spectrans" [0.3] "float eta" [1.0001] "float roughness" [0.6] "float difftrans" [0.5])"},
};

// Near normal incidence, grazing (cos 0.05) and below the surface (inside a transmissive material).
const Vec3 kChiDirections[] = {spherical_direction(0.8f, 0.3f), spherical_direction(0.05f, 1.3f),
                               spherical_direction(-0.6f, 2.1f)};

constexpr int kChiSamples = 200'000;

// A lobe with alpha ~ 1e-3 fits in one cell of any sphere chart, and integrating its pdf over
// the chart's coarse cells takes minutes. Instead: project directions gnomonically onto the plane
// tangent at the lobe's peak (q = (x, y) / z in the peak's frame), keep the square |q| <= window,
// and histogram that. Samples outside count as declined, so the window's pdf integral must match
// the share of samples inside it, which the statistic checks too. dw = dq / (1 + |q|^2)^(3/2).
ChiSquareResult narrow_lobe_chi_square(const Bsdf& bsdf, const Vec3& wo, float window, uint64_t seed) {
  LobeSummary lobe = bsdf.lobe(wo, kRadiance);
  // A material whose diffuse part dominates reports a cosine lobe: its narrow lobe is the reflection.
  Vec3 peak = lobe.cosine ? Vec3(-wo.x, -wo.y, wo.z) : glm::normalize(lobe.peak);
  Frame frame(peak);
  auto sample = [&](Vec2 u, float uc) -> std::optional<Vec2> {
    std::optional<BsdfSample> s = bsdf.sample_f(wo, uc, u, kRadiance);
    if (!s || s->is_specular() || !(s->pdf > 0.f)) return std::nullopt;
    Vec3 l = frame.to_local(s->wi);
    if (l.z <= 0.f) return std::nullopt;
    Vec2 p = (Vec2(l.x, l.y) / l.z / window + 1.f) * 0.5f;
    if (p.x < 0.f || p.x > 1.f || p.y < 0.f || p.y > 1.f) return std::nullopt;
    return p;
  };
  auto density = [&](const Vec2& p) -> double {
    Vec2 q = (2.f * p - 1.f) * window;
    Vec3 w = frame.to_world(glm::normalize(Vec3(q.x, q.y, 1.f)));
    double jacobian = std::pow(1.0 + double(glm::dot(q, q)), -1.5) * sqr(2.f * window);
    return bsdf.pdf(wo, w, kRadiance) * jacobian;
  };
  PlaneRect rect;
  rect.max_refinements = 3;
  return chi_square_plane(sample, density, kChiSamples, 24, 24, seed, rect);
}

// Runs fn(i) for i < n on two threads (the harness is stateless; BSDFs are const).
template <typename Fn>
void parallel_for(int n, Fn fn) {
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int i; (i = next++) < n;) fn(i);
  };
  std::thread other(worker);
  worker();
  other.join();
}

// Forwards to a real BSDF but reports the density of another one, scaled: what the chi-square test
// exists to catch.
class BrokenPdf final : public Bsdf {
 public:
  BrokenPdf(const Bsdf& sampler, const Bsdf& density, float scale) : s_(sampler), d_(density), scale_(scale) {}
  uint32_t flags() const override { return s_.flags(); }
  Rgb f(const Vec3& wo, const Vec3& wi, const ShadingContext& c) const override { return s_.f(wo, wi, c); }
  std::optional<BsdfSample> sample_f(const Vec3& wo, float uc, Vec2 u, const ShadingContext& c) const override {
    return s_.sample_f(wo, uc, u, c);
  }
  float pdf(const Vec3& wo, const Vec3& wi, const ShadingContext& c) const override {
    return scale_ * d_.pdf(wo, wi, c);
  }
  LobeSummary lobe(const Vec3& wo, const ShadingContext& c) const override { return s_.lobe(wo, c); }

 private:
  const Bsdf &s_, &d_;
  float scale_;
};

}  // namespace

TEST(DisneyBsdf, SamplingMatchesPdfChiSquareOverParameterGrid) {
  constexpr int kCases = sizeof(kChiCases) / sizeof(kChiCases[0]);
  constexpr int kDirs = sizeof(kChiDirections) / sizeof(kChiDirections[0]);
  const double alpha = sidak_alpha(0.01, kCases * kDirs);
  std::vector<std::unique_ptr<Bsdf>> bsdfs;
  for (const ChiCase& c : kChiCases) bsdfs.push_back(make_bsdf("disney", c.params));

  std::vector<ChiSquareResult> results(kCases * kDirs);
  parallel_for(kCases * kDirs, [&](int i) {
    const ChiCase& c = kChiCases[i / kDirs];
    const Vec3& wo = kChiDirections[i % kDirs];
    if (c.window > 0.f) {
      results[i] = narrow_lobe_chi_square(*bsdfs[i / kDirs], wo, c.window, 1000 + i);
    } else {
      BsdfChiSquareOptions options;
      options.zoom = c.zoom;
      // Smooth lobes need little refinement; at grazing wo the horizon cuts through the zoomed cells.
      options.max_refinements = std::abs(wo.z) < 0.1f ? 4 : 2;
      results[i] = bsdf_chi_square(*bsdfs[i / kDirs], wo, kChiSamples, 1000 + i, options);
    }
  });
  for (int i = 0; i < kCases * kDirs; ++i) {
    const ChiSquareResult& r = results[i];
    const Vec3& wo = kChiDirections[i % kDirs];
    std::printf("  [chi2] p=%.4f pdf_integral=%.4f invalid=%.4f cos_o=%+.2f %s\n", r.p_value, r.pdf_integral,
                r.invalid_fraction, wo.z, kChiCases[i / kDirs].params);
    EXPECT_TRUE(r.passes(alpha)) << kChiCases[i / kDirs].params << " wo.z=" << wo.z << ": " << r.summary();
    // What sample_f declines (shadowed microfacet samples, total internal reflection, the delta
    // pass-through) is exactly the mass the density misses.
    EXPECT_NEAR(r.pdf_integral, 1.0 - r.invalid_fraction, 0.01) << kChiCases[i / kDirs].params << " wo.z=" << wo.z;
  }
}

TEST(DisneyBsdf, ChiSquareCatchesAWrongPdf) {
  // A density 20 % too high, and a clearcoat density with the wrong GTR1 alpha (pbrt-v3's
  // clearcoat samples one alpha and evaluates another). The coat alone (black base, no specular at
  // eta 1) so that its lobe carries all the samples.
  auto bsdf = make_bsdf("disney", R"("float roughness" [0.4] "float clearcoat" [1] "float clearcoatgloss" [0.3])");
  const char* coat = R"("rgb color" [0 0 0] "float eta" [1] "float clearcoat" [1] "float clearcoatgloss" )";
  auto coat_a = make_bsdf("disney", std::string(coat) + "[0.3]");
  auto coat_b = make_bsdf("disney", std::string(coat) + "[0.6]");
  Vec3 wo = spherical_direction(0.6f, 0.4f);
  BrokenPdf scaled(*bsdf, *bsdf, 1.2f);
  BrokenPdf wrong_alpha(*coat_a, *coat_b, 1.f);
  ChiSquareResult a = bsdf_chi_square(scaled, wo, kChiSamples, 5);
  ChiSquareResult b = bsdf_chi_square(wrong_alpha, wo, kChiSamples, 6);
  std::printf("  [broken] scaled pdf: p=%.3g; wrong clearcoat alpha: p=%.3g\n", a.p_value, b.p_value);
  EXPECT_FALSE(a.passes(0.01)) << a.summary();
  EXPECT_FALSE(b.passes(0.01)) << b.summary();
}

// ---- White furnace -------------------------------------------------------------------------------

namespace {

const Vec3 kFurnaceDirections[] = {spherical_direction(1.f, 0.f),     spherical_direction(0.5f, 0.7f),
                                   spherical_direction(0.05f, 1.9f),  spherical_direction(0.001f, 2.5f),
                                   spherical_direction(-0.5f, 0.4f),  spherical_direction(-0.05f, 3.f)};
constexpr int kFurnaceSamples = 100'000;

// Largest luminance albedo over kFurnaceDirections, each checked against `bound` + 4 sigma.
double max_albedo(const Bsdf& bsdf, const std::string& what, double bound, TransportMode mode) {
  double worst = 0.0;
  for (const Vec3& wo : kFurnaceDirections) {
    AlbedoEstimate e = albedo_estimate(bsdf, wo, kFurnaceSamples, 21, mode);
    double a = luminance(e.mean), sigma = luminance(e.standard_error);
    EXPECT_EQ(e.non_finite, 0) << what << " wo.z=" << wo.z;
    EXPECT_LE(a, bound + 4.0 * sigma + 1e-4) << what << " wo.z=" << wo.z;
    worst = std::max(worst, a);
  }
  std::printf("  [furnace] max albedo %.4f  %s\n", worst, what.c_str());
  return worst;
}

}  // namespace

TEST(DisneyBsdf, WhiteFurnaceMetalAndCoatConserveEnergy) {
  for (const char* r : {"0.01", "0.032", "0.3", "1"}) {
    auto metal = make_bsdf("disney", std::string(R"("rgb color" [1 1 1] "float metallic" [1] "float roughness" [)") + r + "]");
    max_albedo(*metal, std::string("metal roughness ") + r, 1.0, TransportMode::Radiance);
  }
  // A smooth mirror loses nothing except to masking right at the horizon.
  auto mirror = make_bsdf("disney", R"("rgb color" [1 1 1] "float metallic" [1] "float roughness" [0])");
  EXPECT_GT(luminance(albedo(*mirror, spherical_direction(0.5f, 0.f), kFurnaceSamples)), 0.999f);
  for (const char* g : {"0", "1"}) {
    // The coat alone: black base, no specular lobe at eta 1. Its weight 0.25 caps it far below 1.
    auto coat = make_bsdf("disney", std::string(R"("rgb color" [0 0 0] "float eta" [1] "float clearcoat" [1] "float clearcoatgloss" [)") + g + "]");
    max_albedo(*coat, std::string("clearcoat alone, gloss ") + g, 0.25, TransportMode::Radiance);
    // Disney adds the coat on top without dimming what is under it: at grazing angles, where the
    // metal's Schlick Fresnel reflects nearly everything, the sum exceeds 1 by up to the coat's
    // albedo (observed 1.006 at cos 1e-3).
    auto coated_metal = make_bsdf("disney", std::string(R"("rgb color" [0.9 0.9 0.9] "float metallic" [1] "float roughness" [0.2] "float clearcoat" [1] "float clearcoatgloss" [)") + g + "]");
    max_albedo(*coated_metal, std::string("0.9 metal + clearcoat, gloss ") + g, 1.05, TransportMode::Radiance);
  }
}

TEST(DisneyBsdf, WhiteFurnaceTransmissionConservesEnergy) {
  // Importance transport integrates the BSDF over its second argument, the direction light leaves
  // to: that is the energy balance for both sides. Radiance from outside is lower by 1/eta^2 for
  // the transmitted part (and higher from inside, so no bound there).
  for (const char* r : {"0.01", "0.032", "0.3", "1"}) {
    std::string params = std::string(R"("rgb color" [1 1 1] "float spectrans" [1] "float eta" [1.5] "float roughness" [)") + r + "]";
    auto glass = make_bsdf("disney", params);
    max_albedo(*glass, "glass (importance) roughness " + std::string(r), 1.0, TransportMode::Importance);
    for (float c : {1.f, 0.5f, 0.05f}) {
      AlbedoEstimate e = albedo_estimate(*glass, spherical_direction(c, 0.2f), kFurnaceSamples, 5);
      EXPECT_LE(luminance(e.mean), 1.0 + 4.0 * luminance(e.standard_error)) << params << " cos " << c;
    }
    auto thin = make_bsdf("disney", params + R"( "bool thin" [true])");
    max_albedo(*thin, "thin glass (importance) roughness " + std::string(r), 1.0, TransportMode::Importance);
  }
  // Smooth glass: reflection F and transmission 1 - F add up to 1.
  auto smooth = make_bsdf("disney", R"("rgb color" [1 1 1] "float spectrans" [1] "float roughness" [0])");
  EXPECT_NEAR(luminance(albedo(*smooth, spherical_direction(0.9f, 0.f), kFurnaceSamples, 11, TransportMode::Importance)),
              1.0, 2e-3);
  // eta = 1: no interface, everything passes straight through (a delta of weight 1).
  auto air = make_bsdf("disney", R"("rgb color" [1 1 1] "float spectrans" [1] "float eta" [1])");
  EXPECT_NEAR(luminance(albedo(*air, spherical_direction(0.3f, 0.f), 1000)), 1.0, 1e-4);
}

namespace {

// Albedo of Burley's diffuse model with a white base, written from Burley 2015 eq. (4) and its
// retro-reflection term (not from the plugin): f = (1/pi) (1 - F_o/2)(1 - F_i/2)
// + (1/pi) R_R (F_o + F_i + F_o F_i (R_R - 1)), F_x = (1 - cos_x)^5, R_R = 2 roughness cos^2 theta_d,
// integrated against cos theta_i by midpoint quadrature (doubling the 400 x 200 grid changes it by
// less than 1e-6).
double burley_albedo_by_quadrature(double roughness, const Vec3& wo_f) {
  glm::dvec3 wo(wo_f.x, wo_f.y, std::abs(wo_f.z));  // two-sided: the lower side mirrors the upper
  auto F = [](double c) { return std::pow(1.0 - c, 5.0); };
  return test::hemisphere_quadrature(
      [&](const glm::dvec3& wi) {
        double cos_d = glm::dot(wi, glm::normalize(wi + wo));
        double fo = F(wo.z), fi = F(wi.z), rr = 2.0 * roughness * cos_d * cos_d;
        double f = (1.0 - 0.5 * fo) * (1.0 - 0.5 * fi) + rr * (fo + fi + fo * fi * (rr - 1.0));
        return f / M_PI * wi.z;
      },
      400, 200);
}

}  // namespace

// Burley's retro-reflection adds energy at grazing angles for rough surfaces: with a white base the
// albedo exceeds 1 there (up to about 1.55 at roughness 1). The sampled albedo at every furnace
// direction equals the model's, computed independently by quadrature, within 4 standard errors; a
// 2 % bias on the same estimate would fail.
TEST(DisneyBsdf, DiffuseRetroReflectionMatchesTheModelsAlbedo) {
  double rough_max = 0.0;
  for (double roughness : {0.0, 0.5, 1.0}) {
    auto bsdf = make_bsdf("disney", fmt::format(R"("rgb color" [1 1 1] "float eta" [1] "float roughness" [{}])", roughness));
    for (const Vec3& wo : kFurnaceDirections) {
      AlbedoEstimate e = albedo_estimate(*bsdf, wo, kFurnaceSamples, 21, TransportMode::Radiance);
      double a = e.mean.g, tol = 4.0 * e.standard_error.g + 1e-4;
      double expected = burley_albedo_by_quadrature(roughness, wo);
      EXPECT_EQ(e.non_finite, 0);
      EXPECT_NEAR(a, expected, tol) << "roughness " << roughness << " wo.z " << wo.z << " +- " << e.standard_error.g;
      EXPECT_GT(std::abs(0.98 * a - expected), tol) << "a 2 % bias would pass";
      if (roughness == 1.0) rough_max = std::max(rough_max, expected);
    }
  }
  EXPECT_GT(rough_max, 1.5);  // the excess is the model's, not a sampling artefact
}

// ---- Reciprocity ---------------------------------------------------------------------------------

TEST(DisneyBsdf, ReflectionIsReciprocal) {
  for (const char* params : {
           R"("float roughness" [0.5] "float sheen" [1] "float clearcoat" [1] "float clearcoatgloss" [0.5] "rgb color" [0.7 0.4 0.2])",
           R"("float metallic" [1] "float roughness" [0.2] "float anisotropic" [0.8] "rgb color" [0.9 0.5 0.3])",
           R"("float metallic" [0.5] "float speculartint" [1] "float roughness" [0.4] "float sheen" [0.5])",
           R"("bool thin" [true] "float flatness" [0.7] "float difftrans" [0] "float roughness" [0.6])",
       }) {
    auto bsdf = make_bsdf("disney", params);
    EXPECT_LT(reciprocity_error(*bsdf, 20'000), 1e-4) << params;
  }
}

TEST(DisneyBsdf, TransmissionIsTheAdjointOfImportanceTransport) {
  // Refraction is not symmetric, but radiance one way equals importance the other way:
  // f_radiance(wo, wi) = f_importance(wi, wo) (Veach 5.3; the 1/eta^2 goes with radiance).
  ShadingContext importance;
  importance.mode = TransportMode::Importance;
  for (const char* params : {R"("float spectrans" [1] "float roughness" [0.4] "float eta" [1.5])",
                             R"("float spectrans" [1] "float roughness" [0.2] "float eta" [2.5] "float anisotropic" [0.5])",
                             R"("bool thin" [true] "float spectrans" [0.7] "float roughness" [0.5] "float difftrans" [1])"}) {
    auto bsdf = make_bsdf("disney", params);
    Pcg32 rng(3);
    double worst = 0.0;
    for (int i = 0; i < 20'000; ++i) {
      // Not within cos 0.05 of the horizon: there F -> 1 and 1 - F cancels in float.
      Vec3 a = spherical_direction(0.05f + 0.95f * rng.next_float(), 2.f * Pi * rng.next_float());
      Vec3 b = spherical_direction(-0.05f - 0.95f * rng.next_float(), 2.f * Pi * rng.next_float());
      for (int k = 0; k < 2; ++k) {
        Rgb forward = bsdf->f(a, b, kRadiance), backward = bsdf->f(b, a, importance);
        // Relative to at least 0.01: next to total internal reflection 1 - F cancels too.
        for (int ch = 0; ch < 3; ++ch) {
          double m = std::max({double(forward[ch]), double(backward[ch]), 1e-2});
          worst = std::max(worst, std::abs(double(forward[ch]) - backward[ch]) / m);
        }
        std::swap(a, b);
      }
    }
    EXPECT_LT(worst, 1e-3) << params;
  }
}

// ---- Robustness ----------------------------------------------------------------------------------

TEST(DisneyBsdf, EdgeCasesStayFinite) {
  const std::pair<const char*, const char*> kEdgeCases[] = {
      {"disney", R"("float metallic" [1] "float roughness" [0])"},
      {"disney", R"("float roughness" [0.0001] "float clearcoat" [1])"},
      {"disney", R"("float spectrans" [1] "float roughness" [0] "float eta" [1.5])"},
      {"disney", R"("float spectrans" [1] "float eta" [1])"},
      {"disney", R"("float spectrans" [1] "float eta" [1.0001] "float roughness" [0.5])"},
      {"disney", R"("float spectrans" [1] "float eta" [1.0011] "float roughness" [0])"},
      {"disney", R"("rgb color" [0 0 0] "float eta" [1])"},
      {"disney", R"("bool thin" [true] "float spectrans" [1] "float roughness" [0] "float eta" [2.5])"},
      {"disney", R"("bool thin" [true] "float spectrans" [0.5] "float eta" [1.0001] "float flatness" [1] "float difftrans" [2] "float roughness" [0])"},
      {"disney", R"("float anisotropic" [1] "float roughness" [0.3] "float clearcoat" [1] "float clearcoatgloss" [1] "float sheen" [1] "float metallic" [0.5])"},
      {"disney", R"("float roughness" [1] "float eta" [0.5] "float spectrans" [0.5])"},
      {"coateddiffuse", R"("float roughness" [0])"},
  };
  Pcg32 rng(99);
  auto random_direction = [&] {
    float z = 2.f * rng.next_float() - 1.f;
    // Every third direction is one of the hard ones: normal, grazing, exactly in the plane.
    const float special[] = {1.f, -1.f, 1e-4f, -1e-4f, 0.05f, -0.05f, 0.f};
    if (rng.next_u32() % 3 == 0) z = special[rng.next_u32() % 7];
    return spherical_direction(z, 2.f * Pi * rng.next_float());
  };
  auto finite_nonnegative = [](const Rgb& c) { return is_finite(c) && c.r >= 0.f && c.g >= 0.f && c.b >= 0.f; };
  for (const auto& [name, params] : kEdgeCases) {
    auto bsdf = make_bsdf(name, params);
    int bad = 0;
    for (int i = 0; i < 20'000; ++i) {
      ShadingContext ctx;
      ctx.mode = i % 2 ? TransportMode::Importance : TransportMode::Radiance;
      Vec3 wo = random_direction();
      // Also the degenerate partners: straight through, the mirror direction, wo itself.
      Vec3 candidates[] = {random_direction(), -wo, Vec3(-wo.x, -wo.y, wo.z), wo};
      for (const Vec3& wi : candidates) {
        Rgb f = bsdf->f(wo, wi, ctx);
        float p = bsdf->pdf(wo, wi, ctx);
        if (!finite_nonnegative(f) || !std::isfinite(p) || p < 0.f) {
          if (++bad < 5) ADD_FAILURE() << name << " " << params << ": f or pdf not finite at wo.z=" << wo.z << " wi.z=" << wi.z;
        }
      }
      std::optional<BsdfSample> s = bsdf->sample_f(wo, rng.next_float(), Vec2(rng.next_float(), rng.next_float()), ctx);
      if (!s) continue;
      float throughput = luminance(s->f) * std::abs(s->wi.z) / s->pdf;
      bool ok = finite_nonnegative(s->f) && std::isfinite(s->pdf) && s->pdf > 0.f && is_finite(s->wi) &&
                std::abs(glm::length(s->wi) - 1.f) < 1e-3f && std::isfinite(throughput);
      if (!ok && ++bad < 5)
        ADD_FAILURE() << name << " " << params << ": bad sample at wo.z=" << wo.z << " pdf=" << s->pdf;
    }
    EXPECT_EQ(bad, 0) << name << " " << params;
  }
}

TEST(DisneyBsdf, SampledValuesAgreeWithEvaluation) {
  for (const char* params : {R"("float roughness" [0.4] "float sheen" [1] "float clearcoat" [1] "float metallic" [0.3])",
                             R"("float spectrans" [0.8] "float roughness" [0.2] "float eta" [1.33])",
                             R"("bool thin" [true] "float spectrans" [0.5] "float flatness" [0.5] "float roughness" [0.6])"}) {
    auto bsdf = make_bsdf("disney", params);
    for (float c : {0.7f, 0.05f, -0.4f}) {
      PdfConsistency r = pdf_consistency(*bsdf, spherical_direction(c, 0.9f), 20'000);
      EXPECT_GT(r.checked, 10'000) << params;
      EXPECT_LT(r.max_pdf_error, 1e-4) << params << " cos " << c;
      EXPECT_LT(r.max_f_error, 1e-4) << params << " cos " << c;
    }
  }
}

// ---- Lobe summary, parameters ---------------------------------------------------------------------

TEST(DisneyBsdf, LobeReportsTheDominantLobe) {
  Vec3 wo = spherical_direction(0.6f, 0.5f);
  auto metal = make_bsdf("disney", R"("float metallic" [1] "float roughness" [0.3] "float anisotropic" [0.5])");
  LobeSummary l = metal->lobe(wo, kRadiance);
  EXPECT_FALSE(l.cosine);
  EXPECT_NEAR(glm::distance(l.peak, Vec3(-wo.x, -wo.y, wo.z)), 0.f, 1e-5f);
  float aspect = std::sqrt(1.f - 0.45f);
  EXPECT_NEAR(l.alpha_x, 0.09f / aspect, 1e-5f);
  EXPECT_NEAR(l.alpha_y, 0.09f * aspect, 1e-5f);
  EXPECT_GT(l.coefficient, 0.3f);

  auto plastic = make_bsdf("disney", R"("float roughness" [0.5] "rgb color" [0.8 0.8 0.8])");
  l = plastic->lobe(-wo, kRadiance);
  EXPECT_TRUE(l.cosine);
  EXPECT_EQ(l.peak, Vec3(0.f, 0.f, -1.f));  // on wo's side

  // Glass seen from outside sends most light along the refracted direction.
  auto glass = make_bsdf("disney", R"("float spectrans" [1] "float roughness" [0.1] "float eta" [1.5])");
  l = glass->lobe(wo, kRadiance);
  EXPECT_FALSE(l.cosine);
  EXPECT_LT(l.peak.z, 0.f);
  EXPECT_NEAR(std::sqrt(1.f - sqr(l.peak.z)), std::sqrt(1.f - sqr(wo.z)) / 1.5f, 1e-4f);  // Snell
}

TEST(DisneyBsdf, RejectsBadAndUnsupportedParameters) {
  EXPECT_THROW(make_bsdf("disney", R"("float metallic" [1.5])"), Error);
  EXPECT_THROW(make_bsdf("disney", R"("float eta" [0])"), Error);
  EXPECT_THROW(make_bsdf("disney", R"("rgb color" [1.2 0 0])"), Error);
  EXPECT_THROW(make_bsdf("disney", R"("float difftrans" [2.5])"), Error);
  EXPECT_THROW(make_bsdf("disney", R"("rgb scatterdistance" [1 1 1])"), Error);
  EXPECT_THROW(make_bsdf("coateddiffuse", R"("float g" [1.5])"), Error);  // layered: g in (-1, 1)
  EXPECT_NO_THROW(make_bsdf("disney", R"("float difftrans" [2] "bool thin" [true])"));
}

// ---- Smooth lobes are deltas (TrowbridgeReitz::kSmoothAlpha, shared with conductor and dielectric) --

namespace {

// Above, grazing, at the pole and below (two-sided metal; the inside of glass).
const Vec3 kDeltaDirections[] = {spherical_direction(1.f, 0.f),    spherical_direction(0.8f, 0.3f),
                                 spherical_direction(0.3f, 2.f),   spherical_direction(0.02f, 4.f),
                                 spherical_direction(-0.6f, 1.1f), spherical_direction(-0.9f, 5.f),
                                 spherical_direction(-1.f, 0.f)};

Rgb weight_of(const BsdfSample& s) { return s.f * std::abs(s.wi.z) / s.pdf; }
// Largest component of |a - b| (Rgb and Vec3 are the same type).
float max_difference(const Vec3& a, const Vec3& b) {
  Vec3 d = glm::abs(a - b);
  return std::max({d.x, d.y, d.z});
}
double schlick(double r0, double cos_theta) { return r0 + (1.0 - r0) * std::pow(1.0 - cos_theta, 5.0); }

// f() and pdf() of a BSDF made of delta lobes only are 0 for any pair of directions, the delta's own
// direction included.
void expect_no_density(const Bsdf& bsdf, const Vec3& wo, const Vec3& delta_direction, const std::string& what) {
  Pcg32 rng(5);
  for (int i = 0; i < 64; ++i) {
    Vec3 wi = i == 0 ? delta_direction : spherical_direction(2.f * rng.next_float() - 1.f, 2.f * Pi * rng.next_float());
    for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
      ShadingContext ctx;
      ctx.mode = mode;
      EXPECT_EQ(bsdf.f(wo, wi, ctx), Rgb(0.f)) << what << " wo.z=" << wo.z << " wi.z=" << wi.z;
      EXPECT_EQ(bsdf.pdf(wo, wi, ctx), 0.f) << what << " wo.z=" << wo.z << " wi.z=" << wi.z;
    }
  }
}

// Forwards to a real BSDF, with every sample's weight scaled: a 2 % bias the furnace check must see.
class ScaledWeight final : public Bsdf {
 public:
  ScaledWeight(const Bsdf& bsdf, float scale) : b_(bsdf), scale_(scale) {}
  uint32_t flags() const override { return b_.flags(); }
  Rgb f(const Vec3& wo, const Vec3& wi, const ShadingContext& c) const override { return b_.f(wo, wi, c); }
  std::optional<BsdfSample> sample_f(const Vec3& wo, float uc, Vec2 u, const ShadingContext& c) const override {
    std::optional<BsdfSample> s = b_.sample_f(wo, uc, u, c);
    if (s) s->f *= scale_;
    return s;
  }
  float pdf(const Vec3& wo, const Vec3& wi, const ShadingContext& c) const override { return b_.pdf(wo, wi, c); }
  LobeSummary lobe(const Vec3& wo, const ShadingContext& c) const override { return b_.lobe(wo, c); }

 private:
  const Bsdf& b_;
  float scale_;
};

}  // namespace

TEST(DisneyBsdf, SmoothThresholdIsConductorsOnBothAxesAfterAnisotropy) {
  // alpha = roughness^2, stretched to alpha / aspect and alpha * aspect (aspect = sqrt(1 - 0.9 aniso)).
  struct Case {
    const char* params;
    bool delta;
  };
  const Case cases[] = {
      {R"("float metallic" [1] "float roughness" [0])", true},
      {R"("float metallic" [1] "float roughness" [0.0316])", true},    // alpha 9.99e-4
      {R"("float metallic" [1] "float roughness" [0.032])", false},    // alpha 1.024e-3
      {R"("float metallic" [1] "float roughness" [0.01] "float anisotropic" [1])", true},   // 3.2e-4, 3.2e-5
      {R"("float metallic" [1] "float roughness" [0.02] "float anisotropic" [1])", false},  // 1.26e-3 along s
  };
  for (const Case& c : cases) {
    auto bsdf = make_bsdf("disney", c.params);
    EXPECT_EQ(bsdf->flags(), uint32_t(BsdfReflection | (c.delta ? BsdfSpecular : BsdfGlossy))) << c.params;
    EXPECT_EQ(bsdf->is_specular_only(), c.delta) << c.params;
    std::optional<BsdfSample> s = bsdf->sample_f(spherical_direction(0.7f, 0.2f), 0.5f, Vec2(0.3f, 0.6f), kRadiance);
    ASSERT_TRUE(s) << c.params;
    EXPECT_EQ(s->is_specular(), c.delta) << c.params;
  }
  EXPECT_EQ(TrowbridgeReitz::kSmoothAlpha, 1e-3f);
}

TEST(DisneyBsdf, SmoothMetalIsTheConductorMirror) {
  // A white metal against conductor's near-perfect mirror (eta 1, k 1e4: F = 1 - O(1e-8) at every
  // angle, as Schlick's F with R0 = 1 is exactly): same directions, same weights.
  auto disney = make_bsdf("disney", R"("rgb color" [1 1 1] "float metallic" [1] "float roughness" [0])");
  auto mirror = make_bsdf("conductor", R"("rgb eta" [1 1 1] "rgb k" [10000 10000 10000] "float roughness" [0])");
  // A coloured metal against conductor with the same reflectance at normal incidence: Disney's
  // Fresnel is Schlick's from R0 = color, conductor's the exact one of eta 1 and k from R0, so the
  // weights agree at normal incidence and each follows its own Fresnel elsewhere.
  const Rgb r0(0.9f, 0.6f, 0.3f);
  auto disney_c = make_bsdf("disney", R"("rgb color" [0.9 0.6 0.3] "float metallic" [1] "float roughness" [0])");
  auto copperish = make_bsdf("conductor", R"("rgb reflectance" [0.9 0.6 0.3] "float roughness" [0])");
  for (const Bsdf* b : {disney.get(), mirror.get(), disney_c.get(), copperish.get()})
    EXPECT_EQ(b->flags(), uint32_t(BsdfReflection | BsdfSpecular));

  Pcg32 rng(41);
  float worst_direction = 0.f, worst_weight = 0.f, worst_schlick = 0.f, largest_model_gap = 0.f;
  for (const Vec3& wo : kDeltaDirections) {
    const Vec3 reflected(-wo.x, -wo.y, wo.z);
    expect_no_density(*disney, wo, reflected, "disney metal");
    expect_no_density(*disney_c, wo, reflected, "disney coloured metal");
    for (int i = 0; i < 16; ++i) {
      float uc = rng.next_float();
      Vec2 u(rng.next_float(), rng.next_float());
      ShadingContext ctx;
      ctx.mode = i % 2 ? TransportMode::Importance : TransportMode::Radiance;
      std::optional<BsdfSample> a = disney->sample_f(wo, uc, u, ctx), b = mirror->sample_f(wo, uc, u, ctx);
      std::optional<BsdfSample> c = disney_c->sample_f(wo, uc, u, ctx), d = copperish->sample_f(wo, uc, u, ctx);
      ASSERT_TRUE(a && b && c && d) << "wo.z=" << wo.z;
      for (const BsdfSample* s : {&*a, &*b, &*c, &*d}) {
        EXPECT_EQ(s->flags, uint32_t(BsdfReflection | BsdfSpecular)) << "wo.z=" << wo.z;
        EXPECT_EQ(s->pdf, 1.f) << "wo.z=" << wo.z;  // the only lobe
        worst_direction = std::max(worst_direction, max_difference(s->wi, reflected));
      }
      worst_weight = std::max(worst_weight, max_difference(weight_of(*a), weight_of(*b)));
      Rgb expected_schlick(schlick(r0.r, std::abs(wo.z)), schlick(r0.g, std::abs(wo.z)), schlick(r0.b, std::abs(wo.z)));
      worst_schlick = std::max(worst_schlick, max_difference(weight_of(*c), expected_schlick));
      if (std::abs(wo.z) == 1.f) {
        EXPECT_LT(max_difference(weight_of(*c), weight_of(*d)), 1e-5f) << "normal incidence, wo.z=" << wo.z;
        EXPECT_LT(max_difference(weight_of(*d), r0), 1e-5f);
      }
      largest_model_gap = std::max(largest_model_gap, max_difference(weight_of(*c), weight_of(*d)));
    }
  }
  std::printf("  [mirror] direction error %.2g, weight vs conductor %.2g, coloured weight vs Schlick %.2g; "
              "Schlick vs exact conductor Fresnel (same R0) up to %.3f off normal incidence\n",
              worst_direction, worst_weight, worst_schlick, largest_model_gap);
  EXPECT_LT(worst_direction, 1e-6f);
  EXPECT_LT(worst_weight, 1e-5f);
  EXPECT_LT(worst_schlick, 1e-5f);
}

TEST(DisneyBsdf, SmoothGlassIsTheDielectric) {
  auto disney = make_bsdf("disney", R"("rgb color" [1 1 1] "float spectrans" [1] "float eta" [1.5] "float roughness" [0])");
  auto glass = make_bsdf("dielectric", R"("float eta" [1.5] "float roughness" [0])");
  const uint32_t kFlags = BsdfReflection | BsdfTransmission | BsdfSpecular;
  EXPECT_EQ(disney->flags(), kFlags);
  EXPECT_EQ(glass->flags(), kFlags);
  float worst_direction = 0.f, worst_weight = 0.f, worst_probability = 0.f;
  int refractions = 0, total_internal = 0;
  for (const Vec3& wo : kDeltaDirections) {
    for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
      ShadingContext ctx;
      ctx.mode = mode;
      // uc = 0 picks reflection in both; uc just below 1 refraction, unless there is none (total
      // internal reflection, where both reflect with probability 1).
      for (float uc : {0.f, 0.999999f}) {
        std::optional<BsdfSample> a = disney->sample_f(wo, uc, Vec2(0.4f, 0.7f), ctx);
        std::optional<BsdfSample> b = glass->sample_f(wo, uc, Vec2(0.4f, 0.7f), ctx);
        ASSERT_TRUE(a && b) << "wo.z=" << wo.z << " uc=" << uc;
        EXPECT_EQ(a->flags, b->flags) << "wo.z=" << wo.z << " uc=" << uc;
        EXPECT_TRUE(a->is_specular());
        worst_direction = std::max(worst_direction, max_difference(a->wi, b->wi));
        worst_weight = std::max(worst_weight, max_difference(weight_of(*a), weight_of(*b)));
        worst_probability = std::max(worst_probability, std::abs(a->pdf - b->pdf));
        if (uc > 0.f) (a->flags & BsdfTransmission ? refractions : total_internal) += 1;
        expect_no_density(*disney, wo, a->wi, "disney glass");
      }
    }
  }
  std::printf("  [glass] direction error %.2g, weight error %.2g, lobe probability error %.2g (%d refractions, "
              "%d total internal reflections)\n",
              worst_direction, worst_weight, worst_probability, refractions, total_internal);
  EXPECT_LT(worst_direction, 1e-5f);
  EXPECT_LT(worst_weight, 1e-5f);
  EXPECT_LT(worst_probability, 1e-5f);
  EXPECT_GT(refractions, 0);
  EXPECT_GT(total_internal, 0);  // wo.z = -0.6 is past the critical angle (cos 0.745) from inside

  // Thin: the refraction is a straight pass-through of weight 1 - F, picked with probability 1 - F
  // (throughput exactly 1 in both modes: the two interfaces undo each other's radiance scaling).
  auto thin = make_bsdf("disney", R"("bool thin" [true] "rgb color" [1 1 1] "float spectrans" [1] "float eta" [1.5] "float roughness" [0])");
  EXPECT_EQ(thin->flags(), kFlags);
  for (const Vec3& wo : kDeltaDirections) {
    float eta = wo.z > 0.f ? 1.5f : 1.f / 1.5f;
    float T = 1.f - fresnel_dielectric(std::abs(wo.z), eta);
    for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
      ShadingContext ctx;
      ctx.mode = mode;
      std::optional<BsdfSample> s = thin->sample_f(wo, 0.999999f, Vec2(0.5f), ctx);
      ASSERT_TRUE(s);
      if (T == 0.f) {
        EXPECT_EQ(s->flags, uint32_t(BsdfReflection | BsdfSpecular));
        continue;
      }
      EXPECT_EQ(s->flags, uint32_t(BsdfTransmission | BsdfSpecular)) << "wo.z=" << wo.z;
      EXPECT_EQ(s->wi, -wo);
      EXPECT_NEAR(s->pdf, T, 1e-5f) << "wo.z=" << wo.z;
      EXPECT_LT(max_difference(weight_of(*s), Rgb(1.f)), 1e-5f) << "wo.z=" << wo.z;
      expect_no_density(*thin, wo, -wo, "thin disney glass");
    }
  }
}

// A delta next to other lobes: sample_f picks among all of them, f() and pdf() describe the others
// only (so the chi-square of the non-delta samples against pdf() must pass, and the pdf integrates to
// the share of non-delta samples), flags() has Specular and the others' bits.
TEST(DisneyBsdf, MixedDeltaAndOtherLobesSampleTheirPdf) {
  const char* kMixed[] = {
      R"("float metallic" [0.5] "float roughness" [0])",
      R"("float roughness" [0.01] "rgb color" [0.8 0.3 0.2])",  // plastic: the dielectric part is a mirror
      R"("float metallic" [1] "float roughness" [0] "float clearcoat" [1] "float clearcoatgloss" [0.5])",
      R"("float spectrans" [0.5] "float eta" [1.5] "float roughness" [0])",
      R"("bool thin" [true] "float spectrans" [0.5] "float roughness" [0] "float flatness" [0.5] "float difftrans" [1])",
  };
  constexpr int kCases = sizeof(kMixed) / sizeof(kMixed[0]);
  constexpr int kDirs = sizeof(kChiDirections) / sizeof(kChiDirections[0]);
  const double alpha = sidak_alpha(0.01, kCases * kDirs);
  std::vector<std::unique_ptr<Bsdf>> bsdfs;
  for (const char* p : kMixed) {
    bsdfs.push_back(make_bsdf("disney", p));
    uint32_t f = bsdfs.back()->flags();
    EXPECT_TRUE(f & BsdfSpecular) << p;
    EXPECT_TRUE(f & (BsdfDiffuse | BsdfGlossy)) << p;
    EXPECT_FALSE(bsdfs.back()->is_specular_only()) << p;
  }
  std::vector<ChiSquareResult> results(kCases * kDirs);
  parallel_for(kCases * kDirs, [&](int i) {
    BsdfChiSquareOptions options;
    options.max_refinements = std::abs(kChiDirections[i % kDirs].z) < 0.1f ? 4 : 2;
    results[i] = bsdf_chi_square(*bsdfs[i / kDirs], kChiDirections[i % kDirs], kChiSamples, 2000 + i, options);
  });
  for (int i = 0; i < kCases * kDirs; ++i) {
    const ChiSquareResult& r = results[i];
    const Vec3& wo = kChiDirections[i % kDirs];
    std::printf("  [mixed chi2] p=%.4f pdf_integral=%.4f delta+declined=%.4f cos_o=%+.2f %s\n", r.p_value,
                r.pdf_integral, r.invalid_fraction, wo.z, kMixed[i / kDirs]);
    EXPECT_TRUE(r.passes(alpha)) << kMixed[i / kDirs] << " wo.z=" << wo.z << ": " << r.summary();
    EXPECT_NEAR(r.pdf_integral, 1.0 - r.invalid_fraction, 0.01) << kMixed[i / kDirs] << " wo.z=" << wo.z;
    EXPECT_GT(r.invalid_fraction, 0.01) << "the delta lobe is sampled: " << kMixed[i / kDirs];
    PdfConsistency c = pdf_consistency(*bsdfs[i / kDirs], wo, 100'000);  // the coat case samples its coat 2 % of the time
    EXPECT_GT(c.checked, 1000) << kMixed[i / kDirs];
    EXPECT_LT(c.max_pdf_error, 1e-4) << kMixed[i / kDirs] << " wo.z=" << wo.z;
    EXPECT_LT(c.max_f_error, 1e-4) << kMixed[i / kDirs] << " wo.z=" << wo.z;
  }
}

TEST(DisneyBsdf, MixedMirrorAndDiffuseFurnaceMatchesClosedForm) {
  // White base, metallic 0.5, roughness 0, eta 1.5: a mirror of weight
  //   F(c) = 0.5 F_dielectric(c, 1.5) + 0.5 Schlick(R0 = lerp(0.04, 1, 0.5) = 0.52, c)
  // plus Burley's diffuse 0.5 (1 - Fo/2)(1 - Fi/2)/pi (no retro-reflection at roughness 0), whose
  // albedo is 0.5 (1 - Fo/2)(1 - 1/42), Fo = (1 - c)^5, since 2 int_0^1 (1 - mu)^5 mu dmu = 1/21.
  // The estimate must match that within 4 standard errors from its own sample variance, and a 2 %
  // bias in the weights must not. Disney adds diffuse and specular without coupling them, so at
  // grazing angles the albedo exceeds 1 (1.11 at cos 0.05, the closed form says so too); up to
  // cos 0.2 it stays below 1.
  auto bsdf = make_bsdf("disney", R"("rgb color" [1 1 1] "float metallic" [0.5] "float roughness" [0])");
  ScaledWeight biased(*bsdf, 1.02f);
  auto expected = [](double c) {
    double fo = std::pow(1.0 - c, 5.0);
    double mirror = 0.5 * fresnel_dielectric(float(c), 1.5f) + 0.5 * schlick(0.52, c);
    return mirror + 0.5 * (1.0 - 0.5 * fo) * (1.0 - 1.0 / 42.0);
  };
  constexpr int kSamples = 400'000;
  for (float c : {1.f, 0.7f, 0.4f, 0.2f, 0.05f, -0.5f}) {
    Vec3 wo = spherical_direction(c, 0.8f);
    double truth = expected(std::abs(c));
    for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
      AlbedoEstimate e = albedo_estimate(*bsdf, wo, kSamples, 77, mode);
      AlbedoEstimate b = albedo_estimate(biased, wo, kSamples, 77, mode);
      EXPECT_EQ(e.non_finite, 0);
      for (int ch = 0; ch < 3; ++ch) {
        double z = (e.mean[ch] - truth) / e.standard_error[ch];
        double z_biased = (b.mean[ch] - truth) / b.standard_error[ch];
        if (ch == 0)
          std::printf("  [mixed furnace] cos %+.2f: %.5f +- %.5f, closed form %.5f (z = %+.2f; 2 %% biased: z = %+.1f)\n",
                      c, e.mean[ch], e.standard_error[ch], truth, z, z_biased);
        EXPECT_LT(std::abs(z), 4.0) << "cos " << c << " channel " << ch;
        EXPECT_GT(std::abs(z_biased), 4.0) << "the check must catch a 2 % bias: cos " << c;
        if (std::abs(c) >= 0.2f) {
          EXPECT_LE(e.mean[ch], 1.0 + 4.0 * e.standard_error[ch]) << "cos " << c;
        }
      }
    }
  }
}

TEST(DisneyBsdf, LobeSummaryLeavesDeltasOutWhenThereAreOtherLobes) {
  Vec3 wo = spherical_direction(0.6f, 0.5f);
  Vec3 reflected(-wo.x, -wo.y, wo.z);
  // A mirror that would dominate (weight ~0.9) next to a faint diffuse: connections only see the diffuse.
  auto mostly_mirror = make_bsdf("disney", R"("rgb color" [1 1 1] "float metallic" [0.9] "float roughness" [0])");
  LobeSummary l = mostly_mirror->lobe(wo, kRadiance);
  EXPECT_TRUE(l.cosine);
  EXPECT_NEAR(l.coefficient, 0.1f, 1e-3f);
  // Mirror + clear coat: the coat's GTR1 lobe.
  auto coated = make_bsdf("disney", R"("float metallic" [1] "float roughness" [0] "float clearcoat" [1] "float clearcoatgloss" [0.5])");
  l = coated->lobe(wo, kRadiance);
  EXPECT_FALSE(l.cosine);
  EXPECT_NEAR(l.alpha_x, 0.0505f, 1e-5f);
  EXPECT_LT(glm::distance(l.peak, reflected), 1e-5f);
  // Deltas only: the strongest delta, narrower than the threshold, as conductor reports its mirror.
  auto metal = make_bsdf("disney", R"("float metallic" [1] "float roughness" [0])");
  l = metal->lobe(wo, kRadiance);
  EXPECT_FALSE(l.cosine);
  EXPECT_LT(glm::distance(l.peak, reflected), 1e-5f);
  EXPECT_LT(std::max(l.alpha_x, l.alpha_y), TrowbridgeReitz::kSmoothAlpha);
  auto glass = make_bsdf("disney", R"("float spectrans" [1] "float roughness" [0] "float eta" [1.5])");
  l = glass->lobe(wo, kRadiance);
  EXPECT_LT(std::max(l.alpha_x, l.alpha_y), TrowbridgeReitz::kSmoothAlpha);
  EXPECT_NEAR(std::sqrt(1.f - sqr(l.peak.z)), std::sqrt(1.f - sqr(wo.z)) / 1.5f, 1e-4f);  // refracted
}

// A white Disney metal (Schlick F with F0 = 1: F = 1) reflects exactly the single-scattering albedo
// of its GGX microfacets (alpha = roughness^2), bounded from below as well as above; a BSDF 2 % too
// dark or too bright would fail (checked on the same estimate).
TEST(DisneyBsdf, RoughWhiteMetalMatchesIndependentAlbedo) {
  for (double roughness : {0.3, 0.5, 1.0}) {
    auto bsdf = test::make_bsdf("disney", fmt::format(R"("rgb color" [1 1 1] "float metallic" [1] "float roughness" [{}])",
                                                      roughness));
    for (double cos_o : {0.9, 0.5, 0.2}) {
      Vec3 wo(static_cast<float>(std::sqrt(1.0 - cos_o * cos_o)), 0.f, static_cast<float>(cos_o));
      double expected = test::ggx_albedo_by_quadrature(roughness * roughness, cos_o);
      test::AlbedoEstimate a = test::albedo_estimate(*bsdf, wo, 200'000, 6);
      double tol = 4.0 * a.standard_error.g + 1e-4;
      std::printf("disney metal roughness %.1f cos %.1f: albedo %.5f +- %.5f, quadrature %.5f\n", roughness, cos_o,
                  a.mean.g, a.standard_error.g, expected);
      EXPECT_NEAR(a.mean.g, expected, tol) << "roughness " << roughness << " cos " << cos_o;
      EXPECT_GT(std::abs(0.98 * a.mean.g - expected), tol) << "a 2 % bias would pass";
      EXPECT_GT(std::abs(1.02 * a.mean.g - expected), tol) << "a 2 % bias would pass";
    }
  }
}

