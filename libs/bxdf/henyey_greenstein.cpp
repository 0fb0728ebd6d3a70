#include "henyey_greenstein.h"

namespace penumbra::bxdf {

float HenyeyGreenstein::p(const Vec3& w, const Vec3& w_out) const {
  float c = std::clamp(glm::dot(w, w_out), -1.f, 1.f);
  float denom = 1.f + sqr(g_) - 2.f * g_ * c;
  return Inv4Pi * (1.f - sqr(g_)) / (denom * safe_sqrt(denom));
}

Vec3 HenyeyGreenstein::sample(const Vec3& w, Vec2 u) const {
  // Inverting the cumulative distribution of cos: uniform for |g| ~ 0.
  float c;
  if (std::abs(g_) < 1e-3f) {
    c = 1.f - 2.f * u.x;
  } else {
    float s = (1.f - sqr(g_)) / (1.f - g_ + 2.f * g_ * u.x);
    c = (1.f + sqr(g_) - sqr(s)) / (2.f * g_);
  }
  c = std::clamp(c, -1.f, 1.f);
  float sin_t = safe_sqrt(1.f - sqr(c)), phi = 2.f * Pi * u.y;
  Frame frame(w);
  return glm::normalize(frame.to_world(Vec3(sin_t * std::cos(phi), sin_t * std::sin(phi), c)));
}

}  // namespace penumbra::bxdf
