#include "spectra/rgb_to_spectrum_table.h"

#include <penumbra/error.h>

#include <algorithm>
#include <cstring>

// The generated table (core/CMakeLists.txt passes its path), linked in as read-only data.
#define PENUMBRA_STRINGIFY_(x) #x
#define PENUMBRA_STRINGIFY(x) PENUMBRA_STRINGIFY_(x)
asm(".section .rodata\n"
    ".balign 16\n"
    "penumbra_rgb_to_spectrum_table:\n"
    ".incbin \"" PENUMBRA_STRINGIFY(PENUMBRA_RGB_TO_SPECTRUM_TABLE) "\"\n"
    "penumbra_rgb_to_spectrum_table_end:\n"
    ".previous\n");
extern "C" const unsigned char penumbra_rgb_to_spectrum_table[];
extern "C" const unsigned char penumbra_rgb_to_spectrum_table_end[];

namespace penumbra::spectra {

const RgbToSpectrumTable& RgbToSpectrumTable::built_in() {
  static const RgbToSpectrumTable table(
      penumbra_rgb_to_spectrum_table,
      static_cast<size_t>(penumbra_rgb_to_spectrum_table_end - penumbra_rgb_to_spectrum_table));
  return table;
}

RgbToSpectrumTable::RgbToSpectrumTable(const void* data, size_t bytes) {
  uint32_t header[2] = {0, 0};
  if (bytes >= sizeof header) std::memcpy(header, data, sizeof header);
  if (bytes != kBytes || header[0] != kMagic || header[1] != static_cast<uint32_t>(kResolution))
    throw Error("the RGB-to-spectrum table is damaged (" + std::to_string(bytes) + " bytes, expected " +
                std::to_string(kBytes) + "): rebuild Penumbra");
  coefficients_ = reinterpret_cast<const float*>(static_cast<const unsigned char*>(data) + sizeof header);
  for (int k = 0; k < kResolution; ++k) z_[k] = z_node(k);
}

SigmoidCoefficients RgbToSpectrumTable::operator()(float r, float g, float b) const {
  float rgb[3] = {std::clamp(r, 0.f, 1.f), std::clamp(g, 0.f, 1.f), std::clamp(b, 0.f, 1.f)};
  if (rgb[0] == rgb[1] && rgb[1] == rgb[2]) return constant_sigmoid(rgb[0]);
  int m = rgb[0] > rgb[1] ? (rgb[0] > rgb[2] ? 0 : 2) : (rgb[1] > rgb[2] ? 1 : 2);
  float z = rgb[m];
  float x = rgb[(m + 1) % 3] / z * (kResolution - 1), y = rgb[(m + 2) % 3] / z * (kResolution - 1);
  int xi = std::min(static_cast<int>(x), kResolution - 2), yi = std::min(static_cast<int>(y), kResolution - 2);
  int zi = static_cast<int>(std::upper_bound(z_, z_ + kResolution, z) - z_) - 1;
  zi = std::clamp(zi, 0, kResolution - 2);
  float fx = x - xi, fy = y - yi, fz = (z - z_[zi]) / (z_[zi + 1] - z_[zi]);
  SigmoidCoefficients c{0.f, 0.f, 0.f};
  const size_t n = kResolution;
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        float w = (dx ? fx : 1.f - fx) * (dy ? fy : 1.f - fy) * (dz ? fz : 1.f - fz);
        const float* v = coefficients_ + 3 * ((((m * n + zi + dz) * n + yi + dy) * n) + xi + dx);
        for (int i = 0; i < 3; ++i) c[i] += w * v[i];
      }
  return c;
}

}  // namespace penumbra::spectra
