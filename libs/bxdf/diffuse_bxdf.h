// Lambertian reflection, f = R / pi, sampled by the cosine-weighted hemisphere on the side of wo.
#pragma once

#include "lobes.h"

#include <penumbra/bsdf.h>

#include <optional>

namespace penumbra::bxdf {

class DiffuseBxdf {
 public:
  explicit DiffuseBxdf(Rgb r) : r_(r) {}
  Rgb reflectance() const { return r_; }
  uint32_t flags() const { return is_black(r_) ? 0u : (BsdfReflection | BsdfDiffuse); }
  Rgb f(const Vec3& wo, const Vec3& wi, TransportMode = TransportMode::Radiance) const {
    return same_hemisphere(wo, wi) ? r_ * InvPi : Rgb(0.f);
  }
  std::optional<BsdfSample> sample_f(const Vec3& wo, float uc, Vec2 u, TransportMode mode = TransportMode::Radiance,
                                     Lobes allowed = Lobes::All) const;
  float pdf(const Vec3& wo, const Vec3& wi, TransportMode mode = TransportMode::Radiance,
            Lobes allowed = Lobes::All) const;
  LobeSummary lobe(const Vec3& wo) const;

 private:
  Rgb r_;
};

}  // namespace penumbra::bxdf
