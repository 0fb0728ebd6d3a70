// The Henyey-Greenstein phase function of the scattering medium between layers, written in terms of
// the propagation direction: p(w, w') = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos)^(3/2)) with cos = w.w'
// (g > 0 scatters forward, g = 0 is isotropic). Sampled exactly: the weight p / pdf is 1.
#pragma once

#include <penumbra/math.h>

namespace penumbra::bxdf {

class HenyeyGreenstein {
 public:
  explicit HenyeyGreenstein(float g) : g_(std::clamp(g, -0.99f, 0.99f)) {}
  float g() const { return g_; }
  /// Density per unit solid angle of scattering from propagation direction w into w'.
  float p(const Vec3& w, const Vec3& w_out) const;
  float pdf(const Vec3& w, const Vec3& w_out) const { return p(w, w_out); }
  /// A direction scattered from propagation direction w.
  Vec3 sample(const Vec3& w, Vec2 u) const;

 private:
  float g_;
};

}  // namespace penumbra::bxdf
