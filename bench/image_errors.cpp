// Error of an image against a reference, with the metrics `penumbra converge` uses
// (render/image_metrics.h): relMSE = mean over pixels and channels of (I - R)^2 / (R^2 + 0.01).
// Usage: penumbra-bench-image-errors IMAGE REFERENCE
//        penumbra-bench-image-errors --reference-noise HALF_A SPP_A HALF_B SPP_B
// The first prints one JSON object: relmse, rmse, mae, nonfinite (channel values of IMAGE that are
// NaN or infinite; any makes the errors NaN, printed as null), width, height. The second combines two
// independent halves of a reference, weighted by their samples per pixel, and prints the reference's
// noise (render/image_metrics.h, ReferenceNoise): floor (what a perfect image shows against it) and
// own_error (its own relMSE, estimated over each pixel's neighbours), width, height.
#include "render/image_metrics.h"

#include <penumbra/error.h>
#include <penumbra/image.h>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

using namespace penumbra;

namespace {

// A half's samples per pixel: a positive number, the whole argument.
double sample_count(const char* text, const char* name) {
  char* end = nullptr;
  double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || !(v > 0.0) || !std::isfinite(v))
    throw Error(fmt::format("--reference-noise: {} must be a positive number, got '{}'", name, text));
  return v;
}

int print_reference_noise(char** argv) {
  double n_a = sample_count(argv[3], "SPP_A"), n_b = sample_count(argv[5], "SPP_B");
  ImageRgb a = read_image(argv[2]), b = read_image(argv[4]);
  ImageRgb reference;
  ImageRgb variance = half_reference_variance(a, b, &reference, n_a / (n_a + n_b));
  ReferenceNoise noise = reference_noise(reference, variance);
  nlohmann::json j;
  j["floor"] = noise.floor;
  j["own_error"] = noise.error;
  j["width"] = reference.width;
  j["height"] = reference.height;
  std::printf("%s\n", j.dump().c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const bool noise_mode = argc == 6 && std::string(argv[1]) == "--reference-noise";
  if (argc != 3 && !noise_mode) {
    std::fprintf(stderr, "usage: %s IMAGE REFERENCE\n       %s --reference-noise HALF_A SPP_A HALF_B SPP_B\n", argv[0],
                 argv[0]);
    return 2;
  }
  try {
    if (noise_mode) return print_reference_noise(argv);
    ImageRgb image = read_image(argv[1]);
    ImageRgb reference = read_image(argv[2]);
    ImageErrors e = image_errors(image, reference);
    size_t nonfinite = 0;
    for (float v : image.pixels) nonfinite += !std::isfinite(v);
    nlohmann::json j;
    j["relmse"] = e.rel_mse;
    j["rmse"] = e.rmse;
    j["mae"] = e.mae;
    j["nonfinite"] = nonfinite;
    j["width"] = image.width;
    j["height"] = image.height;
    std::printf("%s\n", j.dump().c_str());
  } catch (const Error& e) {
    std::fprintf(stderr, "%s\n", e.formatted().c_str());
    return 1;
  }
  return 0;
}
