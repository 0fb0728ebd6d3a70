// Fits the sigmoid coefficients of every colour of the RGB-to-spectrum table
// (core/src/spectra/rgb_to_spectrum_table.h) and writes the table file. Run by the build:
//   make_rgb_to_spectrum_table OUTPUT
// For each largest channel and each (x, y) of the grid, the fit starts at the brightness node
// kResolution / 5 from the flat spectrum and walks up, then down, through the brightness nodes, each
// fit starting from its neighbour's solution (colours along such a walk change smoothly).
#include "spectra/rgb_to_spectrum_table.h"

#include <atomic>
#include <cstdio>
#include <fstream>
#include <thread>
#include <vector>

using namespace penumbra::spectra;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_rgb_to_spectrum_table OUTPUT\n");
    return 2;
  }
  constexpr int n = RgbToSpectrumTable::kResolution;
  std::vector<float> table(RgbToSpectrumTable::kFloats);
  std::atomic<int> next{0};
  std::vector<double> worst(3 * n, 0.0);
  auto work = [&] {
    for (int job; (job = next++) < 3 * n;) {
      int m = job / n, yi = job % n;
      for (int xi = 0; xi < n; ++xi) {
        float x = static_cast<float>(xi) / (n - 1), y = static_cast<float>(yi) / (n - 1);
        auto fit_at = [&](int zi, SigmoidCoefficients& c) {
          float z = RgbToSpectrumTable::z_node(zi);
          glm::dvec3 rgb(0.0);
          rgb[m] = z, rgb[(m + 1) % 3] = x * z, rgb[(m + 2) % 3] = y * z;
          double err = fit_sigmoid(rgb, c);
          // Very dark colours are fitted as far as they go (their coefficients only steer the
          // interpolation towards black); elsewhere the fit must reach the colour.
          if (z > 0.01f) worst[job] = std::max(worst[job], err);
          float* out = &table[3 * ((((static_cast<size_t>(m) * n + zi) * n + yi) * n) + xi)];
          for (int i = 0; i < 3; ++i) out[i] = c[i];
        };
        const int start = n / 5;
        SigmoidCoefficients c{0.f, 0.f, 0.f};
        for (int zi = start; zi < n; ++zi) fit_at(zi, c);
        c = {0.f, 0.f, 0.f};
        fit_at(start, c);
        for (int zi = start - 1; zi >= 0; --zi) fit_at(zi, c);
      }
    }
  };
  std::vector<std::thread> threads;
  unsigned count = std::max(1u, std::thread::hardware_concurrency());
  for (unsigned i = 0; i < count; ++i) threads.emplace_back(work);
  for (std::thread& t : threads) t.join();
  double max_err = 0.0;
  for (double e : worst) max_err = std::max(max_err, e);
  std::printf("make_rgb_to_spectrum_table: %d^3 x 3 colours, largest CIELAB error %.2e\n", n, max_err);
  if (!(max_err < 1e-2)) {
    std::fprintf(stderr, "make_rgb_to_spectrum_table: a fit did not converge (CIELAB error %g)\n", max_err);
    return 1;
  }
  std::ofstream out(argv[1], std::ios::binary);
  uint32_t header[2] = {RgbToSpectrumTable::kMagic, static_cast<uint32_t>(n)};
  out.write(reinterpret_cast<const char*>(header), sizeof header);
  out.write(reinterpret_cast<const char*>(table.data()), static_cast<std::streamsize>(table.size() * sizeof(float)));
  return out ? 0 : 1;
}
