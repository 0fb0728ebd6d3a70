// Microfacet building blocks shared by BSDF plugins: the anisotropic Trowbridge-Reitz (GGX)
// distribution with height-correlated Smith masking and visible-normal sampling, Fresnel equations
// for dielectrics and conductors, and the reflect/refract helpers.
//
// Everything works in the local shading frame (normal +z) and is two-sided: a direction below the
// surface sees the mirror image (w -> -w) of the configuration above it, so BSDFs can be evaluated
// from inside a dielectric with the same code. Degenerate inputs (grazing directions, directions
// exactly at +-z, alpha -> 0) give finite values, never NaN.
//
// References: Walter et al. 2007 (microfacet transmission), Heitz 2014 (masking functions),
// Heitz 2018 (sampling the GGX distribution of visible normals), pbrt-v4 chapter 9.
#pragma once

#include <penumbra/color.h>
#include <penumbra/math.h>
#include <penumbra/params.h>
#include <penumbra/plugin.h>
#include <penumbra/texture.h>

#include <algorithm>
#include <complex>

namespace penumbra {

/// Anisotropic Trowbridge-Reitz (GGX) microfacet distribution in the local shading frame (+z normal).
/// alpha_x and alpha_y are the roughnesses along the shading frame's s (x) and t (y) axes.
class TrowbridgeReitz {
 public:
  /// Alphas are clamped to at least 1e-4 so that D and Lambda stay finite; such values are a
  /// delta lobe anyway (see effectively_smooth()).
  TrowbridgeReitz(float alpha_x, float alpha_y)
      : alpha_x_(std::max(alpha_x, kMinAlpha)), alpha_y_(std::max(alpha_y, kMinAlpha)) {}

  /// pbrt-v4's perceptual remap of a user roughness in [0, 1] ("bool remaproughness").
  static float roughness_to_alpha(float roughness) { return std::sqrt(std::max(roughness, 0.f)); }

  float alpha_x() const { return alpha_x_; }
  float alpha_y() const { return alpha_y_; }

  /// The smoothness threshold every microfacet BSDF shares (conductor, dielectric, disney): a lobe
  /// whose alpha is below kSmoothAlpha along both axes is so narrow that sampling and evaluating it
  /// as a density is hopeless in float (D reaches 1 / (pi alpha^2) ~ 3e5 and next-event estimation
  /// through it produces fireflies), so it is a delta instead: a perfect mirror (f = F / |cos|,
  /// pdf = the lobe's selection probability, flags Specular) or a perfect refraction, and f() and
  /// pdf() of that lobe are 0 for given directions. GTR1 (Disney's clearcoat) is not a
  /// TrowbridgeReitz lobe and does not use it.
  static constexpr float kSmoothAlpha = 1e-3f;

  /// So narrow that sampling and evaluating it as a lobe is hopeless in float: treat as a delta.
  bool effectively_smooth() const { return std::max(alpha_x_, alpha_y_) < kSmoothAlpha; }

  /// Normal distribution D(wm), normalised so that the projected microfacet area integrates to 1:
  /// int D(wm) cos(theta_m) dwm = 1. Symmetric in wm -> -wm, so callers may pass either orientation.
  float D(const Vec3& wm) const {
    // Written without tan/cos so that wm at the horizon or at +-z needs no special case:
    // cos^4 (1 + tan^2 (cos^2 phi/ax^2 + sin^2 phi/ay^2)) = mx^2/ax^2 + my^2/ay^2 + mz^2.
    float e = sqr(wm.x / alpha_x_) + sqr(wm.y / alpha_y_) + sqr(wm.z);
    return 1.f / (Pi * alpha_x_ * alpha_y_ * sqr(e));
  }

  /// Smith's auxiliary function. A grazing direction (cos = 0) is fully masked: Lambda = infinity,
  /// the limit, so that G1 = G = 0 there without a division by zero.
  float lambda(const Vec3& w) const {
    float s2 = projected_alpha2(w);  // alpha(phi)^2 sin^2(theta)
    float c2 = sqr(w.z);
    if (s2 == 0.f) return 0.f;  // at +-z (or a zero vector): nothing is masked
    if (c2 == 0.f) return Infinity;
    return 0.5f * (std::sqrt(1.f + s2 / c2) - 1.f);
  }

  /// Masking of one direction: the fraction of microfacet area facing w that w sees.
  float G1(const Vec3& w) const { return 1.f / (1.f + lambda(w)); }

  /// Height-correlated Smith masking-shadowing (Heitz 2014): more accurate than G1(wo) G1(wi).
  float G(const Vec3& wo, const Vec3& wi) const { return 1.f / (1.f + lambda(wo) + lambda(wi)); }

  /// Distribution of normals visible from w: G1(w) max(0, w.wm) D(wm) / |cos theta_w|, over wm in
  /// the +z hemisphere; it integrates to 1 over wm. For w below the surface the visible normals are
  /// those seen from -w (the mirrored configuration), matching sample_wm().
  float D(const Vec3& w, const Vec3& wm) const {
    if (wm.z <= 0.f) return 0.f;
    float w_dot_m = (w.z < 0.f ? -1.f : 1.f) * glm::dot(w, wm);
    if (w_dot_m <= 0.f) return 0.f;
    // G1/|cos| = 2 / (|cos| + sqrt(cos^2 + alpha^2 sin^2)): finite even at grazing w.
    float c = std::abs(w.z);
    float denom = c + std::sqrt(sqr(c) + projected_alpha2(w));
    if (denom == 0.f) return 0.f;
    return 2.f * w_dot_m * D(wm) / denom;
  }

  /// Density of sample_wm(w, .) per unit solid angle of wm (the same as D(w, wm)).
  float pdf(const Vec3& w, const Vec3& wm) const { return D(w, wm); }

  /// Samples a microfacet normal (+z hemisphere) from the visible normals D(w, .) (Heitz 2018):
  /// in the stretched configuration where the distribution is a hemisphere of unit radius, the
  /// visible normals are the projection of a disk perpendicular to w onto that hemisphere.
  Vec3 sample_wm(const Vec3& w, Vec2 u) const {
    Vec3 wh = glm::normalize(Vec3(alpha_x_ * w.x, alpha_y_ * w.y, w.z));
    if (wh.z < 0.f) wh = -wh;
    // Orthonormal basis with t1 horizontal, so the projected disk's lower half is easy to squash.
    float len2 = sqr(wh.x) + sqr(wh.y);
    Vec3 t1 = len2 > 1e-14f ? Vec3(-wh.y, wh.x, 0.f) / std::sqrt(len2) : Vec3(1.f, 0.f, 0.f);
    Vec3 t2 = glm::cross(wh, t1);
    // Uniform point on the unit disk (polar map: continuity does not matter here).
    float r = std::sqrt(u.x), phi = 2.f * Pi * u.y;
    float p1 = r * std::cos(phi), p2 = r * std::sin(phi);
    // The half of the disk behind the hemisphere's rim is seen foreshortened by (1 + cos)/2.
    float h = std::sqrt(std::max(0.f, 1.f - sqr(p1)));
    float s = 0.5f * (1.f + wh.z);
    p2 = (1.f - s) * h + s * p2;
    float p3 = std::sqrt(std::max(0.f, 1.f - sqr(p1) - sqr(p2)));
    Vec3 nh = p1 * t1 + p2 * t2 + p3 * wh;
    // Unstretch; the normal's z is kept off zero so that wm stays in the open upper hemisphere.
    return glm::normalize(Vec3(alpha_x_ * nh.x, alpha_y_ * nh.y, std::max(1e-6f, nh.z)));
  }

  /// Path regularisation (pbrt-v4): widens near-specular lobes so that paths through them can be
  /// found by next-event estimation, at the price of bias.
  void regularize() {
    if (alpha_x_ < 0.3f) alpha_x_ = std::clamp(2.f * alpha_x_, 0.1f, 0.3f);
    if (alpha_y_ < 0.3f) alpha_y_ = std::clamp(2.f * alpha_y_, 0.1f, 0.3f);
  }

 private:
  static constexpr float kMinAlpha = 1e-4f;
  // alpha(phi)^2 sin^2(theta) = ax^2 wx^2 + ay^2 wy^2, the projected roughness times the tangent part.
  float projected_alpha2(const Vec3& w) const { return sqr(alpha_x_ * w.x) + sqr(alpha_y_ * w.y); }

  float alpha_x_, alpha_y_;
};

/// Unpolarised Fresnel reflectance of a dielectric interface with relative IOR eta = eta_t/eta_i,
/// for light arriving at cos_theta_i from the eta_i side. cos_theta_i < 0 means the other side:
/// eta is inverted. Total internal reflection returns 1.
inline float fresnel_dielectric(float cos_theta_i, float eta) {
  cos_theta_i = std::clamp(cos_theta_i, -1.f, 1.f);
  if (cos_theta_i < 0.f) {
    eta = 1.f / eta;
    cos_theta_i = -cos_theta_i;
  }
  float sin2_t = (1.f - sqr(cos_theta_i)) / sqr(eta);
  if (sin2_t >= 1.f) return 1.f;
  float cos_t = safe_sqrt(1.f - sin2_t);
  float r_parallel = (eta * cos_theta_i - cos_t) / (eta * cos_theta_i + cos_t);
  float r_perpendicular = (cos_theta_i - eta * cos_t) / (cos_theta_i + eta * cos_t);
  return 0.5f * (sqr(r_parallel) + sqr(r_perpendicular));
}

/// Fresnel reflectance of a conductor with complex IOR eta + i k (relative to the outside medium),
/// for one wavelength. cos_theta_i is clamped to [0, 1]: light reaches a conductor from outside only.
/// Real arithmetic in double (the closed form of |r_s|^2 and |r_p|^2 through a^2 + b^2 = |eta^2 -
/// sin^2|): the same values as the complex-number formula, without its library calls.
inline float fresnel_conductor(float cos_theta_i, float eta, float k) {
  double c = std::clamp(static_cast<double>(cos_theta_i), 0.0, 1.0);
  double c2 = c * c, s2 = 1.0 - c2;
  double e2 = static_cast<double>(eta) * eta, k2 = static_cast<double>(k) * k;
  double t0 = e2 - k2 - s2;
  double a2b2 = std::sqrt(t0 * t0 + 4.0 * e2 * k2);
  double a = std::sqrt(std::max(0.0, 0.5 * (a2b2 + t0)));
  double t1 = a2b2 + c2, t2 = 2.0 * a * c;
  // Only a lossless interface with eta = 1 viewed at exactly grazing gets here: the limit is 1.
  if (t1 + t2 == 0.0) return 1.f;
  double rs = (t1 - t2) / (t1 + t2);
  double t3 = c2 * a2b2 + s2 * s2, t4 = t2 * s2;
  double rp = rs * (t3 - t4) / (t3 + t4);
  return static_cast<float>(0.5 * (rs + rp));
}

/// The same with the complex IOR as one number.
inline float fresnel_complex(float cos_theta_i, std::complex<float> eta) {
  return fresnel_conductor(cos_theta_i, eta.real(), eta.imag());
}

/// Conductor Fresnel reflectance per RGB channel (eta and k per channel).
inline Rgb fresnel_complex(float cos_theta_i, const Rgb& eta, const Rgb& k) {
  return Rgb(fresnel_conductor(cos_theta_i, eta.r, k.r), fresnel_conductor(cos_theta_i, eta.g, k.g),
             fresnel_conductor(cos_theta_i, eta.b, k.b));
}

/// Mirror reflection of wo about n (both pointing away from the surface).
inline Vec3 reflect(const Vec3& wo, const Vec3& n) { return -wo + 2.f * glm::dot(wo, n) * n; }

/// Refracts wi about n with relative IOR eta (eta = eta_t/eta_i for wi on n's side). When wi is on
/// the other side of n, the interface is crossed the other way: n is flipped and eta inverted.
/// Returns false on total internal reflection; `etap` receives the effective relative IOR used.
inline bool refract(const Vec3& wi, Vec3 n, float eta, float* etap, Vec3* wt) {
  float cos_i = glm::dot(n, wi);
  if (cos_i < 0.f) {
    eta = 1.f / eta;
    cos_i = -cos_i;
    n = -n;
  }
  float sin2_t = std::max(0.f, 1.f - sqr(cos_i)) / sqr(eta);
  if (sin2_t >= 1.f) return false;
  float cos_t = safe_sqrt(1.f - sin2_t);
  *wt = -wi / eta + (cos_i / eta - cos_t) * n;
  if (etap) *etap = eta;
  return true;
}

/// GGX alphas from pbrt-v4's roughness parameters: "float roughness", "float uroughness" and
/// "float vroughness" (default: roughness), "bool remaproughness" (alpha = sqrt(roughness) when true).
/// Negative roughness is an error at its parameter. Shared by every microfacet material.
inline Vec2 microfacet_alphas(const ParamSet& p) {
  for (const char* name : {"roughness", "uroughness", "vroughness"})
    if (p.has(name) && !(p.get_float(name) >= 0.f)) throw Error(p.loc_of(name), std::string(name) + " must be >= 0");
  float roughness = p.get_float("roughness");
  Vec2 r(p.has("uroughness") ? p.get_float("uroughness") : roughness,
         p.has("vroughness") ? p.get_float("vroughness") : roughness);
  if (p.get_bool("remaproughness", true))
    r = Vec2(TrowbridgeReitz::roughness_to_alpha(r.x), TrowbridgeReitz::roughness_to_alpha(r.y));
  return r;
}

/// The same roughness parameters where any may be a float texture (`"texture roughness" "name"`):
/// constants are checked as microfacet_alphas() does; textured values are clamped at 0 per lookup.
struct MicrofacetRoughness {
  TexturedFloat u, v;
  bool remap = true;

  bool is_constant() const { return u.is_constant() && v.is_constant(); }
  /// The distribution at a hit.
  TrowbridgeReitz at(const TextureEvalContext& ctx) const {
    Vec2 r(std::max(0.f, u.evaluate(ctx)), std::max(0.f, v.evaluate(ctx)));
    if (remap) r = Vec2(TrowbridgeReitz::roughness_to_alpha(r.x), TrowbridgeReitz::roughness_to_alpha(r.y));
    return TrowbridgeReitz(r.x, r.y);
  }
};

inline MicrofacetRoughness microfacet_roughness(const CreateContext& ctx) {
  const ParamSet& p = ctx.params;
  microfacet_alphas(p);  // checks the constants
  MicrofacetRoughness m;
  TexturedFloat roughness = ctx.float_input("roughness");
  m.u = p.has("uroughness") ? ctx.float_input("uroughness") : roughness;
  m.v = p.has("vroughness") ? ctx.float_input("vroughness") : roughness;
  m.remap = p.get_bool("remaproughness", true);
  return m;
}

}  // namespace penumbra
