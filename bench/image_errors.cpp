// Error of an image against a reference, with the metrics `penumbra converge` uses
// (render/image_metrics.h): relMSE = mean over pixels and channels of (I - R)^2 / (R^2 + 0.01).
// Usage: penumbra-bench-image-errors IMAGE REFERENCE
// Prints one JSON object: relmse, rmse, mae, nonfinite (channel values of IMAGE that are NaN or
// infinite; any makes the errors NaN, printed as null), width, height.
#include "render/image_metrics.h"

#include <penumbra/error.h>
#include <penumbra/image.h>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>

using namespace penumbra;

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s IMAGE REFERENCE\n", argv[0]);
    return 2;
  }
  try {
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
