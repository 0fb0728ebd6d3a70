// Per-pixel state of stochastic progressive photon mapping: the visible point a camera path found in
// the current iteration, the photon statistics that survive across iterations, and the progressive
// radius/flux update (Hachisuka and Jensen 2009).
#pragma once

#include <penumbra/bsdf.h>
#include <penumbra/color.h>
#include <penumbra/math.h>

#include <atomic>
#include <cmath>
#include <cstdint>

namespace penumbra::sppm {

/// Where a camera path met its first diffuse surface in this iteration. The Bsdf belongs to the
/// scene (materials are shared objects), so keeping a pointer across the photon pass is safe.
struct VisiblePoint {
  Frame shading;                 // shading frame at the point (the BSDF works in it)
  Vec3 wo{0.f};                  // towards the camera, in the shading frame
  TextureEvalContext tex;        // where a textured material is evaluated
  const Bsdf* bsdf = nullptr;    // null: no visible point in this pixel this iteration
  Rgb beta{0.f};                 // camera path throughput up to the point
  // Deepest photon vertex whose light may be gathered here: the camera prefix has already used
  // `depth` bounces and the gather adds one, so maxdepth - 1 - depth keeps every path within maxdepth,
  // the same truncation as the path integrator's.
  int max_photon_depth = 0;
};

/// What a photon needs at a visible point (its throughput is applied at the update instead), copied
/// into the grid's slot order each iteration: 72 bytes. A textured material's full lookup context
/// stays in the VisiblePoint (`textured`), so untextured gathers touch no more memory.
struct GatherPoint {
  Frame shading;
  Vec3 wo{0.f};
  Vec2 uv{0.f};
  const Bsdf* bsdf = nullptr;
  int max_photon_depth = 0;
  bool textured = false;  // the visible point's TextureEvalContext has a footprint (look it up there)
};

/// Statistics that persist across iterations (pbrt's N, r, tau) plus the camera-side sum Ld.
/// Doubles: they accumulate thousands of iterations.
struct PixelStatistics {
  double Ld[3] = {0, 0, 0};   // emitted + direct light along the camera prefixes, summed over iterations
  double tau[3] = {0, 0, 0};  // flux gathered so far, rescaled to the current radius
  double N = 0.0;             // photons credited so far (fractional: only alpha of each batch)
  double radius = 0.0;
};

/// Photons gathered by one visible point during the current photon pass. Deposits arrive from all
/// threads in any order, so they are added as integers (multiples of a fixed quantum): integer sums do
/// not depend on the order, which keeps the image bit-identical for a seed whatever the thread count.
struct PhotonAccumulator {
  std::atomic<int64_t> phi[3] = {0, 0, 0};
  std::atomic<int64_t> M{0};

  /// Adds one photon's beta * f; `inv_quantum` maps flux to integer units. Values beyond 2^50
  /// quanta (~10^4 times the scene's total power, see photon_quantum) are clamped so a sum of
  /// millions of deposits cannot overflow.
  void add(const Rgb& phi_value, double inv_quantum) {
    for (int c = 0; c < 3; ++c) {
      double q = std::min(static_cast<double>(phi_value[c]) * inv_quantum, 0x1p50);
      int64_t units = static_cast<int64_t>(std::llround(q));
      if (units != 0) phi[c].fetch_add(units, std::memory_order_relaxed);
    }
    M.fetch_add(1, std::memory_order_relaxed);
  }
  void reset() {
    for (auto& p : phi) p.store(0, std::memory_order_relaxed);
    M.store(0, std::memory_order_relaxed);
  }
};

/// Quantum of the photon accumulators for a scene whose lights emit `total_power` (luminance):
/// 2^-36 of it, so a deposit is resolved to ~1e-11 of the power and a pixel can gather 2^27 times the
/// power in one pass before the 64-bit sum overflows.
inline double photon_quantum(double total_power) {
  return std::ldexp(total_power > 0.0 ? total_power : 1.0, -36);
}

/// One progressive update after a photon pass: M photons carried flux Phi (already multiplied by the
/// visible point's throughput). Only alpha of the new photons are kept in the count, the radius
/// shrinks so that the photon density per area stays what it was, and tau is rescaled to the smaller
/// disk (it would have gathered that fraction of the flux). Pixels with no photons keep their state.
inline void update_statistics(PixelStatistics& s, double M, const double Phi[3], double alpha) {
  if (M <= 0.0) return;
  double N_new = s.N + alpha * M;
  double ratio = N_new / (s.N + M);  // (r_new / r)^2
  for (int c = 0; c < 3; ++c) s.tau[c] = (s.tau[c] + Phi[c]) * ratio;
  s.N = N_new;
  s.radius *= std::sqrt(ratio);
}

/// The pixel's estimate after `iterations` iterations and `photons` emitted photons in total:
/// the mean camera-side light plus the density estimate tau / (photons * pi r^2).
inline Rgb pixel_estimate(const PixelStatistics& s, double iterations, double photons) {
  Rgb L(0.f);
  double area = Pi * s.radius * s.radius;
  for (int c = 0; c < 3; ++c) {
    double v = s.Ld[c] / iterations;
    if (photons > 0.0 && area > 0.0) v += s.tau[c] / (photons * area);
    L[c] = static_cast<float>(v);
  }
  return L;
}

}  // namespace penumbra::sppm
