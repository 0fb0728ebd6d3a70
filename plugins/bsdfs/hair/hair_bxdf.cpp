#include "hair_bxdf.h"

#include <algorithm>

namespace penumbra::hair {

namespace {

float safe_asin(float x) { return std::asin(std::clamp(x, -1.f, 1.f)); }

// Modified Bessel function of the first kind, order 0, by its power series sum (x/2)^2i / (i!)^2,
// summed until the terms stop mattering (pbrt-v4 stops after 10 terms, which is 2 % low at x = 12,
// the switch to the asymptotic form, and makes the longitudinal lobes integrate to less than 1).
float bessel_i0(float x) {
  double q = 0.25 * double(x) * x, term = 1.0, sum = 1.0;
  for (int i = 1; i < 60 && term > 1e-9 * sum; ++i) {
    term *= q / (double(i) * i);
    sum += term;
  }
  return static_cast<float>(sum);
}

// log I0(x); above 12 by the asymptotic series e^x / sqrt(2 pi x) (1 + 1/(8x) + 9/(128x^2) +
// 225/(3072x^3)), accurate to 1e-5 there. (pbrt-v4's form halves the 1/(8x) term, which leaves the
// narrow TT lobe 0.2-0.5 % short of normalised: measured on the pdf's integral over the sphere.)
float log_bessel_i0(float x) {
  if (x > 12.f) {
    double d = x, inv = 1.0 / d;
    return static_cast<float>(d - 0.5 * std::log(2.0 * 3.14159265358979323846 * d) +
                              std::log1p(inv / 8.0 + 9.0 * inv * inv / 128.0 + 225.0 * inv * inv * inv / 3072.0));
  }
  return std::log(bessel_i0(x));
}

// Longitudinal lobe M_p (d'Eon et al.'s normalised form; the log form for small variances, where
// I0 and sinh overflow).
float longitudinal(float cos_i, float cos_o, float sin_i, float sin_o, float v) {
  float a = cos_i * cos_o / v, b = sin_i * sin_o / v;
  if (v <= 0.1f) return std::exp(log_bessel_i0(a) - b - 1.f / v + 0.6931f + std::log(1.f / (2.f * v)));
  return std::exp(-b) * bessel_i0(a) / (std::sinh(1.f / v) * 2.f * v);
}

float logistic(float x, float s) {
  x = std::abs(x);
  float e = std::exp(-x / s);
  return e / (s * sqr(1.f + e));
}

float logistic_cdf(float x, float s) { return 1.f / (1.f + std::exp(-x / s)); }

float trimmed_logistic(float x, float s, float a, float b) {
  return logistic(x, s) / (logistic_cdf(b, s) - logistic_cdf(a, s));
}

float sample_trimmed_logistic(float u, float s, float a, float b) {
  float k = logistic_cdf(b, s) - logistic_cdf(a, s);
  float x = -s * std::log(1.f / (u * k + logistic_cdf(a, s)) - 1.f);
  return std::clamp(x, a, b);
}

// Exit azimuth of term p from a smooth cylinder.
float exit_azimuth(int p, float gamma_o, float gamma_t) { return 2.f * p * gamma_t - 2.f * gamma_o + p * Pi; }

// Azimuthal lobe N_p at relative azimuth phi.
float azimuthal(float phi, int p, float s, float gamma_o, float gamma_t) {
  float dphi = phi - exit_azimuth(p, gamma_o, gamma_t);
  while (dphi > Pi) dphi -= 2.f * Pi;
  while (dphi < -Pi) dphi += 2.f * Pi;
  return trimmed_logistic(dphi, s, -Pi, Pi);
}

struct Angles {
  float sin_theta, cos_theta, phi;
};

Angles angles_of(const Vec3& w) {
  float sin_theta = std::clamp(w.x, -1.f, 1.f);
  return {sin_theta, safe_sqrt(1.f - sqr(sin_theta)), std::atan2(w.z, w.y)};
}

}  // namespace

Rgb sigma_a_from_reflectance(const Rgb& c, float beta_n) {
  float d = 5.969f - 0.215f * beta_n + 2.532f * sqr(beta_n) - 10.73f * std::pow(beta_n, 3.f) +
            5.574f * std::pow(beta_n, 4.f) + 0.245f * std::pow(beta_n, 5.f);
  Rgb s;
  for (int k = 0; k < 3; ++k) s[k] = sqr(std::log(std::max(c[k], 1e-6f)) / d);
  return s;
}

Rgb sigma_a_from_concentration(float eumelanin, float pheomelanin) {
  const Rgb eu(0.419f, 0.697f, 1.37f), pheo(0.187f, 0.4f, 1.05f);
  return eumelanin * eu + pheomelanin * pheo;
}

HairLobes HairLobes::from(float beta_m, float beta_n, float alpha) {
  HairLobes l;
  // Longitudinal variances from beta_m (Chiang et al.'s fit), wider for the internal terms.
  l.v[0] = sqr(0.726f * beta_m + 0.812f * sqr(beta_m) + 3.7f * std::pow(beta_m, 20.f));
  l.v[1] = 0.25f * l.v[0];
  l.v[2] = 4.f * l.v[0];
  for (int k = 3; k <= kPMax; ++k) l.v[k] = l.v[2];
  // Logistic scale from beta_n (sqrt(pi / 8) times the fit).
  constexpr float kSqrtPiOver8 = 0.626657069f;
  l.s = kSqrtPiOver8 * (0.265f * beta_n + 1.194f * sqr(beta_n) + 5.372f * std::pow(beta_n, 22.f));
  // sin and cos of 2^k alpha for the tilts of R (2 alpha), TT (alpha) and TRT (4 alpha).
  l.sin2k_alpha[0] = std::sin(alpha * Pi / 180.f);
  l.cos2k_alpha[0] = safe_sqrt(1.f - sqr(l.sin2k_alpha[0]));
  for (int i = 1; i < 3; ++i) {
    l.sin2k_alpha[i] = 2.f * l.cos2k_alpha[i - 1] * l.sin2k_alpha[i - 1];
    l.cos2k_alpha[i] = sqr(l.cos2k_alpha[i - 1]) - sqr(l.sin2k_alpha[i - 1]);
  }
  return l;
}

HairBxdf::HairBxdf(const HairLobes& lobes, float h, float eta, const Rgb& sigma_a)
    : lobes_(lobes), h_(h), eta_(eta), sigma_a_(sigma_a), gamma_o_(safe_asin(h)) {}

void HairBxdf::tilt(int p, float sin_o, float cos_o, float* sin_p, float* cos_p) const {
  if (p == 0) {  // R: tilted by -2 alpha
    *sin_p = sin_o * lobes_.cos2k_alpha[1] - cos_o * lobes_.sin2k_alpha[1];
    *cos_p = cos_o * lobes_.cos2k_alpha[1] + sin_o * lobes_.sin2k_alpha[1];
  } else if (p == 1) {  // TT: by alpha
    *sin_p = sin_o * lobes_.cos2k_alpha[0] + cos_o * lobes_.sin2k_alpha[0];
    *cos_p = cos_o * lobes_.cos2k_alpha[0] - sin_o * lobes_.sin2k_alpha[0];
  } else if (p == 2) {  // TRT: by 4 alpha
    *sin_p = sin_o * lobes_.cos2k_alpha[2] + cos_o * lobes_.sin2k_alpha[2];
    *cos_p = cos_o * lobes_.cos2k_alpha[2] - sin_o * lobes_.sin2k_alpha[2];
  } else {
    *sin_p = sin_o;
    *cos_p = cos_o;
  }
  *cos_p = std::abs(*cos_p);
}

std::array<Rgb, kPMax + 1> HairBxdf::attenuation(float cos_theta_o) const {
  std::array<Rgb, kPMax + 1> ap;
  float sin_theta_o = safe_sqrt(1.f - sqr(cos_theta_o));
  // The refracted ray inside: its longitudinal angle, and the modified index for the azimuthal plane.
  float sin_theta_t = sin_theta_o / eta_, cos_theta_t = safe_sqrt(1.f - sqr(sin_theta_t));
  float etap = std::sqrt(std::max(sqr(eta_) - sqr(sin_theta_o), 1e-12f)) / std::max(cos_theta_o, 1e-6f);
  float sin_gamma_t = h_ / etap, cos_gamma_t = safe_sqrt(1.f - sqr(sin_gamma_t));
  // Transmittance of one internal segment.
  Rgb T;
  for (int k = 0; k < 3; ++k) T[k] = std::exp(-sigma_a_[k] * (2.f * cos_gamma_t / std::max(cos_theta_t, 1e-6f)));
  float cos_gamma_o = safe_sqrt(1.f - sqr(h_));
  float f = fresnel_dielectric(cos_theta_o * cos_gamma_o, eta_);
  ap[0] = Rgb(f);
  ap[1] = sqr(1.f - f) * T;
  for (int p = 2; p < kPMax; ++p) ap[p] = ap[p - 1] * T * f;
  // All longer paths: a geometric series.
  Rgb denom = Rgb(1.f) - T * f;
  for (int k = 0; k < 3; ++k) ap[kPMax][k] = denom[k] > 0.f ? ap[kPMax - 1][k] * f * T[k] / denom[k] : 0.f;
  return ap;
}

std::array<float, kPMax + 1> HairBxdf::attenuation_pdf(float cos_theta_o) const {
  std::array<Rgb, kPMax + 1> ap = attenuation(cos_theta_o);
  std::array<float, kPMax + 1> pdf;
  float sum = 0.f;
  auto average = [](const Rgb& c) { return (c.r + c.g + c.b) / 3.f; };
  for (int p = 0; p <= kPMax; ++p) sum += average(ap[p]);
  for (int p = 0; p <= kPMax; ++p) pdf[p] = sum > 0.f ? average(ap[p]) / sum : (p == 0 ? 1.f : 0.f);
  return pdf;
}

float HairBxdf::gamma_t(float sin_theta_o, float cos_theta_o) const {
  float etap = std::sqrt(std::max(sqr(eta_) - sqr(sin_theta_o), 1e-12f)) / std::max(cos_theta_o, 1e-6f);
  return safe_asin(h_ / etap);
}

// sum_p M_p N_p weight[p] (the last term's azimuth uniform): f with A_p as weights, pdf with the
// probabilities of choosing each term.
template <class T>
T HairBxdf::lobe_sum(const Vec3& wo, const Vec3& wi, const std::array<T, kPMax + 1>& weight) const {
  Angles o = angles_of(wo), i = angles_of(wi);
  float g_t = gamma_t(o.sin_theta, o.cos_theta);
  float phi = i.phi - o.phi;
  T sum(0.f);
  for (int p = 0; p < kPMax; ++p) {
    float sin_p, cos_p;
    tilt(p, o.sin_theta, o.cos_theta, &sin_p, &cos_p);
    sum += longitudinal(i.cos_theta, cos_p, i.sin_theta, sin_p, lobes_.v[p]) * weight[p] * azimuthal(phi, p, lobes_.s, gamma_o_, g_t);
  }
  sum += longitudinal(i.cos_theta, o.cos_theta, i.sin_theta, o.sin_theta, lobes_.v[kPMax]) * weight[kPMax] / (2.f * Pi);
  return sum;
}

Rgb HairBxdf::f(const Vec3& wo, const Vec3& wi) const {
  Rgb sum = lobe_sum(wo, wi, attenuation(angles_of(wo).cos_theta));
  if (std::abs(wi.z) > 0.f) sum /= std::abs(wi.z);
  return sum;
}

float HairBxdf::pdf(const Vec3& wo, const Vec3& wi) const {
  return lobe_sum(wo, wi, attenuation_pdf(angles_of(wo).cos_theta));
}

std::optional<HairSample> HairBxdf::sample_f(const Vec3& wo, float uc, Vec2 u) const {
  Angles o = angles_of(wo);
  // Which term: by the attenuations' channel average (pbrt-v4's); uc is then reused for the azimuth.
  std::array<float, kPMax + 1> ap = attenuation_pdf(o.cos_theta);
  int p = 0;
  for (; p < kPMax; ++p) {
    if (uc < ap[p]) break;
    uc -= ap[p];
  }
  if (!(ap[p] > 0.f)) return std::nullopt;
  uc = std::min(uc / ap[p], 0x1.fffffep-1f);

  float sin_p, cos_p;
  tilt(p, o.sin_theta, o.cos_theta, &sin_p, &cos_p);
  // theta_i from M_p (d'Eon et al.'s sampling of the longitudinal lobe).
  float v = lobes_.v[p];
  float cos_theta = 1.f + v * std::log(std::max(u[0], 1e-5f) + (1.f - u[0]) * std::exp(-2.f / v));
  float sin_theta = safe_sqrt(1.f - sqr(cos_theta));
  float cos_phi = std::cos(2.f * Pi * u[1]);
  float sin_theta_i = -cos_theta * sin_p + sin_theta * cos_phi * cos_p;
  float cos_theta_i = safe_sqrt(1.f - sqr(sin_theta_i));
  // phi_i from N_p.
  float dphi = p < kPMax ? exit_azimuth(p, gamma_o_, gamma_t(o.sin_theta, o.cos_theta)) +
                               sample_trimmed_logistic(uc, lobes_.s, -Pi, Pi)
                         : 2.f * Pi * uc;
  float phi_i = o.phi + dphi;
  Vec3 wi(sin_theta_i, cos_theta_i * std::cos(phi_i), cos_theta_i * std::sin(phi_i));
  float pdf_value = pdf(wo, wi);
  if (!(pdf_value > 0.f)) return std::nullopt;
  return HairSample{wi, f(wo, wi), pdf_value};
}

}  // namespace penumbra::hair
