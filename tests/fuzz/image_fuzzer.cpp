// libFuzzer target for the environment-image path: read_image (OpenImageIO) followed by the
// importance-sampling distribution an environment light builds from the pixels' luminance. Any
// file must either load (pixel count = width x height x 3) and give a usable distribution, or raise
// penumbra::Error naming the file. The first input byte picks the format (.exr, .hdr, .pfm, .tga,
// .png). Built and run by scripts/fuzz.sh.
#include "fuzz/file_fuzzer.h"
#include "image/image_io.h"

#include <penumbra/error.h>
#include <penumbra/image.h>
#include <penumbra/sampling.h>

#include <cmath>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  static const char* const kExtensions[] = {".exr", ".hdr", ".pfm", ".tga", ".png"};
  std::string path = penumbra::fuzz::write_input(data + 1, size - 1, kExtensions[data[0] % 5]);
  try {
    penumbra::ImageRgb img = penumbra::read_image(path);
    if (img.width <= 0 || img.height <= 0) __builtin_trap();
    if (img.pixels.size() != 3 * static_cast<size_t>(img.width) * img.height) __builtin_trap();
    std::vector<float> lum(static_cast<size_t>(img.width) * img.height);
    for (size_t i = 0; i < lum.size(); ++i) {
      float v = 0.2126f * img.pixels[3 * i] + 0.7152f * img.pixels[3 * i + 1] + 0.0722f * img.pixels[3 * i + 2];
      lum[i] = std::isfinite(v) && v > 0.f ? v : 0.f;
    }
    penumbra::Distribution2D d(lum, static_cast<size_t>(img.width), static_cast<size_t>(img.height));
    float pdf = 0.f;
    penumbra::Vec2 p = d.sample_continuous(penumbra::Vec2(0.37f, 0.61f), &pdf);
    if (!(p.x >= 0.f && p.x <= 1.f && p.y >= 0.f && p.y <= 1.f) || !std::isfinite(pdf)) __builtin_trap();
  } catch (const penumbra::Error& e) {
    if (std::string(e.what()).find(path) == std::string::npos) __builtin_trap();
  }
  return 0;
}
