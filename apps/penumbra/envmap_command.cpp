#include "envmap_command.h"

#include "environment_map.h"
#include "image/image_io.h"

#include <penumbra/error.h>
#include <penumbra/image.h>

#include <fmt/core.h>

#include <cmath>
#include <cstdio>

namespace penumbra::cli {

namespace {

envmap::Mapping input_mapping(const EnvmapSettings& s, const ImageRgb& in) {
  if (!s.from.empty()) {
    auto m = envmap::parse_mapping(s.from);
    if (!m) throw Error(fmt::format("--from: expected equalarea or equirectangular, got '{}'", s.from));
    if (*m == envmap::Mapping::EqualArea && in.width != in.height)
      throw Error(fmt::format("--from equalarea: {} is {}x{}, and an equal-area map is square", s.input, in.width, in.height));
    return *m;
  }
  auto m = envmap::mapping_from_shape(in.width, in.height);
  if (!m)
    throw Error(fmt::format("{} is {}x{}: neither square (equal area) nor 2:1 (equirectangular); say which with --from",
                            s.input, in.width, in.height));
  return *m;
}

}  // namespace

int run_envmap(const EnvmapSettings& s) {
  auto to = envmap::parse_mapping(s.to);
  if (!to) throw Error(fmt::format("--to: expected equalarea or equirectangular, got '{}'", s.to));
  if (s.size < 0) throw Error("--size must be positive");
  if (*to == envmap::Mapping::Equirectangular && s.size % 2 != 0)
    throw Error(fmt::format("--size {}: an equirectangular map is N x N/2, so N must be even", s.size));

  if (std::string problem = image_output_problem(s.output); !problem.empty())
    throw Error(fmt::format("output: {}", problem));
  ImageRgb in = read_image(s.input);
  if (in.width <= 0 || in.height <= 0) throw Error(fmt::format("{} is empty", s.input));
  for (float v : in.pixels)
    if (!std::isfinite(v) || v < 0.f) throw Error(fmt::format("{} has negative or non-finite texels", s.input));
  envmap::Mapping from = input_mapping(s, in);

  auto [width, height] = envmap::default_size(*to, in.width, in.height);
  if (s.size > 0) {
    width = s.size;
    height = *to == envmap::Mapping::EqualArea ? s.size : s.size / 2;
  }
  ImageRgb out = envmap::resample(in, from, *to, width, height);
  write_image(s.output, out);

  envmap::RgbD before = envmap::sphere_mean(in, from), after = envmap::sphere_mean(out, *to);
  auto change = [](double a, double b) { return a > 0.0 ? 100.0 * (b / a - 1.0) : 0.0; };
  std::fprintf(stderr,
               "wrote %s: %dx%d %s from %s (%dx%d %s)\n"
               "mean radiance over the sphere: %.6g %.6g %.6g -> %.6g %.6g %.6g (%+.3f %%, %+.3f %%, %+.3f %%)\n",
               s.output.c_str(), width, height, envmap::mapping_name(*to), s.input.c_str(), in.width, in.height,
               envmap::mapping_name(from), before.r, before.g, before.b, after.r, after.g,
               after.b, change(before.r, after.r), change(before.g, after.g), change(before.b, after.b));
  return 0;
}

}  // namespace penumbra::cli
