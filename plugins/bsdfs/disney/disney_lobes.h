// The lobes of the Disney principled BSDF (Burley 2012, 2015), each on its own. DisneyBsdf
// (disney_bsdf.h) mixes them and picks one per sample.
//
// Every lobe works in the "upper" configuration: wo above the surface (wo.z > 0). DisneyBsdf mirrors
// a configuration with wo below onto it, so the lobes never deal with signs; the one thing the side
// changes, the relative IOR of a transmissive material, is passed in as `eta`.
#pragma once

#include <penumbra/bsdf.h>
#include <penumbra/color.h>
#include <penumbra/math.h>
#include <penumbra/microfacet.h>

#include <optional>

namespace penumbra::disney {

/// (1 - cos)^5: how Schlick's approximation moves from normal incidence to grazing.
inline float schlick_weight(float cos_theta) {
  float m = std::clamp(1.f - cos_theta, 0.f, 1.f);
  return sqr(m) * sqr(m) * m;
}
inline float schlick_r0_from_eta(float eta) { return sqr((eta - 1.f) / (eta + 1.f)); }
inline Rgb fresnel_schlick(const Rgb& r0, float cos_theta) { return r0 + (Rgb(1.f) - r0) * schlick_weight(cos_theta); }
inline float fresnel_schlick(float r0, float cos_theta) { return r0 + (1.f - r0) * schlick_weight(cos_theta); }

/// Burley's diffuse family, all sampled with the cosine-weighted hemisphere: the Fresnel-shaped
/// diffuse (1 - Fo/2)(1 - Fi/2)/pi, the Hanrahan-Krueger-like "fake subsurface" lobe that thin
/// surfaces blend in by flatness, retro-reflection and sheen. Each term has its own colour weight.
struct DiffuseLobes {
  Rgb diffuse{0.f};
  Rgb fake_subsurface{0.f};
  Rgb retro{0.f};
  Rgb sheen{0.f};
  float roughness = 0.f;

  bool active() const { return !is_black(diffuse + fake_subsurface + retro + sheen); }
  /// Rough luminance of the lobes' albedo, for choosing among lobes.
  float selection_weight() const;
  /// Both directions above the surface.
  Rgb f(const Vec3& wo, const Vec3& wi) const;
};

/// The anisotropic GGX specular reflection with Disney's Fresnel: dielectric Fresnel for the
/// non-metallic part (so it pairs with the transmission lobe's 1 - F), Schlick from Cspec0 for the
/// metallic part. Sampled with visible normals.
struct SpecularReflection {
  TrowbridgeReitz distribution{1.f, 1.f};
  Rgb cspec0{0.f};
  float metallic = 0.f;

  /// Whether the lobe can reflect anything: a dielectric with eta = 1 has no interface.
  bool active(float eta) const { return metallic > 0.f || eta != 1.f; }
  Rgb fresnel(float cos_theta_d, float eta) const;
  Rgb f(const Vec3& wo, const Vec3& wi, float eta) const;
  float pdf(const Vec3& wo, const Vec3& wi) const;
  std::optional<Vec3> sample(const Vec3& wo, Vec2 u) const;
};

/// The clearcoat: a second, achromatic specular layer with the long-tailed GTR1 distribution,
/// Schlick Fresnel from a fixed R0 and Smith masking with a fixed alpha of 0.25. GTR1 has no
/// visible-normal sampler, so it samples D(wm) cos(theta_m) (Burley 2012, appendix B).
struct Clearcoat {
  float weight = 0.f;  // 0.25 clearcoat: Burley's ad-hoc scale
  float alpha = 0.1f;  // lerp(0.1, 0.001, clearcoatgloss)
  float r0 = 0.04f;    // IOR 1.5

  bool active() const { return weight > 0.f; }
  float D(float cos_theta_m) const;
  float f(const Vec3& wo, const Vec3& wi) const;
  float pdf(const Vec3& wo, const Vec3& wi) const;
  std::optional<Vec3> sample(const Vec3& wo, Vec2 u) const;
};

/// Transmission through a rough dielectric interface (Walter et al. 2007) tinted by `tint`. `eta`
/// is the relative IOR across the interface as seen from wo (wo above, wi below).
struct RoughTransmission {
  TrowbridgeReitz distribution{1.f, 1.f};
  Rgb tint{0.f};

  Rgb f(const Vec3& wo, const Vec3& wi, float eta, TransportMode mode) const;
  float pdf(const Vec3& wo, const Vec3& wi, float eta) const;
  std::optional<Vec3> sample(const Vec3& wo, Vec2 u, float eta) const;
};

}  // namespace penumbra::disney
