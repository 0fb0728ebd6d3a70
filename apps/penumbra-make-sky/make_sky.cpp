// Writes a synthetic equirectangular sky for the environment-lit scenes: a blue gradient above the
// horizon, a dim ground below it, and a small, very bright sun disk. The sky that ships in
// scenes/environment/ was made with `penumbra-make-sky scenes/environment/sky.exr`.
//
// Mapping: equirectangular, column u = phi / 2pi, row v = theta / pi, +z up. The "infinite" light
// reads a 2:1 image that way only with "string mapping" "equirectangular" (or with a warning);
// `penumbra envmap OUT.exr SKY.exr --to equalarea` makes the square equal-area map pbrt-v4 reads.
//
// Usage: penumbra-make-sky OUT.exr [WIDTH HEIGHT SUN_ELEVATION_DEG SUN_AZIMUTH_DEG SUN_RADIANCE]
#include <penumbra/color.h>
#include <penumbra/error.h>
#include <penumbra/image.h>
#include <penumbra/math.h>

#include "number_options.h"

#include <cstdio>
#include <string>

using namespace penumbra;

int main(int argc, char** argv) {
  std::string out;
  int w = 256, h = 128;
  double elevation_deg = 35.0, azimuth_deg = 60.0, sun_radiance = 1500.0;
  CLI::App app{"Writes the synthetic equirectangular sky of the environment-lit scenes"};
  app.add_option("out", out, "image to write (.exr, .pfm, .hdr, ...)")->required();
  app.add_option("width", w, "columns (default 256)")->check(cli::whole_number(8, 65536, "a whole number from 8 to 65536"));
  app.add_option("height", h, "rows (default 128)")->check(cli::whole_number(4, 32768, "a whole number from 4 to 32768"));
  app.add_option("sun_elevation", elevation_deg, "degrees above the horizon (default 35)")->check(cli::finite_number("degrees"));
  app.add_option("sun_azimuth", azimuth_deg, "degrees from +x towards +y (default 60)")->check(cli::finite_number("degrees"));
  app.add_option("sun_radiance", sun_radiance, "radiance of the sun disk (default 1500)")->check(cli::positive_number());
  if (std::optional<int> exit_code = cli::parse_tool_options(app, argc, argv, "error:")) return *exit_code;
  const float elevation = radians(static_cast<float>(elevation_deg)), azimuth = radians(static_cast<float>(azimuth_deg));
  const float sun_L = static_cast<float>(sun_radiance);
  const float sun_radius = radians(1.6f);  // a little over a texel at 256 x 128, like a small sun
  Vec3 sun(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth), std::sin(elevation));

  ImageRgb img;
  img.width = w;
  img.height = h;
  img.pixels.resize(3 * static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float theta = Pi * (y + 0.5f) / h, phi = 2.f * Pi * (x + 0.5f) / w;
      Vec3 d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      Rgb L;
      if (d.z >= 0.f) {
        float t = std::pow(d.z, 0.4f);  // zenith blue, whiter towards the horizon
        L = glm::mix(Rgb(0.9f, 0.95f, 1.05f), Rgb(0.25f, 0.45f, 0.95f), t);
        float glow = std::max(0.f, glm::dot(d, sun));
        L += Rgb(1.f, 0.8f, 0.5f) * 0.6f * std::pow(glow, 32.f);  // haze around the sun
      } else {
        L = Rgb(0.12f, 0.1f, 0.08f);  // ground
      }
      if (std::acos(std::clamp(glm::dot(d, sun), -1.f, 1.f)) < sun_radius) L = Rgb(1.f, 0.92f, 0.8f) * sun_L;
      float* p = &img.pixels[3 * (static_cast<size_t>(y) * w + x)];
      p[0] = L.r, p[1] = L.g, p[2] = L.b;
    }
  try {
    write_image(out, img);
  } catch (const Error& e) {
    std::fprintf(stderr, "%s\n", e.formatted().c_str());
    return 1;
  }
  return 0;
}
