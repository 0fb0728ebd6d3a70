#include "layered_bxdf.h"

#include <penumbra/sampling.h>

#include <bit>
#include <cmath>

namespace penumbra::bxdf {

namespace {

// Transmittance through the slab's medium (unit extinction) over height dz along w.
float tr(float dz, const Vec3& w) {
  if (dz == 0.f) return 1.f;
  return std::exp(-std::abs(dz / w.z));
}

bool usable(const std::optional<BsdfSample>& s) {
  return s && !is_black(s->f) && s->pdf > 0.f && s->wi.z != 0.f;
}

TransportMode adjoint(TransportMode m) {
  return m == TransportMode::Radiance ? TransportMode::Importance : TransportMode::Radiance;
}

uint64_t bits(const Vec3& v) {
  return hash_ints(std::bit_cast<uint32_t>(v.x), std::bit_cast<uint32_t>(v.y), std::bit_cast<uint32_t>(v.z));
}

Vec2 next2(Pcg32& rng) {
  float a = rng.next_float();
  return Vec2(a, rng.next_float());
}

// Distinct streams for f, pdf and sample_f, so their estimates for one pair are independent.
constexpr uint64_t kSaltF = 0x6c61796572656466ull, kSaltPdf = 0x6c61796572656470ull, kSaltSample = 0x6c61796572656473ull;

}  // namespace

template <class Bottom>
uint32_t LayeredBxdf<Bottom>::nonspecular_lobe() const {
  if ((bottom_.flags() & BsdfDiffuse) || has_medium()) return BsdfDiffuse;
  return BsdfGlossy;
}

template <class Bottom>
uint32_t LayeredBxdf<Bottom>::flags() const {
  uint32_t flags = BsdfReflection;
  if (top_.specular()) flags |= BsdfSpecular;
  // Everything that passes through the slab has met a non-delta lobe unless both layers are deltas
  // and nothing scatters in between.
  if (!(top_.specular() && bottom_specular() && !has_medium())) flags |= nonspecular_lobe();
  return flags;
}

// ---- f: pbrt-v4's estimator, for reflection (both layers are entered and left through the top) ----

template <class Bottom>
Rgb LayeredBxdf<Bottom>::f_walk(const Vec3& wo, const Vec3& wi, TransportMode mode, Pcg32& rng) const {
  // Enter along a refraction of wo and prepare the connection through the refraction of wi.
  std::optional<BsdfSample> wos = top_.sample_f(wo, rng.next_float(), next2(rng), mode, Lobes::Transmission);
  if (!usable(wos)) return Rgb(0.f);
  std::optional<BsdfSample> wis = top_.sample_f(wi, rng.next_float(), next2(rng), adjoint(mode), Lobes::Transmission);
  if (!usable(wis)) return Rgb(0.f);
  const bool top_delta = top_.specular(), bottom_delta = bottom_specular();
  const float h = p_.thickness;
  Rgb beta = wos->f * abs_cos_theta(wos->wi) / wos->pdf;
  Rgb wis_weight = wis->f / wis->pdf;
  // MIS between the connection through wis and hitting wi by sampling needs both densities over the
  // same variable, the direction w leaving upwards inside the slab: the connection draws it with the
  // density of refracting wi into -w. (pbrt-v4 uses the density of refracting -w into wi here, which is
  // not the same for a rough top: its weights then miss 1 and f() comes out ~6 % high at alpha 0.22.)
  auto nee_pdf = [&](const Vec3& w_up) { return top_.pdf(wi, -w_up, adjoint(mode), Lobes::Transmission); };
  Vec3 w = wos->wi;
  float z = h;
  Rgb f(0.f);
  for (int depth = 0; depth < p_.max_depth; ++depth) {
    if (depth > 3 && max_component(beta) < 0.25f) {
      float q = std::max(0.f, 1.f - max_component(beta));
      if (rng.next_float() < q) break;
      beta /= 1.f - q;
    }
    if (!has_medium()) {
      z = (z == h) ? 0.f : h;
      beta *= tr(h, w);
    } else {
      float dz = -std::log(1.f - rng.next_float()) * std::abs(w.z);
      float zp = w.z > 0.f ? z + dz : z - dz;
      if (zp == z) continue;
      if (0.f < zp && zp < h) {
        // Scattering in the medium: connect to wi's refraction, then sample the phase function.
        float wt = top_delta ? 1.f : power_heuristic(1, wis->pdf, 1, phase_.pdf(w, -wis->wi));
        f += beta * p_.albedo * phase_.p(w, -wis->wi) * wt * tr(zp - h, wis->wi) * wis_weight;
        Vec3 wn = phase_.sample(w, next2(rng));
        float ps_pdf = phase_.pdf(w, wn);
        if (!(ps_pdf > 0.f) || wn.z == 0.f) continue;
        beta *= p_.albedo;  // p / pdf = 1
        w = wn;
        z = zp;
        if (w.z > 0.f && !top_delta) {
          Rgb f_exit = top_.f(-w, wi, mode);
          if (!is_black(f_exit)) {
            float wt2 = power_heuristic(1, ps_pdf, 1, nee_pdf(w));
            f += beta * tr(zp - h, w) * f_exit * wt2;
          }
        }
        continue;
      }
      z = std::clamp(zp, 0.f, h);
    }
    if (z == h) {
      // Back at the top from inside: reflect (leaving is what the connections count).
      std::optional<BsdfSample> bs = top_.sample_f(-w, rng.next_float(), next2(rng), mode, Lobes::Reflection);
      if (!usable(bs)) break;
      beta *= bs->f * abs_cos_theta(bs->wi) / bs->pdf;
      w = bs->wi;
    } else {
      // At the base: connect to wi's refraction, then sample the base.
      if (!bottom_delta) {
        float wt = top_delta ? 1.f : power_heuristic(1, wis->pdf, 1, bottom_.pdf(-w, -wis->wi, mode));
        f += beta * bottom_.f(-w, -wis->wi, mode) * abs_cos_theta(wis->wi) * wt * tr(h, wis->wi) * wis_weight;
      }
      std::optional<BsdfSample> bs = bottom_.sample_f(-w, rng.next_float(), next2(rng), mode);
      if (!usable(bs)) break;
      beta *= bs->f * abs_cos_theta(bs->wi) / bs->pdf;
      w = bs->wi;
      if (!top_delta) {
        Rgb f_exit = top_.f(-w, wi, mode);
        if (!is_black(f_exit)) {
          float wt = bottom_delta ? 1.f : power_heuristic(1, bs->pdf, 1, nee_pdf(w));
          f += beta * tr(h, bs->wi) * f_exit * wt;
        }
      }
    }
  }
  return f;
}

namespace {

// Two-sided as pbrt-v4: a wo below the surface mirrors both directions to the upper side. False
// when the pair is not a reflection there (the base is opaque: the layers only reflect).
bool to_upper_side(Vec3& wo, Vec3& wi) {
  if (wo.z < 0.f) {
    wo = -wo;
    wi = -wi;
  }
  return wo.z > 0.f && wi.z > 0.f;
}

}  // namespace

template <class Bottom>
Rgb LayeredBxdf<Bottom>::f(const Vec3& wo_in, const Vec3& wi_in, TransportMode mode, Pcg32& rng) const {
  Vec3 wo = wo_in, wi = wi_in;
  if (!to_upper_side(wo, wi)) return Rgb(0.f);
  Rgb f = top_.f(wo, wi, mode) * static_cast<float>(p_.n_samples);
  for (int s = 0; s < p_.n_samples; ++s) f += f_walk(wo, wi, mode, rng);
  return f / static_cast<float>(p_.n_samples);
}

template <class Bottom>
Rgb LayeredBxdf<Bottom>::f(const Vec3& wo, const Vec3& wi, TransportMode mode) const {
  Pcg32 rng(bits(wo), hash_ints(bits(wi), kSaltF));
  return f(wo, wi, mode, rng);
}

// ---- sample_f: the walk ----------------------------------------------------------------------------

template <class Bottom>
std::optional<BsdfSample> LayeredBxdf<Bottom>::sample_walk(const Vec3& wo_in, float uc, Vec2 u, TransportMode mode,
                                                           Pcg32& rng) const {
  Vec3 wo = wo_in;
  bool flip = wo.z < 0.f;
  if (flip) wo = -wo;
  if (wo.z == 0.f) return std::nullopt;
  std::optional<BsdfSample> bs = top_.sample_f(wo, uc, u, mode);
  if (!usable(bs)) return std::nullopt;
  if (bs->flags & BsdfReflection) {
    if (flip) bs->wi = -bs->wi;
    return bs;
  }
  const float h = p_.thickness;
  Rgb f = bs->f * abs_cos_theta(bs->wi);
  float pdf = bs->pdf;
  bool specular = bs->is_specular();
  Vec3 w = bs->wi;
  float z = h;
  for (int depth = 0; depth < p_.max_depth; ++depth) {
    if (w.z == 0.f) return std::nullopt;
    if (has_medium()) {
      float dz = -std::log(1.f - rng.next_float()) * std::abs(w.z);
      float zp = w.z > 0.f ? z + dz : z - dz;
      if (zp == z) return std::nullopt;
      if (0.f < zp && zp < h) {
        Vec3 wn = phase_.sample(w, next2(rng));
        float ps = phase_.pdf(w, wn);
        if (!(ps > 0.f) || wn.z == 0.f) return std::nullopt;
        f *= p_.albedo * ps;
        pdf *= ps;
        specular = false;
        w = wn;
        z = zp;
        continue;
      }
      z = std::clamp(zp, 0.f, h);
    } else {
      z = (z == h) ? 0.f : h;
      f *= tr(h, w);
    }
    std::optional<BsdfSample> s = z == 0.f ? bottom_.sample_f(-w, rng.next_float(), next2(rng), mode)
                                           : top_.sample_f(-w, rng.next_float(), next2(rng), mode);
    if (!usable(s)) return std::nullopt;
    f *= s->f;
    pdf *= s->pdf;
    specular = specular && s->is_specular();
    w = s->wi;
    if (s->flags & BsdfTransmission) {  // left through the top
      uint32_t flags = BsdfReflection | (specular ? BsdfSpecular : nonspecular_lobe());
      return BsdfSample{f, flip ? -w : w, pdf, flags, 1.f};
    }
    f *= abs_cos_theta(s->wi);
  }
  return std::nullopt;
}

template <class Bottom>
std::optional<BsdfSample> LayeredBxdf<Bottom>::sample_f(const Vec3& wo, float uc, Vec2 u, TransportMode mode) const {
  Pcg32 rng(bits(wo), hash_ints(std::bit_cast<uint32_t>(uc), std::bit_cast<uint64_t>(u), kSaltSample));
  std::optional<BsdfSample> s = sample_walk(wo, uc, u, mode, rng);
  if (!s || s->is_specular()) return s;
  // The throughput stays the walk's; the density reported is the (deterministic) estimate pdf(wo, wi).
  Rgb weight = s->f * abs_cos_theta(s->wi) / s->pdf;
  float p = pdf(wo, s->wi, mode);
  if (!(p > 0.f) || !std::isfinite(p)) return std::nullopt;
  s->f = weight * p / abs_cos_theta(s->wi);
  s->pdf = p;
  return s;
}

// ---- pdf: the density of sample_f's directions -------------------------------------------------------

template <class Bottom>
float LayeredBxdf<Bottom>::pdf_walk(const Vec3& wo, const Vec3& wi, TransportMode mode, Pcg32& rng) const {
  // The walk sample_f() takes once it has refracted into the slab, with the lobe choices it would make
  // at the top replaced by forced ones whose probabilities are carried in `weight`.
  float choice = 1.f;
  std::optional<BsdfSample> wos =
      top_.sample_f(wo, rng.next_float(), next2(rng), mode, Lobes::Transmission, &choice);
  if (!usable(wos)) return 0.f;
  float weight = choice;
  const float h = p_.thickness, eta = top_.eta();
  const bool smooth_top = top_.specular(), bottom_delta = bottom_specular();
  // Smooth top: wi can only come from the inside direction w_up that refracts into it, leaving with
  // probability t_up; the density of w_up maps to wi's by jacobian (etendue: eta^2 cos dw = cos' dw').
  Vec3 w_up(0.f), w_down(0.f);
  float t_up = 0.f, jacobian = 0.f;
  if (smooth_top) {
    Vec3 wt;
    if (eta == 1.f) wt = -wi;
    else if (!refract(wi, Vec3(0.f, 0.f, 1.f), eta, nullptr, &wt)) return 0.f;
    if (wt.z == 0.f) return 0.f;
    w_up = -wt;
    w_down = Vec3(w_up.x, w_up.y, -w_up.z);  // what a mirror base turns into w_up
    t_up = eta == 1.f ? 1.f : 1.f - fresnel_dielectric(wt.z, eta);
    jacobian = wi.z / (sqr(eta) * std::abs(w_up.z));
  }
  // The probability of flying from height zf along w_up to the top without scattering.
  auto reach_top = [&](float zf) { return has_medium() ? tr(h - zf, w_up) : 1.f; };
  // Rough top: the density of leaving through wi at the top visit that follows an event, i.e. the
  // integral over the upward direction v arriving at the top of full(v) reach(v) t(v): full is the
  // density with which the walk's own sampling leads to v (through a mirror base if there is one),
  // reach the probability of getting to the top unscattered, t(v) the top's density of refracting v
  // into wi. Estimated by MIS from the direction the walk drew (`drawn`, with the forced-choice
  // factor; drawing density `sampling`) and from a refraction of wi drawn by the top itself.
  auto t_exit = [&](const Vec3& v) { return top_.pdf(-v, wi, mode); };
  auto q_exit = [&](const Vec3& v) { return top_.pdf(wi, -v, adjoint(mode), Lobes::Transmission); };
  auto rough_exit = [&](const Vec3& drawn, float factor, auto&& sampling, auto&& full, auto&& reach) {
    float x = 0.f;
    if (drawn.z > 0.f) x += power_heuristic(1, sampling(drawn), 1, q_exit(drawn)) * factor * reach(drawn) * t_exit(drawn);
    std::optional<BsdfSample> s = top_.sample_f(wi, rng.next_float(), next2(rng), adjoint(mode), Lobes::Transmission);
    if (usable(s)) {
      Vec3 v = -s->wi;
      float pe = sampling(v);
      if (pe > 0.f) x += power_heuristic(1, s->pdf, 1, pe) * full(v) * reach(v) * t_exit(v) / s->pdf;
    }
    return x;
  };
  auto mirror = [](const Vec3& v) { return Vec3(v.x, v.y, -v.z); };
  auto tr_h = [&](const Vec3& v) { return has_medium() ? tr(h, v) : 1.f; };
  auto via_mirror = [&](const Vec3& v) { return tr_h(v) * tr_h(v); };  // down to the mirror and up again
  // A top event (the entrance, or an internal reflection) that sent the walk down towards a mirror
  // base from direction `from`, restricted to `lobe`: the next top visit is two events later.
  auto rough_exit_after_top = [&](const Vec3& from, Lobes lobe, const std::optional<BsdfSample>& drawn, float factor) {
    return rough_exit(
        usable(drawn) ? mirror(drawn->wi) : Vec3(0.f), factor,
        [&](const Vec3& v) { return top_.pdf(from, mirror(v), mode, lobe); },
        [&](const Vec3& v) { return top_.pdf(from, mirror(v), mode, Lobes::All); }, via_mirror);
  };
  float p = 0.f;
  if (!smooth_top && bottom_delta && 1 < p_.max_depth) p += rough_exit_after_top(wo, Lobes::Transmission, wos, choice);
  Vec3 w = wos->wi;
  float z = h;
  for (int depth = 0; depth < p_.max_depth; ++depth) {
    if (w.z == 0.f) break;
    if (has_medium()) {
      float dz = -std::log(1.f - rng.next_float()) * std::abs(w.z);
      float zp = w.z > 0.f ? z + dz : z - dz;
      if (zp == z) break;
      if (0.f < zp && zp < h) {
        Vec3 wn = phase_.sample(w, next2(rng));
        if (smooth_top) {
          // Straight up and out; with a mirror base also down to it first, and both after any number
          // of round trips (internal reflection at the top, the mirror), each taking two more events.
          float up = phase_.pdf(w, w_up) * reach_top(zp);
          float down = bottom_delta ? phase_.pdf(w, w_down) * tr(zp, w_down) * reach_top(0.f) : 0.f;
          float round_trip = bottom_delta ? (1.f - t_up) * tr(h, w_down) * reach_top(0.f) : 0.f;
          for (int d = depth + 1; d < p_.max_depth && (up > 0.f || down > 0.f); d += 2) {
            p += weight * (up + (d + 1 < p_.max_depth ? down : 0.f)) * t_up * jacobian;
            up *= round_trip;
            down *= round_trip;
          }
        } else {
          auto phase_up = [&](const Vec3& v) { return phase_.pdf(w, v); };
          if (depth + 1 < p_.max_depth)
            p += weight * rough_exit(wn, 1.f, phase_up, phase_up, [&](const Vec3& v) { return tr(h - zp, v); });
          if (bottom_delta && depth + 2 < p_.max_depth) {
            auto phase_down = [&](const Vec3& v) { return phase_.pdf(w, mirror(v)); };
            p += weight * rough_exit(wn.z < 0.f ? mirror(wn) : Vec3(0.f), 1.f, phase_down, phase_down,
                                     [&](const Vec3& v) { return tr(zp, v) * tr(h, v); });
          }
        }
        w = wn;
        z = zp;
        continue;
      }
      z = std::clamp(zp, 0.f, h);
    } else {
      z = (z == h) ? 0.f : h;
    }
    if (z == h) {
      Vec3 from = -w;
      std::optional<BsdfSample> bs = top_.sample_f(from, rng.next_float(), next2(rng), mode, Lobes::Reflection, &choice);
      if (!smooth_top && bottom_delta && depth + 2 < p_.max_depth)
        p += weight * rough_exit_after_top(from, Lobes::Reflection, bs, choice);
      if (!usable(bs)) break;
      weight *= choice;
      w = bs->wi;
    } else {
      Vec3 from = -w;
      if (smooth_top && !bottom_delta && depth + 1 < p_.max_depth)
        p += weight * bottom_.pdf(from, w_up, mode) * reach_top(0.f) * t_up * jacobian;
      std::optional<BsdfSample> bs = bottom_.sample_f(from, rng.next_float(), next2(rng), mode);
      if (!smooth_top && !bottom_delta && depth + 1 < p_.max_depth) {
        auto base = [&](const Vec3& v) { return bottom_.pdf(from, v, mode); };
        p += weight * rough_exit(usable(bs) ? bs->wi : Vec3(0.f), 1.f, base, base, tr_h);
      }
      if (!usable(bs)) break;
      w = bs->wi;
    }
  }
  return p;
}

template <class Bottom>
float LayeredBxdf<Bottom>::pdf(const Vec3& wo_in, const Vec3& wi_in, TransportMode mode, Pcg32& rng) const {
  Vec3 wo = wo_in, wi = wi_in;
  if (!to_upper_side(wo, wi)) return 0.f;
  float p = 0.f;
  for (int s = 0; s < p_.n_samples; ++s) p += pdf_walk(wo, wi, mode, rng);
  return top_.pdf(wo, wi, mode) + p / static_cast<float>(p_.n_samples);
}

template <class Bottom>
float LayeredBxdf<Bottom>::pdf(const Vec3& wo, const Vec3& wi, TransportMode mode) const {
  Pcg32 rng(bits(wi), hash_ints(bits(wo), kSaltPdf));
  return pdf(wo, wi, mode, rng);
}

template <class Bottom>
LobeSummary LayeredBxdf<Bottom>::lobe(const Vec3& wo) const {
  float R = fresnel_dielectric(std::abs(wo.z), top_.eta());
  LobeSummary base = bottom_.lobe(wo);
  LobeSummary l = base;
  if (!base.cosine) {
    l.alpha_x = std::max(base.alpha_x, top_.distribution().alpha_x());
    l.alpha_y = std::max(base.alpha_y, top_.distribution().alpha_y());
  }
  l.coefficient = R + (1.f - R) * base.coefficient;
  if (has_medium()) {
    l.cosine = true;
    l.peak = Vec3(0.f, 0.f, wo.z < 0.f ? -1.f : 1.f);
    l.alpha_x = l.alpha_y = 1.f;
  }
  return l;
}

template class LayeredBxdf<DiffuseBxdf>;
template class LayeredBxdf<ConductorBxdf>;

}  // namespace penumbra::bxdf
