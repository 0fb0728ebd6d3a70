// The table of sigmoid coefficients (sigmoid_fit.h) for every reflectance colour, fitted once when
// Penumbra is built (core/tools/make_rgb_to_spectrum_table.cpp) and compiled into the core.
//
// Layout: a colour is located by its largest channel m (which of r, g, b), that channel's value z
// and the other two channels divided by it, x = rgb[(m+1)%3] / z and y = rgb[(m+2)%3] / z, both in
// [0, 1]. x and y are sampled uniformly at kResolution points, z at kResolution points crowded
// towards 0 and 1 (z_k = smoothstep(smoothstep(k / (kResolution - 1)))), where the coefficients
// change fastest. A lookup interpolates the coefficients trilinearly in (x, y, z).
#pragma once

#include <cstddef>
#include <cstdint>

#include "spectra/sigmoid_fit.h"

namespace penumbra::spectra {

class RgbToSpectrumTable {
 public:
  static constexpr int kResolution = 64;
  static constexpr uint32_t kMagic = 0x50525332;  // "PRS2"

  /// The grid value z_k.
  static float z_node(int k) {
    float x = static_cast<float>(k) / (kResolution - 1);
    x = x * x * (3.f - 2.f * x);
    return x * x * (3.f - 2.f * x);
  }
  /// Bytes of the table file: magic, resolution, then floats
  /// coefficients[m][z][y][x][3] for m in 0..2 and each index in 0..kResolution-1.
  static constexpr size_t kFloats = 3ull * kResolution * kResolution * kResolution * 3;
  static constexpr size_t kBytes = 2 * sizeof(uint32_t) + kFloats * sizeof(float);

  /// The table compiled into the core.
  static const RgbToSpectrumTable& built_in();
  /// A table over `data` (kBytes, as the generator writes it); throws Error when it is not one.
  explicit RgbToSpectrumTable(const void* data, size_t bytes);

  /// Coefficients for a reflectance (each channel clamped to [0, 1]); greys are exact constants.
  SigmoidCoefficients operator()(float r, float g, float b) const;

 private:
  const float* coefficients_ = nullptr;
  float z_[kResolution];
};

}  // namespace penumbra::spectra
