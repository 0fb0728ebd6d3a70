// The "conductor" and "dielectric" plugins, loaded through the registry: sampling against pdf over
// a grid of roughnesses, IORs and directions (chi-square, Šidák-corrected over the grid), white
// furnace, reciprocity and adjointness, and the delta cases.
#include "support/bsdf_harness.h"

#include <penumbra/error.h>
#include <penumbra/microfacet.h>

#include <gtest/gtest.h>

#include <fmt/core.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <span>
#include <string>
#include <thread>
#include <vector>

namespace penumbra {
namespace {

using test::make_bsdf;
using test::spherical_direction;

struct Case {
  std::string plugin, params;
};

std::string describe(const Case& c, const Vec3& wo) {
  return fmt::format("{} {} at wo = ({:.3f}, {:.3f}, {:.3f})", c.plugin, c.params, wo.x, wo.y, wo.z);
}

// pbrt-v4's default remap turns roughness r into alpha = sqrt(r); veach-mis uses alpha directly.
const std::vector<Case> kConductors = {
    {"conductor", R"("float roughness" [0.01])"},
    {"conductor", R"("float roughness" [0.05])"},
    {"conductor", R"("float roughness" [0.3])"},
    {"conductor", R"("float roughness" [1])"},
    {"conductor", R"("float uroughness" [0.05] "float vroughness" [0.3])"},
    {"conductor", R"("float roughness" [0.05] "bool remaproughness" false)"},
    {"conductor", R"("float roughness" [0.01] "bool remaproughness" false)"},
};
const Vec3 kConductorViews[] = {spherical_direction(0.95f, 0.3f), spherical_direction(0.5f, 2.f),
                                spherical_direction(0.05f, 4.f)};

std::vector<Case> dielectric_cases() {
  std::vector<Case> cases;
  for (float eta : {1.33f, 1.5f, 2.5f})
    for (float roughness : {0.01f, 0.1f, 0.3f, 1.f})
      cases.push_back({"dielectric", fmt::format(R"("float eta" [{}] "float roughness" [{}])", eta, roughness)});
  return cases;
}
// Outside and inside the medium, each from near-normal to grazing.
const Vec3 kDielectricViews[] = {spherical_direction(0.95f, 0.3f),  spherical_direction(0.5f, 2.f),
                                 spherical_direction(0.05f, 4.f),   spherical_direction(-0.95f, 1.f),
                                 spherical_direction(-0.5f, 5.f),   spherical_direction(-0.05f, 3.f)};

constexpr int kSamples = 200'000;

int grid_size() {
  return int(kConductors.size() * std::size(kConductorViews) + dielectric_cases().size() * std::size(kDielectricViews));
}

// Runs the chi-square test for every (case, direction) on two threads, then checks the results.
void expect_chi_square_grid_passes(const std::vector<Case>& cases, std::span<const Vec3> views, uint64_t seed) {
  std::vector<std::unique_ptr<Bsdf>> bsdfs;
  for (const Case& c : cases) bsdfs.push_back(make_bsdf(c.plugin, c.params));
  const int n = int(cases.size() * views.size());
  std::vector<test::ChiSquareResult> results(n);
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int i; (i = next++) < n;)
      results[i] = test::bsdf_chi_square(*bsdfs[i / views.size()], views[i % views.size()], kSamples, seed + i);
  };
  std::thread other(worker);
  worker();
  other.join();

  const double alpha = test::sidak_alpha(0.01, grid_size());
  for (int i = 0; i < n; ++i) {
    const test::ChiSquareResult& r = results[i];
    std::string what = describe(cases[i / views.size()], views[i % views.size()]);
    EXPECT_TRUE(r.passes(alpha)) << what << ": " << r.summary();
    // Everything the sampler produced is accounted for by the pdf (it declines, never lies).
    EXPECT_NEAR(r.pdf_integral, 1.0 - r.invalid_fraction, 5e-3) << what << ": " << r.summary();
    if (std::getenv("PENUMBRA_VERBOSE_CHI2")) std::printf("%s: %s\n", what.c_str(), r.summary().c_str());
  }
}

TEST(Conductor, SamplingMatchesPdf) { expect_chi_square_grid_passes(kConductors, kConductorViews, 100); }

TEST(Dielectric, SamplingMatchesPdf) { expect_chi_square_grid_passes(dielectric_cases(), kDielectricViews, 200); }

// At eta = 1.0001 the transmitted lobe is a spike around -wo, at most acos(1/eta) = 0.0141 rad
// wide and mostly ~1e-4: far below what a histogram over the sphere resolves. Chart it instead in
// the plane tangent to -wo, with coordinates x = asinh(p / 1e-5) / asinh(0.015 / 1e-5) per axis of
// the projection p, which spreads decades of deviation evenly over the cells.
TEST(Dielectric, NearlyIndexMatchedTransmissionMatchesPdf) {
  constexpr double kEps = 1e-5, kHalfWidth = 0.015;
  const double scale = std::asinh(kHalfWidth / kEps);
  auto bsdf = make_bsdf("dielectric", R"("float eta" [1.0001] "float roughness" [0.3])");
  const Vec3 views[] = {spherical_direction(0.95f, 0.3f), spherical_direction(0.05f, 4.f),
                        spherical_direction(-0.5f, 5.f), spherical_direction(-0.05f, 3.f)};
  uint64_t seed = 300;
  for (Vec3 wo : views) {
    Frame frame(-wo);
    auto sampler = [&](Vec2 u, float uc) -> std::optional<Vec2> {
      auto s = bsdf->sample_f(wo, uc, u, {});
      if (!s || !(s->flags & BsdfTransmission)) return std::nullopt;  // the reflections go elsewhere
      Vec3 p = frame.to_local(s->wi);
      return Vec2(float(std::asinh(p.x / kEps) / scale), float(std::asinh(p.y / kEps) / scale));
    };
    auto density = [&](const Vec2& x) -> double {
      double px = kEps * std::sinh(x.x * scale), py = kEps * std::sinh(x.y * scale);
      double pz2 = 1.0 - px * px - py * py;
      if (pz2 <= 0.0) return 0.0;
      Vec3 wi = frame.to_world(Vec3(float(px), float(py), float(std::sqrt(pz2))));
      // d(omega) = dpx dpy / pz, and dp/dx = eps scale cosh(x scale) per axis.
      double jacobian = kEps * scale * std::cosh(x.x * scale) * kEps * scale * std::cosh(x.y * scale) / std::sqrt(pz2);
      return bsdf->pdf(wo, wi, {}) * jacobian;
    };
    test::PlaneRect rect{-1.0, -1.0, 1.0, 1.0, 1};
    test::ChiSquareResult r = test::chi_square_plane(sampler, density, kSamples, 30, 30, seed++, rect);
    EXPECT_TRUE(r.passes(test::sidak_alpha(0.01, int(std::size(views))))) << "cos " << wo.z << ": " << r.summary();
    EXPECT_NEAR(r.pdf_integral, 1.0 - r.invalid_fraction, 5e-3) << "cos " << wo.z << ": " << r.summary();
    if (std::getenv("PENUMBRA_VERBOSE_CHI2")) std::printf("eta 1.0001 cos %.2f: %s\n", wo.z, r.summary().c_str());
  }
}

// ---- The test must be able to fail --------------------------------------------------------------

// Samples like `sampler` but reports the density of `reporter`, times `scale`.
class MislabelledBsdf final : public Bsdf {
 public:
  MislabelledBsdf(const Bsdf& sampler, const Bsdf& reporter, float scale)
      : sampler_(sampler), reporter_(reporter), scale_(scale) {}
  uint32_t flags() const override { return sampler_.flags(); }
  Rgb f(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const override { return sampler_.f(wo, wi, ctx); }
  std::optional<BsdfSample> sample_f(const Vec3& wo, float uc, Vec2 u, const ShadingContext& ctx) const override {
    return sampler_.sample_f(wo, uc, u, ctx);
  }
  float pdf(const Vec3& wo, const Vec3& wi, const ShadingContext& ctx) const override {
    return scale_ * reporter_.pdf(wo, wi, ctx);
  }
  LobeSummary lobe(const Vec3& wo, const ShadingContext& ctx) const override { return sampler_.lobe(wo, ctx); }

 private:
  const Bsdf& sampler_;
  const Bsdf& reporter_;
  float scale_;
};

TEST(BsdfChiSquare, DetectsAWrongPdf) {
  auto rough = make_bsdf("conductor", R"("float roughness" [0.3])");
  auto rougher = make_bsdf("conductor", R"("float roughness" [0.4])");
  auto glass = make_bsdf("dielectric", R"("float roughness" [0.3])");
  Vec3 wo = spherical_direction(0.6f, 1.f);
  test::BsdfChiSquareOptions options;
  options.zoom = false;  // the same chart for both pdfs

  auto scaled = test::bsdf_chi_square(MislabelledBsdf(*rough, *rough, 1.3f), wo, kSamples, 1, options);
  EXPECT_FALSE(scaled.passes(1e-6)) << scaled.summary();
  EXPECT_NEAR(scaled.pdf_integral, 1.3 * (1.0 - scaled.invalid_fraction), 0.01);

  auto wrong_alpha = test::bsdf_chi_square(MislabelledBsdf(*rough, *rougher, 1.f), wo, kSamples, 2, options);
  EXPECT_FALSE(wrong_alpha.passes(1e-6)) << wrong_alpha.summary();

  // A pdf that forgets the transmission lobe's share of the samples (or its Jacobian) is caught too.
  auto scaled_glass = test::bsdf_chi_square(MislabelledBsdf(*glass, *glass, 0.97f), -wo, kSamples, 3, options);
  EXPECT_FALSE(scaled_glass.passes(1e-6)) << scaled_glass.summary();

  if (std::getenv("PENUMBRA_VERBOSE_CHI2"))
    std::printf("pdf x 1.3: %s\nalpha 0.55 sampled, 0.63 reported: %s\nglass pdf x 0.97: %s\n",
                scaled.summary().c_str(), wrong_alpha.summary().c_str(), scaled_glass.summary().c_str());

  // And the honest versions pass with the same chart.
  EXPECT_TRUE(test::bsdf_chi_square(*rough, wo, kSamples, 1, options).passes(1e-3));
  EXPECT_TRUE(test::bsdf_chi_square(*glass, -wo, kSamples, 3, options).passes(1e-3));
}

// ---- Consistency of sample_f with f and pdf -------------------------------------------------------

TEST(ConductorDielectric, SampleAgreesWithEvaluation) {
  std::vector<Case> cases = kConductors;
  for (const Case& c : dielectric_cases()) cases.push_back(c);
  cases.push_back({"dielectric", R"("float eta" [1.0001] "float roughness" [0.3])"});
  for (const Case& c : cases) {
    auto bsdf = make_bsdf(c.plugin, c.params);
    for (Vec3 wo : kDielectricViews) {
      if (c.plugin == "conductor" && wo.z < 0.f) wo = -wo;
      for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
        test::PdfConsistency r = test::pdf_consistency(*bsdf, wo, 5'000, 5, mode);
        // At eta ~ 1 the half vector wo + eta wi of a transmitted pair cancels to ~1e-4 of its terms:
        // float directions then carry only ~3 digits of it into pdf() and f().
        double tolerance = c.params.find("1.0001") != std::string::npos ? 1e-2 : 2e-3;
        EXPECT_GT(r.checked, 0) << describe(c, wo);
        EXPECT_LT(r.max_pdf_error, tolerance) << describe(c, wo);
        EXPECT_LT(r.max_f_error, tolerance) << describe(c, wo);
      }
    }
  }
}

// ---- Energy ---------------------------------------------------------------------------------------

void expect_albedo_at_most_one(const Bsdf& bsdf, const std::string& what, const Vec3& wo, TransportMode mode,
                               Rgb* out = nullptr) {
  test::AlbedoEstimate a = test::albedo_estimate(bsdf, wo, 50'000, 3, mode);
  EXPECT_EQ(a.non_finite, 0) << what;
  for (int c = 0; c < 3; ++c)
    EXPECT_LE(a.mean[c], 1.f + 3.f * a.standard_error[c] + 1e-5f)
        << what << " at cos " << wo.z << ": albedo " << a.mean[c] << " +- " << a.standard_error[c];
  if (out) *out = a.mean;
  if (std::getenv("PENUMBRA_VERBOSE_CHI2"))
    std::printf("albedo %s at cos %.2f: %.4f +- %.4f (max weight %.3g)\n", what.c_str(), wo.z, a.mean.g,
                a.standard_error.g, a.max_weight);
}

TEST(Conductor, WhiteFurnace) {
  // A perfect reflector (R = 1 at every angle) loses energy only to single-scattering masking.
  for (const char* roughness : {"0", "0.01", "0.05", "0.3", "1"}) {
    auto bsdf = make_bsdf("conductor", fmt::format(R"("rgb reflectance" [1 1 1] "float roughness" [{}])", roughness));
    for (Vec3 wo : kConductorViews) {
      Rgb a;
      expect_albedo_at_most_one(*bsdf, fmt::format("conductor roughness {}", roughness), wo, TransportMode::Radiance, &a);
      if (std::string(roughness) == "0") {
        EXPECT_NEAR(a.g, 1.f, 1e-3f);  // a mirror keeps it all
      }
    }
  }
  // Copper absorbs: its albedo is below the perfect reflector's.
  auto copper = make_bsdf("conductor", R"("float roughness" [0.3])");
  Rgb a = test::albedo(*copper, spherical_direction(0.8f, 0.f), 100'000);
  EXPECT_TRUE(a.r > a.g && a.g > a.b && a.r < 1.f) << a.r << " " << a.g << " " << a.b;
}

TEST(Dielectric, WhiteFurnace) {
  // Importance is not compressed by refraction, so a lossless interface scatters at most all of it;
  // the smooth one exactly all of it.
  for (float eta : {1.33f, 1.5f, 2.5f})
    for (const char* roughness : {"0", "0.01", "0.3", "1"}) {
      auto bsdf = make_bsdf("dielectric", fmt::format(R"("float eta" [{}] "float roughness" [{}])", eta, roughness));
      for (Vec3 wo : kDielectricViews) {
        Rgb a;
        expect_albedo_at_most_one(*bsdf, fmt::format("dielectric eta {} roughness {}", eta, roughness), wo,
                                  TransportMode::Importance, &a);
        if (std::string(roughness) == "0") {
          EXPECT_NEAR(a.g, 1.f, 1e-5f);
        }
      }
    }
}

TEST(Dielectric, SmoothSampleWeightsAreExact) {
  for (float eta : {1.33f, 1.5f, 2.5f}) {
    auto bsdf = make_bsdf("dielectric", fmt::format(R"("float eta" [{}])", eta));
    EXPECT_EQ(bsdf->flags(), uint32_t(BsdfReflection | BsdfTransmission | BsdfSpecular));
    EXPECT_TRUE(bsdf->is_specular_only());
    for (Vec3 wo : kDielectricViews) {
      float R = fresnel_dielectric(wo.z, eta);
      int reflected = 0, n = 10'000;
      for (int i = 0; i < n; ++i) {
        float uc = (i + 0.5f) / n;
        for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
          ShadingContext ctx;
          ctx.mode = mode;
          auto s = bsdf->sample_f(wo, uc, Vec2(0.5f), ctx);
          ASSERT_TRUE(s);
          EXPECT_TRUE(s->is_specular());
          float weight = s->f.g * std::abs(s->wi.z) / s->pdf;
          if (s->flags & BsdfReflection) {
            EXPECT_NEAR(weight, 1.f, 1e-5f);
            EXPECT_NEAR(s->pdf, R, 1e-6f);
            EXPECT_NEAR(glm::length(s->wi - Vec3(-wo.x, -wo.y, wo.z)), 0.f, 1e-6f);
            reflected += mode == TransportMode::Radiance;
          } else {
            // Radiance entering the denser side is compressed by 1/eta'^2, importance is not.
            float etap = wo.z > 0.f ? eta : 1.f / eta;
            EXPECT_NEAR(weight, mode == TransportMode::Radiance ? 1.f / (etap * etap) : 1.f, 1e-5f);
            EXPECT_NEAR(s->pdf, 1.f - R, 1e-6f);
            EXPECT_LT(s->wi.z * wo.z, 0.f);
          }
        }
      }
      EXPECT_NEAR(double(reflected) / n, R, 1e-3);  // R + T = 1, split by Fresnel
      EXPECT_EQ(bsdf->f(wo, -wo, {}), Rgb(0.f));
      EXPECT_EQ(bsdf->pdf(wo, Vec3(-wo.x, -wo.y, wo.z), {}), 0.f);
    }
  }
  // Beyond the critical angle inside the glass every sample reflects.
  auto glass = make_bsdf("dielectric", "");
  for (float uc : {0.f, 0.5f, OneMinusEpsilon}) {
    auto s = glass->sample_f(spherical_direction(-0.3f, 1.f), uc, Vec2(0.5f), {});
    ASSERT_TRUE(s);
    EXPECT_TRUE(s->flags & BsdfReflection);
    EXPECT_FLOAT_EQ(s->pdf, 1.f);
  }
}

TEST(Dielectric, IndexMatchedPassesStraightThrough) {
  for (const char* params : {R"("float eta" [1])", R"("float eta" [1] "float roughness" [0.5])"}) {
    auto bsdf = make_bsdf("dielectric", params);
    EXPECT_EQ(bsdf->flags(), uint32_t(BsdfTransmission | BsdfSpecular));
    for (Vec3 wo : kDielectricViews) {
      auto s = bsdf->sample_f(wo, 0.3f, Vec2(0.2f, 0.7f), {});
      ASSERT_TRUE(s);
      EXPECT_EQ(s->wi, -wo);
      EXPECT_EQ(s->flags, uint32_t(BsdfTransmission | BsdfSpecular));
      EXPECT_NEAR(s->f.g * std::abs(s->wi.z) / s->pdf, 1.f, 1e-6f);
      EXPECT_EQ(bsdf->f(wo, -wo, {}), Rgb(0.f));
      EXPECT_EQ(bsdf->pdf(wo, -wo, {}), 0.f);
    }
  }
}

TEST(Conductor, SmoothIsAMirrorWeightedByFresnel) {
  auto bsdf = make_bsdf("conductor", "");  // copper, roughness 0
  EXPECT_EQ(bsdf->flags(), uint32_t(BsdfReflection | BsdfSpecular));
  Rgb eta(0.200438f, 0.924033f, 1.102212f), k(3.912949f, 2.452848f, 2.142188f);
  for (Vec3 wo : {Vec3(0, 0, 1), spherical_direction(0.5f, 1.f), spherical_direction(0.05f, 2.f),
                  spherical_direction(-0.5f, 3.f)}) {
    auto s = bsdf->sample_f(wo, 0.5f, Vec2(0.3f, 0.6f), {});
    ASSERT_TRUE(s);
    EXPECT_TRUE(s->is_specular());
    EXPECT_EQ(s->wi, Vec3(-wo.x, -wo.y, wo.z));
    Rgb weight = s->f * std::abs(s->wi.z) / s->pdf;
    Rgb F = fresnel_complex(std::abs(wo.z), eta, k);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(weight[c], F[c], 1e-6f);
    EXPECT_EQ(bsdf->f(wo, s->wi, {}), Rgb(0.f));
    EXPECT_EQ(bsdf->pdf(wo, s->wi, {}), 0.f);
  }
  EXPECT_FALSE(bsdf->sample_f(Vec3(1, 0, 0), 0.5f, Vec2(0.5f), {}));  // exactly grazing: nothing
}

TEST(ConductorDielectric, Reciprocity) {
  for (const Case& c : kConductors) {
    auto bsdf = make_bsdf(c.plugin, c.params);
    EXPECT_LT(test::reciprocity_error(*bsdf, 20'000), 1e-4) << c.params;
  }
  // Reflection off glass is reciprocal; transmission is adjoint: f(wo, wi) for radiance equals
  // f(wi, wo) for importance (the 1/eta^2 moves with the direction of transport).
  ShadingContext radiance, importance;
  importance.mode = TransportMode::Importance;
  for (const Case& c : dielectric_cases()) {
    auto bsdf = make_bsdf(c.plugin, c.params);
    EXPECT_LT(test::reciprocity_error(*bsdf, 20'000), 1e-4) << c.params;
    double worst = 0.0;
    for (int i = 0; i < 2000; ++i) {
      Vec3 wo = spherical_direction(0.001f + 0.998f * ((i * 0.618034f) - std::floor(i * 0.618034f)), 0.37f * i);
      Vec3 wi = spherical_direction(-0.001f - 0.998f * ((i * 0.754878f) - std::floor(i * 0.754878f)), 1.3f * i);
      if (i % 2) std::swap(wo, wi);
      float a = bsdf->f(wo, wi, radiance).g, b = bsdf->f(wi, wo, importance).g;
      // Near the critical angle 1 - F has infinite slope, so float round-off in the half vector
      // shows up at the 1e-3 level there; the floor ignores values too small to matter.
      worst = std::max(worst, double(std::abs(a - b) / (std::max(a, b) + 1e-3f)));
    }
    EXPECT_LT(worst, 1e-2) << c.params;
  }
}

TEST(ConductorDielectric, LobeSummaries) {
  auto copper = make_bsdf("conductor", R"("float uroughness" [0.04] "float vroughness" [0.09])");
  Vec3 wo = spherical_direction(0.6f, 1.f);
  LobeSummary l = copper->lobe(wo, {});
  EXPECT_NEAR(glm::length(l.peak - Vec3(-wo.x, -wo.y, wo.z)), 0.f, 1e-6f);
  EXPECT_FLOAT_EQ(l.alpha_x, 0.2f);
  EXPECT_FLOAT_EQ(l.alpha_y, 0.3f);
  EXPECT_FALSE(l.cosine);
  EXPECT_GT(l.coefficient, 0.4f);
  EXPECT_LT(l.coefficient, 0.8f);

  auto glass = make_bsdf("dielectric", R"("float roughness" [0.01])");
  l = glass->lobe(wo, {});  // transmission dominates at moderate angles
  EXPECT_LT(l.peak.z, 0.f);
  EXPECT_NEAR(l.coefficient, 1.f - fresnel_dielectric(wo.z, 1.5f), 1e-6f);
  l = glass->lobe(spherical_direction(-0.3f, 1.f), {});  // total internal reflection
  EXPECT_LT(l.peak.z, 0.f);
  EXPECT_FLOAT_EQ(l.coefficient, 1.f);
}

TEST(ConductorDielectric, ParameterErrors) {
  EXPECT_THROW(make_bsdf("conductor", R"("float roughness" [-1])"), Error);
  EXPECT_THROW(make_bsdf("conductor", R"("rgb reflectance" [0.5 0.5 0.5] "rgb k" [1 1 1])"), Error);
  EXPECT_THROW(make_bsdf("conductor", R"("rgb reflectance" [1.5 0.5 0.5])"), Error);
  EXPECT_THROW(make_bsdf("conductor", R"("float displacement" [1])"), Error);
  EXPECT_THROW(make_bsdf("dielectric", R"("float eta" [0])"), Error);
  EXPECT_NO_THROW(make_bsdf("dielectric", R"("spectrum eta" "glass-BK7")"));  // spectra_test.cpp checks the value
  EXPECT_THROW(make_bsdf("dielectric", R"("spectrum eta" "glass-BK8")"), Error);
  EXPECT_NO_THROW(make_bsdf("conductor", R"("spectrum eta" [0.2 0.9 1.1] "spectrum k" [3.9 2.4 2.1])"));
}

// ---- Furnace against an independent albedo -------------------------------------------------------

// A rough perfect reflector (eta 1, k 1e4: F = 1 - O(1e-8)) must reflect exactly the single-
// scattering albedo of its microfacets: bounded from below as well as above, so a BSDF whose f is
// scaled by 0.98 fails. Sample means over 200,000 BSDF samples; tolerance 4 standard errors plus the
// quadrature error (at most 5e-7 here: doubling its grid changes it by no more).
TEST(Conductor, RoughFurnaceMatchesIndependentAlbedo) {
  for (double roughness : {0.01, 0.05, 0.3, 1.0}) {
    double alpha = std::sqrt(roughness);  // remaproughness true
    auto bsdf = make_bsdf("conductor", fmt::format(R"("rgb eta" [1 1 1] "rgb k" [1e4 1e4 1e4] "float roughness" [{}])",
                                                   roughness));
    for (double cos_o : {0.9, 0.5, 0.2}) {
      Vec3 wo(static_cast<float>(std::sqrt(1.0 - cos_o * cos_o)), 0.f, static_cast<float>(cos_o));
      double expected = test::ggx_albedo_by_quadrature(alpha, cos_o);
      test::AlbedoEstimate a = test::albedo_estimate(*bsdf, wo, 200'000, 5);
      double tol = 4.0 * a.standard_error.g + 1e-4;
      std::printf("conductor roughness %.2f cos %.1f: albedo %.5f +- %.5f, quadrature %.5f\n", roughness, cos_o,
                  a.mean.g, a.standard_error.g, expected);
      EXPECT_NEAR(a.mean.g, expected, tol) << "roughness " << roughness << " cos " << cos_o;
      // Negative control: the same estimate of a BSDF 2 % too dark (or too bright) is rejected.
      EXPECT_GT(std::abs(0.98 * a.mean.g - expected), tol) << "a 2 % bias would pass";
      EXPECT_GT(std::abs(1.02 * a.mean.g - expected), tol) << "a 2 % bias would pass";
    }
  }
}


// The single-scattering albedo of a rough dielectric (reflection plus transmission, importance
// transport: no 1/eta'^2), written here from the formulas (Walter et al. 2007: generalized half
// vector, Fresnel for unpolarised light, Trowbridge-Reitz D and height-correlated Smith G2 from
// tests/support) without the SDK's microfacet code, by quadrature over both hemispheres.
double rough_dielectric_albedo(double alpha, double eta, double cos_o) {
  auto lambda = [alpha](double c) { return test::ggx_lambda(alpha, c); };
  auto D = [alpha](double c) { return test::ggx_d(alpha, c); };
  auto fresnel = [eta](double ci) {  // ci > 0: from outside into the medium of index eta
    double s2 = (1.0 - ci * ci) / (eta * eta);
    if (s2 >= 1.0) return 1.0;
    double ct = std::sqrt(1.0 - s2);
    double rp = (eta * ci - ct) / (eta * ci + ct), rs = (ci - eta * ct) / (ci + eta * ct);
    return 0.5 * (rp * rp + rs * rs);
  };
  glm::dvec3 wo(std::sqrt(1.0 - cos_o * cos_o), 0.0, cos_o);
  double g_o = lambda(cos_o);
  double reflect = test::hemisphere_quadrature(
      [&](const glm::dvec3& wi) {
        glm::dvec3 wm = glm::normalize(wi + wo);
        return D(wm.z) * fresnel(glm::dot(wo, wm)) / (1.0 + g_o + lambda(wi.z)) / (4.0 * cos_o);
      },
      1500, 600);
  double transmit = test::hemisphere_quadrature(
      [&](const glm::dvec3& up) {
        glm::dvec3 wi(up.x, up.y, -up.z);  // below the surface
        glm::dvec3 wm = glm::normalize(wi * eta + wo);
        if (wm.z < 0) wm = -wm;
        double di = glm::dot(wi, wm), dox = glm::dot(wo, wm);
        if (di * wi.z < 0 || dox * wo.z < 0) return 0.0;
        double denom = (di + dox / eta) * (di + dox / eta);
        double ft = D(wm.z) * (1.0 - fresnel(dox)) / (1.0 + g_o + lambda(up.z)) * std::abs(di * dox / (denom * wi.z * wo.z));
        return ft * up.z;
      },
      1500, 600);
  return reflect + transmit;
}

// A rough dielectric scatters exactly its microfacets' single-scattering albedo (importance
// transport, so refraction does not compress it): bounded from below as well as above, so a BSDF 2 %
// off fails; 4 standard errors of 200,000 samples plus 1e-4 (doubling the quadrature's grid changes
// it by less than 1e-5).
TEST(Dielectric, RoughFurnaceMatchesIndependentAlbedo) {
  for (double roughness : {0.1, 0.3, 1.0})
    for (double eta : {1.5, 1.33}) {
      double alpha = std::sqrt(roughness);
      auto bsdf = make_bsdf("dielectric", fmt::format(R"("float eta" [{}] "float roughness" [{}])", eta, roughness));
      for (double cos_o : {0.9, 0.5}) {
        Vec3 wo(static_cast<float>(std::sqrt(1.0 - cos_o * cos_o)), 0.f, static_cast<float>(cos_o));
        double expected = rough_dielectric_albedo(alpha, eta, cos_o);
        test::AlbedoEstimate a = test::albedo_estimate(*bsdf, wo, 200'000, 7, TransportMode::Importance);
        double tol = 4.0 * a.standard_error.g + 1e-4;
        std::printf("dielectric eta %.2f roughness %.2f cos %.1f: albedo %.5f +- %.5f, quadrature %.5f\n", eta, roughness,
                    cos_o, a.mean.g, a.standard_error.g, expected);
        EXPECT_NEAR(a.mean.g, expected, tol) << "eta " << eta << " roughness " << roughness << " cos " << cos_o;
        EXPECT_GT(std::abs(0.98 * a.mean.g - expected), tol) << "a 2 % bias would pass";
      }
    }
}

}  // namespace
}  // namespace penumbra
