// Reusable statistical checks for any Bsdf plugin, loaded through the registry as a scene would
// load it: sampling against pdf (chi-square), directional albedo (white furnace), reciprocity and
// the agreement of sample_f() with f()/pdf().
//
//   auto bsdf = make_bsdf("conductor", R"("float roughness" [0.3])");
//   ChiSquareResult r = bsdf_chi_square(*bsdf, spherical_direction(0.5f, 1.f), 200'000);
//   EXPECT_TRUE(r.passes(sidak_alpha(0.01, number_of_tests))) << r.summary();
#pragma once

#include <functional>

#include "support/chi_square.h"

#include <penumbra/bsdf.h>

#include <cstdint>
#include <memory>
#include <string>

namespace penumbra::test {

/// Creates BSDF plugin `name` with parameters in scene syntax, e.g.
/// `"float roughness" [0.3] "rgb reflectance" [0.5 0.5 0.5]`. Throws Error like a scene would.
/// Not thread-safe (one registry for the process); the BSDFs it returns are.
std::unique_ptr<Bsdf> make_bsdf(const std::string& name, const std::string& params_text);

/// Unit direction with cos(theta) = cos_theta (may be negative: below the surface) and azimuth phi.
Vec3 spherical_direction(float cos_theta, float phi);

struct BsdfChiSquareOptions {
  int theta_bins = 20;
  int phi_bins = 40;
  /// For narrow lobes (alpha < 0.15 per Bsdf::lobe()), histogram a cap around the lobe's peak in a
  /// frame rotated onto it, so that the lobe spans many cells; the rest of the sphere is one cell.
  bool zoom = true;
  int max_refinements = 6;  // depth of the adaptive integration of the pdf over a cell
  TransportMode mode = TransportMode::Radiance;
  TextureEvalContext tex;  // where on the surface (BSDFs that depend on uv: hair's offset h)
};

/// Chi-square test of sample_f(wo, ...) against pdf(wo, .) over the full sphere (transmission goes
/// below), in theta_bins x phi_bins cells of equal solid angle. Specular samples count as "no
/// sample", so pdf_integral should come out as the probability of sampling a non-specular lobe,
/// 1 - invalid_fraction. The pdf is integrated per cell to a relative accuracy of ~1e-3 (ample
/// for ~1e5 samples, and much faster than chi_square_sphere's 1e-7); the statistic is
/// chi_square_from_counts(). Thread-safe for a const Bsdf.
ChiSquareResult bsdf_chi_square(const Bsdf& bsdf, const Vec3& wo, int n = 1'000'000, uint64_t seed = 7,
                                const BsdfChiSquareOptions& options = {});

struct AlbedoEstimate {
  Rgb mean{0.f};
  Rgb standard_error{0.f};
  double max_weight = 0.0;   // largest f |cos| / pdf seen (fireflies)
  int non_finite = 0;        // samples with NaN or infinite weights (a bug)
};

/// Integral of `f_cos(wi)` over the upper hemisphere by midpoint quadrature in (cos theta, phi) on an
/// nt x np grid (dwi = dcos dphi): the independent side of a furnace test.
double hemisphere_quadrature(const std::function<double(const glm::dvec3& wi)>& f_cos, int nt, int np);

/// Isotropic Trowbridge-Reitz (GGX) normal distribution at a microfacet normal with cosine `cos_m`,
/// and Smith's Lambda for a direction with cosine `cos_w`, written from the formulas (not the SDK's
/// microfacet code) for the independent side of furnace tests.
double ggx_d(double alpha, double cos_m);
double ggx_lambda(double alpha, double cos_w);

/// The single-scattering albedo of an isotropic GGX (Trowbridge-Reitz) surface with Fresnel 1 seen
/// from a direction with cosine `cos_o`: int D(wm) G2(wo, wi) / (4 cos_o) dwi by midpoint quadrature
/// in (cos theta_i, phi_i), written from the formulas without the SDK's microfacet code, so a furnace
/// can bound a rough BSDF from below as well as above. Doubling the grid changes it by at most 5e-7
/// for alpha >= 0.09 (by 5e-4 at alpha 0.04 and cos 0.2: use it for rougher lobes only).
double ggx_albedo_by_quadrature(double alpha, double cos_o);

/// Monte Carlo estimate of the directional albedo int f(wo, wi) |cos theta_i| dwi with the BSDF's
/// own sampling, specular lobes included (weight f |cos| / pdf). Absent samples count as zero.
AlbedoEstimate albedo_estimate(const Bsdf& bsdf, const Vec3& wo, int n, uint64_t seed = 11,
                               TransportMode mode = TransportMode::Radiance, const TextureEvalContext& tex = {});
inline Rgb albedo(const Bsdf& bsdf, const Vec3& wo, int n, uint64_t seed = 11,
                  TransportMode mode = TransportMode::Radiance) {
  return albedo_estimate(bsdf, wo, n, seed, mode).mean;
}

/// Largest relative difference |f(wo, wi) - f(wi, wo)| / max(|f(wo, wi)|, |f(wi, wo)|) over random
/// pairs of directions on the same side of the surface (reflection), per channel.
double reciprocity_error(const Bsdf& bsdf, int n_pairs, uint64_t seed = 13);

struct PdfConsistency {
  double max_pdf_error = 0.0;  // max |sample.pdf - pdf(wo, wi)| / max(sample.pdf, pdf(wo, wi))
  double max_f_error = 0.0;    // the same for f, per channel
  int checked = 0;             // non-specular samples compared
};

/// Draws n samples from sample_f(wo, ...) and compares the returned pdf and f with what pdf() and
/// f() say for the same direction. Specular samples are skipped.
PdfConsistency pdf_consistency(const Bsdf& bsdf, const Vec3& wo, int n, uint64_t seed = 17,
                               TransportMode mode = TransportMode::Radiance, const TextureEvalContext& tex = {});

}  // namespace penumbra::test
