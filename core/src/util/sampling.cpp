#include <penumbra/sampling.h>

#include "util/cpu_clones.h"
#include "util/triangle_warp.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

namespace {

// sin and cos of a in [-pi/4, pi/4] by their Taylor series to a^9 and a^10 (Horner): the first terms
// left out are below 2e-9 there, under float rounding, and no range reduction is needed. A quarter of
// the cost of libm's sincosf, which every diffuse bounce and emitted ray calls through the
// concentric map (docs/benchmarks.md).
void sincos_quarter_pi(float a, float* s, float* c) {
  float a2 = a * a;
  *s = a * (1.f + a2 * (-1.f / 6.f + a2 * (1.f / 120.f + a2 * (-1.f / 5040.f + a2 * (1.f / 362880.f)))));
  *c = 1.f + a2 * (-0.5f + a2 * (1.f / 24.f + a2 * (-1.f / 720.f + a2 * (1.f / 40320.f + a2 * (-1.f / 3628800.f)))));
}

// The map of sample_uniform_disk_concentric(), shared by the clones below.
inline Vec2 disk_concentric(Vec2 u) {
  // Shirley-Chiu: concentric squares map to concentric circles, so strata stay compact (unlike the
  // polar map, which squeezes the square's left edge into the centre). The angle is pi/4 times a
  // ratio in [-1, 1], or pi/2 minus that, so sin and cos of a quarter-circle angle suffice.
  // The two halves of the square (|x| > |y| or not) are chosen by selects rather than by a branch
  // that goes either way at random: one blendv each in the x86-64-v3 clone (docs/benchmarks.md,
  // "FMA clones of the hottest scalar math", has what each part gained).
  Vec2 o = 2.f * u - Vec2(1.f);
  bool x_major = std::abs(o.x) > std::abs(o.y);
  float r = x_major ? o.x : o.y, other = x_major ? o.y : o.x;
  if (r == 0.f) return Vec2(0.f);  // the centre: both are 0
  float s, c;
  sincos_quarter_pi((Pi / 4.f) * (other / r), &s, &c);
  // x major: r (cos a, sin a); y major: r (sin a, cos a), since cos(pi/2 - a) = sin a.
  return r * Vec2(x_major ? c : s, x_major ? s : c);
}

}  // namespace

PENUMBRA_X86_64_V3_CLONES Vec2 sample_uniform_disk_concentric(Vec2 u) { return disk_concentric(u); }

PENUMBRA_X86_64_V3_CLONES Vec3 sample_cosine_hemisphere(Vec2 u) {
  // Malley's method: uniform on the disk, projected up onto the hemisphere, is cosine-distributed.
  // The disk point's radius is |r| of the concentric map, known before its angle: z = sqrt(1 - r^2)
  // is computed alongside the angle's polynomial instead of after it (the direction feeds the next
  // ray, so this chain's latency is paid per bounce).
  Vec2 o = 2.f * u - Vec2(1.f);
  float r = std::max(std::abs(o.x), std::abs(o.y));
  Vec2 d = disk_concentric(u);
  return Vec3(d.x, d.y, safe_sqrt(1.f - r * r));
}

Vec3 sample_uniform_sphere(Vec2 u) {
  // Archimedes: z is uniform on [-1, 1] for a uniform point on the sphere.
  float z = 1.f - 2.f * u.x;
  float r = safe_sqrt(1.f - z * z);
  float phi = 2.f * Pi * u.y;
  return Vec3(r * std::cos(phi), r * std::sin(phi), z);
}

Vec3 sample_uniform_cone(Vec2 u, float cos_max) {
  // cos(theta) is uniform on [cos_max, 1]. Work with t = 1 - cos(theta) so that narrow cones
  // (cos_max close to 1) keep their precision: 1 - cos^2 would cancel catastrophically.
  float t = u.x * (1.f - cos_max);
  float cos_theta = 1.f - t;
  float sin_theta = safe_sqrt(t * (2.f - t));
  float phi = 2.f * Pi * u.y;
  return Vec3(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta);
}

Vec2 sample_uniform_triangle(Vec2 u) { return uniform_triangle_barycentrics(u); }

Distribution1D::Distribution1D(std::span<const float> f) : func_(f.size()), cdf_(f.size() + 1) {
  size_t n = f.size();
  for (size_t i = 0; i < n; ++i) func_[i] = std::abs(f[i]);
  // Accumulate in double: environment maps have millions of bins and a float running sum would
  // drop the small ones entirely.
  std::vector<double> cdf(n + 1, 0.0);
  for (size_t i = 0; i < n; ++i) cdf[i + 1] = cdf[i] + double(func_[i]) / double(n);
  double total = n > 0 ? cdf[n] : 0.0;
  integral_ = float(total);
  if (n == 0) return;
  for (size_t i = 0; i <= n; ++i)
    cdf_[i] = total > 0.0 ? float(cdf[i] / total) : float(double(i) / double(n));
  cdf_[n] = 1.f;  // exact, whatever the rounding, so u < 1 always finds a bin
}

// Largest i in [0, n-1] with cdf[i] <= u. Zero-width bins are never returned for u < 1, because the
// next bin then also satisfies the condition.
static inline size_t find_interval(const std::vector<float>& cdf, float u) {
  size_t n = cdf.size() - 1;
  if (n <= 8) {
    // A few bins (a scene's lights): count the interior edges at or below u. The CDF does not
    // decrease, so they are a prefix and the count is the index upper_bound finds; counting has no
    // branch on u, where a scan or a search mispredicts about every other light sample.
    size_t i = 0;
    for (size_t k = 1; k < n; ++k) i += !(u < cdf[k]);
    return i;
  }
  auto it = std::upper_bound(cdf.begin(), cdf.end(), u);
  size_t i = it == cdf.begin() ? 0 : size_t(it - cdf.begin()) - 1;
  return std::min(i, n - 1);
}

float Distribution1D::sample_continuous(float u, float* pdf, size_t* offset) const {
  size_t n = func_.size();
  if (n == 0) {  // nothing to sample: report an impossible sample rather than read out of bounds
    if (pdf) *pdf = 0.f;
    if (offset) *offset = 0;
    return 0.f;
  }
  size_t o = find_interval(cdf_, u);
  if (offset) *offset = o;
  float width = cdf_[o + 1] - cdf_[o];
  float du = u - cdf_[o];
  if (width > 0.f) du /= width;
  // An all-zero function samples uniformly, so its density is 1 (pbrt reports 0 here; we prefer the
  // density that matches what was actually sampled).
  if (pdf) *pdf = integral_ > 0.f ? func_[o] / integral_ : 1.f;
  // Rounding can carry (o + du) / n onto the next bin's start, whose density may be zero: keep the
  // sample inside the bin whose pdf and offset we report.
  float x = (float(o) + std::min(du, 1.f)) / float(n);
  float upper = std::min(float(o + 1) / float(n), 1.f);
  return x < upper ? x : std::nextafter(upper, 0.f);
}

size_t Distribution1D::sample_discrete(float u, float* pmf, float* u_remapped) const {
  if (func_.empty()) {
    if (pmf) *pmf = 0.f;
    if (u_remapped) *u_remapped = u;
    return 0;
  }
  size_t o = find_interval(cdf_, u);
  if (pmf) *pmf = discrete_pmf(o);
  if (u_remapped) {
    float width = cdf_[o + 1] - cdf_[o];
    float r = width > 0.f ? (u - cdf_[o]) / width : 0.f;
    *u_remapped = std::clamp(r, 0.f, OneMinusEpsilon);
  }
  return o;
}

float Distribution1D::discrete_pmf(size_t i) const {
  size_t n = func_.size();
  if (i >= n) return 0.f;
  if (integral_ <= 0.f) return 1.f / float(n);
  return func_[i] / (integral_ * float(n));
}

Distribution2D::Distribution2D(std::span<const float> f, size_t nu, size_t nv) {
  conditional_.reserve(nv);
  std::vector<float> row_integrals(nv);
  for (size_t v = 0; v < nv; ++v) {
    conditional_.emplace_back(f.subspan(v * nu, nu));
    row_integrals[v] = conditional_.back().integral();
  }
  marginal_ = Distribution1D(row_integrals);
}

Vec2 Distribution2D::sample_continuous(Vec2 u, float* pdf) const {
  float pdf_v = 0.f, pdf_u = 0.f;
  size_t row = 0;
  float v = marginal_.sample_continuous(u.y, &pdf_v, &row);
  float x = conditional_[row].sample_continuous(u.x, &pdf_u);
  if (pdf) *pdf = pdf_v * pdf_u;
  return Vec2(x, v);
}

float Distribution2D::pdf(Vec2 p) const {
  if (conditional_.empty()) return 0.f;
  size_t nu = conditional_[0].size(), nv = conditional_.size();
  size_t iu = std::min(static_cast<size_t>(std::max(p.x, 0.f) * nu), nu - 1);
  size_t iv = std::min(static_cast<size_t>(std::max(p.y, 0.f) * nv), nv - 1);
  // Density = pmf of the cell times the cell count: the marginal's and the conditional's discrete
  // pmfs already include the all-zero-means-uniform rule.
  return marginal_.discrete_pmf(iv) * nv * conditional_[iv].discrete_pmf(iu) * nu;
}

}  // namespace penumbra
