#include "support/bsdf_harness.h"

#include "parser/scene_description.h"
#include "registry/registry.h"
#include "support/pcg32.h"

#include <cmath>
#include <functional>
#include <numeric>
#include <vector>

namespace penumbra::test {

std::unique_ptr<Bsdf> make_bsdf(const std::string& name, const std::string& params_text) {
  // Plugin libraries stay open for the process, so one registry serves every test.
  static Registry registry({std::string(PENUMBRA_BINARY_DIR) + "/lib/penumbra/plugins"});
  SceneDescription desc = parse_scene_string("WorldBegin\nMaterial \"" + name + "\" " + params_text + "\n");
  SceneEntity& m = desc.materials.at(0);
  return registry.create<Bsdf>(PluginKind::Bsdf, m.type, m.params, CreateContext{m.params, m.loc, m.base_dir}, m.loc);
}

Vec3 spherical_direction(float cos_theta, float phi) {
  float sin_theta = safe_sqrt(1.f - sqr(cos_theta));
  return Vec3(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta);
}

namespace {

// 4-point Gauss-Legendre per axis, as in chi_square.cpp: its nodes avoid cell edges, where BSDF
// densities jump (the horizon, the edge of the visible microfacets).
constexpr double kNodes[4] = {-0.86113631159405257522, -0.33998104358485626480, 0.33998104358485626480,
                              0.86113631159405257522};
constexpr double kWeights[4] = {0.34785484513745385737, 0.65214515486254614263, 0.65214515486254614263,
                                0.34785484513745385737};
constexpr double kTwoPi = 6.28318530717958647692;

// Probability of a (z, phi) box under a solid-angle density (d omega = dz dphi). Adaptive like
// chi_square_sphere's integrator, but with a tolerance fit for the test instead of 1e-7: with
// ~1e5 samples, errors of 1e-3 relative or 1e-8 absolute are invisible to the statistic, and a
// smooth lobe then costs one refinement per cell; only cells crossed by a jump go deep.
class BoxIntegrator {
 public:
  BoxIntegrator(const std::function<double(const Vec3&)>& pdf, int max_depth) : pdf_(pdf), max_depth_(max_depth) {}

  double integrate(double z0, double z1, double p0, double p1) {
    return refine(z0, z1, p0, p1, rule(z0, z1, p0, p1), max_depth_);
  }
  const std::string& error() const { return error_; }

 private:
  double eval(double z, double phi) {
    double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    double v = pdf_(Vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)));
    if (!(v >= 0.0) || std::isinf(v)) {
      if (error_.empty()) error_ = "pdf is " + std::to_string(v) + " at z = " + std::to_string(z);
      return 0.0;
    }
    return v;
  }
  double rule(double z0, double z1, double p0, double p1) {
    double cz = 0.5 * (z0 + z1), hz = 0.5 * (z1 - z0), cp = 0.5 * (p0 + p1), hp = 0.5 * (p1 - p0);
    double sum = 0.0;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) sum += kWeights[i] * kWeights[j] * eval(cz + hz * kNodes[i], cp + hp * kNodes[j]);
    return sum * hz * hp;
  }
  double refine(double z0, double z1, double p0, double p1, double whole, int depth) {
    double zm = 0.5 * (z0 + z1), pm = 0.5 * (p0 + p1);
    double q[4][4] = {{z0, zm, p0, pm}, {zm, z1, p0, pm}, {z0, zm, pm, p1}, {zm, z1, pm, p1}};
    double parts[4], sum = 0.0;
    for (int k = 0; k < 4; ++k) sum += parts[k] = rule(q[k][0], q[k][1], q[k][2], q[k][3]);
    if (depth <= 0 || std::abs(sum - whole) <= 1e-3 * std::abs(sum) + 1e-8) return sum;
    sum = 0.0;
    for (int k = 0; k < 4; ++k) sum += refine(q[k][0], q[k][1], q[k][2], q[k][3], parts[k], depth - 1);
    return sum;
  }

  const std::function<double(const Vec3&)>& pdf_;
  int max_depth_;
  std::string error_;
};

}  // namespace

ChiSquareResult bsdf_chi_square(const Bsdf& bsdf, const Vec3& wo, int n, uint64_t seed,
                                const BsdfChiSquareOptions& options) {
  ShadingContext ctx;
  ctx.mode = options.mode;
  ctx.tex = options.tex;
  // The chart's frame: the identity, or rotated so that a narrow lobe's peak sits at +z, where the
  // cap z >= z_min is cut into many cells. Rotations preserve solid angle, so the pdf needs no Jacobian.
  Frame frame;
  double z_min = -1.0;
  LobeSummary lobe = bsdf.lobe(wo, ctx);
  float alpha = std::max(lobe.alpha_x, lobe.alpha_y);
  if (options.zoom && !lobe.cosine && alpha < 0.15f && glm::dot(lobe.peak, lobe.peak) > 0.f) {
    frame = Frame(glm::normalize(lobe.peak));
    // GGX has long tails: about 6 alpha around the peak holds most of a lobe (in wi, twice the
    // half-vector angle), leaving a modest share to the single cell outside the cap.
    z_min = std::cos(std::min(Pi, 6.f * alpha));
  }
  const int nt = options.theta_bins, np = options.phi_bins;
  const size_t grid = size_t(nt) * size_t(np);
  const bool has_rest = z_min > -1.0;

  // Histogram: bins uniform in z and phi have equal solid angle.
  std::vector<double> observed(grid + 1, 0.0), probability(grid + 1, 0.0);
  Pcg32 rng(seed);
  int invalid = 0;
  std::string sample_problem;
  for (int i = 0; i < n && sample_problem.empty(); ++i) {
    Vec2 u(rng.next_float(), rng.next_float());
    float uc = rng.next_float();
    std::optional<BsdfSample> s = bsdf.sample_f(wo, uc, u, ctx);
    if (!s || s->is_specular() || !(s->pdf > 0.f)) {
      ++invalid;
      continue;
    }
    Vec3 w = frame.to_local(s->wi);
    double len = glm::length(glm::dvec3(w));
    if (!is_finite(w) || std::abs(len - 1.0) > 1e-3) {
      sample_problem = "bad direction (" + std::to_string(w.x) + ", " + std::to_string(w.y) + ", " +
                       std::to_string(w.z) + ")";
      break;
    }
    double z = std::clamp(w.z / len, -1.0, 1.0);
    if (z < z_min) {
      observed[grid] += 1.0;
      continue;
    }
    double phi = std::atan2(double(w.y), double(w.x));
    if (phi < 0.0) phi += kTwoPi;
    int ti = std::min(int((z - z_min) / (1.0 - z_min) * nt), nt - 1);
    int pj = std::min(int(phi / kTwoPi * np), np - 1);
    observed[size_t(ti) * np + pj] += 1.0;
  }

  std::function<double(const Vec3&)> density = [&](const Vec3& w) -> double {
    return bsdf.pdf(wo, frame.to_world(w), ctx);
  };
  BoxIntegrator integrator(density, options.max_refinements);
  double dz = (1.0 - z_min) / nt, dphi = kTwoPi / np;
  for (int i = 0; i < nt; ++i)
    for (int j = 0; j < np; ++j)
      probability[size_t(i) * np + j] = integrator.integrate(z_min + i * dz, z_min + (i + 1) * dz, j * dphi, (j + 1) * dphi);
  if (has_rest) {
    constexpr int kRestStrips = 16;
    double rz = (z_min + 1.0) / kRestStrips;
    for (int i = 0; i < kRestStrips; ++i)
      for (int j = 0; j < np; ++j)
        probability[grid] += integrator.integrate(-1.0 + i * rz, -1.0 + (i + 1) * rz, j * dphi, (j + 1) * dphi);
  }

  ChiSquareResult r;
  if (!sample_problem.empty() || !integrator.error().empty()) {
    r.failure = !sample_problem.empty() ? sample_problem : integrator.error();
  } else {
    std::vector<double> expected(probability.size());
    for (size_t i = 0; i < probability.size(); ++i) expected[i] = probability[i] * n;
    r = chi_square_from_counts(observed, expected, n);
  }
  r.pdf_integral = std::accumulate(probability.begin(), probability.end(), 0.0);
  r.invalid_fraction = double(invalid) / n;
  return r;
}

AlbedoEstimate albedo_estimate(const Bsdf& bsdf, const Vec3& wo, int n, uint64_t seed, TransportMode mode,
                               const TextureEvalContext& tex) {
  ShadingContext ctx;
  ctx.mode = mode;
  ctx.tex = tex;
  Pcg32 rng(seed);
  glm::dvec3 sum(0.0), sum2(0.0);
  AlbedoEstimate e;
  for (int i = 0; i < n; ++i) {
    Vec2 u(rng.next_float(), rng.next_float());
    float uc = rng.next_float();
    std::optional<BsdfSample> s = bsdf.sample_f(wo, uc, u, ctx);
    if (!s || !(s->pdf > 0.f)) continue;
    glm::dvec3 w = glm::dvec3(s->f) * double(std::abs(s->wi.z)) / double(s->pdf);
    if (!std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z)) {
      ++e.non_finite;
      continue;
    }
    e.max_weight = std::max({e.max_weight, w.x, w.y, w.z});
    sum += w;
    sum2 += w * w;
  }
  glm::dvec3 mean = sum / double(n);
  glm::dvec3 variance = glm::max(sum2 / double(n) - mean * mean, glm::dvec3(0.0)) / double(std::max(n - 1, 1));
  e.mean = Rgb(mean);
  e.standard_error = Rgb(glm::sqrt(variance));
  return e;
}

double reciprocity_error(const Bsdf& bsdf, int n_pairs, uint64_t seed) {
  Pcg32 rng(seed);
  ShadingContext ctx;
  double worst = 0.0;
  auto random_direction = [&] {
    float z = rng.next_float();
    float phi = 2.f * Pi * rng.next_float();
    return spherical_direction(z, phi);
  };
  for (int i = 0; i < n_pairs; ++i) {
    Vec3 a = random_direction(), b = random_direction();
    if (a.z == 0.f || b.z == 0.f) continue;
    Rgb fab = bsdf.f(a, b, ctx), fba = bsdf.f(b, a, ctx);
    for (int c = 0; c < 3; ++c) {
      double m = std::max(std::abs(fab[c]), std::abs(fba[c]));
      if (m > 0.0) worst = std::max(worst, std::abs(double(fab[c]) - fba[c]) / m);
    }
  }
  return worst;
}

PdfConsistency pdf_consistency(const Bsdf& bsdf, const Vec3& wo, int n, uint64_t seed, TransportMode mode,
                               const TextureEvalContext& tex) {
  ShadingContext ctx;
  ctx.mode = mode;
  ctx.tex = tex;
  Pcg32 rng(seed);
  PdfConsistency r;
  for (int i = 0; i < n; ++i) {
    Vec2 u(rng.next_float(), rng.next_float());
    float uc = rng.next_float();
    std::optional<BsdfSample> s = bsdf.sample_f(wo, uc, u, ctx);
    if (!s || s->is_specular()) continue;
    ++r.checked;
    double p = bsdf.pdf(wo, s->wi, ctx);
    double pm = std::max(p, double(s->pdf));
    if (pm > 0.0) r.max_pdf_error = std::max(r.max_pdf_error, std::abs(p - s->pdf) / pm);
    Rgb f = bsdf.f(wo, s->wi, ctx);
    for (int c = 0; c < 3; ++c) {
      double m = std::max(std::abs(f[c]), std::abs(s->f[c]));
      if (m > 0.0) r.max_f_error = std::max(r.max_f_error, std::abs(double(f[c]) - s->f[c]) / m);
    }
  }
  return r;
}

double hemisphere_quadrature(const std::function<double(const glm::dvec3& wi)>& f_cos, int nt, int np) {
  double sum = 0.0;
  for (int i = 0; i < nt; ++i) {
    double ci = (i + 0.5) / nt, si = std::sqrt(1.0 - ci * ci);
    for (int j = 0; j < np; ++j) {
      double phi = 2.0 * M_PI * (j + 0.5) / np;
      sum += f_cos(glm::dvec3(si * std::cos(phi), si * std::sin(phi), ci));
    }
  }
  return sum * (1.0 / nt) * (2.0 * M_PI / np);
}

double ggx_d(double alpha, double cos_m) {
  double a2 = alpha * alpha, e = cos_m * cos_m * (a2 - 1.0) + 1.0;
  return a2 / (M_PI * e * e);
}

double ggx_lambda(double alpha, double cos_w) {
  double t2 = (1.0 - cos_w * cos_w) / (cos_w * cos_w);
  return 0.5 * (std::sqrt(1.0 + alpha * alpha * t2) - 1.0);
}

double ggx_albedo_by_quadrature(double alpha, double cos_o) {
  glm::dvec3 wo(std::sqrt(1.0 - cos_o * cos_o), 0.0, cos_o);
  // f cos_i = D G2 / (4 cos_o cos_i) * cos_i
  return hemisphere_quadrature(
      [&](const glm::dvec3& wi) {
        glm::dvec3 wm = glm::normalize(wi + wo);
        return ggx_d(alpha, wm.z) / (1.0 + ggx_lambda(alpha, cos_o) + ggx_lambda(alpha, wi.z)) / (4.0 * cos_o);
      },
      1500, 600);
}

}  // namespace penumbra::test
