#include "render/render_outputs.h"

#include "image/film_aovs.h"
#include "image/image_io.h"
#include "util/output_file.h"

#include <penumbra/version.h>

#include <fmt/core.h>

#include <cstdint>
#include <regex>

namespace penumbra {

namespace {

// The image a render writes and who named it, for messages: "-o" or the scene's Film "filename".
struct ImageOutput {
  std::string path;
  std::string option;  // "-o", or "" when the scene (or the default) chose it
  FileLoc loc;         // the Film's "filename" parameter, when the scene chose it
};

ImageOutput image_output(const RenderSettings& settings, const SceneDescription& desc) {
  if (!settings.output.empty()) return {settings.output, "-o", {}};
  const Param* f = desc.film.params.find("filename");
  if (f && !f->strings.empty()) return {f->strings[0], "", f->loc};
  return {kDefaultOutput, "", {}};
}

Error output_error(const ImageOutput& out, const std::string& message) {
  if (!out.option.empty()) return Error(fmt::format("{}: {}", out.option, message));
  if (out.loc.filename) return Error(out.loc, message);
  return Error(fmt::format("the default output {}: {}", out.path, message));
}

}  // namespace

void check_command_line_outputs(const RenderSettings& settings) {
  if (!settings.output.empty()) {
    std::string problem = image_output_problem(settings.output);
    if (!problem.empty()) throw Error(fmt::format("-o: {}", problem));
  }
  if (!settings.stats_file.empty()) {
    std::string problem = output_path_problem(settings.stats_file);
    if (!problem.empty())
      throw Error(fmt::format("--stats: cannot write '{}': {}", settings.stats_file, problem));
  }
}

SampleRange apply_output_settings(const RenderSettings& settings, SceneDescription& desc) {
  SampleRange range;
  bool has_part = settings.spp_offset != 0 || settings.spp_count.has_value();
  if (has_part && !settings.spp_total) throw Error("--spp-offset and --spp-count need --spp-total");
  if (settings.spp_total) {
    int n = *settings.spp_total;
    if (settings.spp) throw Error("--spp and --spp-total exclude each other: a part's size is --spp-count");
    if (settings.time_budget > 0.0) throw Error("--time cannot split a render: parts need fixed sample ranges");
    if (n <= 0) throw Error("--spp-total must be positive");
    if (settings.spp_offset < 0 || settings.spp_offset >= n)
      throw Error(fmt::format("--spp-offset {} is outside the {} samples of --spp-total", settings.spp_offset, n));
    int count = settings.spp_count.value_or(n - settings.spp_offset);
    if (count <= 0 || count > n - settings.spp_offset)
      throw Error(fmt::format("--spp-count {} does not fit: samples {}-{} of {} remain after --spp-offset {}",
                              count, settings.spp_offset, n, n, settings.spp_offset));
    range = SampleRange{n, settings.spp_offset, count, true};
    desc.sampler.params.set_int("pixelsamples", n);
  }

  std::vector<std::string> aovs;
  FileLoc loc;
  if (const Param* p = desc.film.params.find("aovs")) {
    aovs = p->strings;
    loc = p->loc;
  }
  parse_aovs(settings.aovs);  // a wrong --aov name is reported without a scene location
  aovs.insert(aovs.end(), settings.aovs.begin(), settings.aovs.end());
  if (range.split) aovs.push_back("samples");
  AovSet set = parse_aovs(aovs, loc);
  if (set.any()) desc.film.params.set_string("aovs", set.names());

  ImageOutput out = image_output(settings, desc);
  std::string problem = settings.image_written ? image_output_problem(out.path) : "";
  if (!problem.empty()) throw output_error(out, problem);
  if (range.split && !is_exr_path(out.path))
    throw output_error(out, fmt::format("a part of a split render must be written as .exr (for `penumbra merge`), "
                                        "not '{}'", out.path));
  if (set.any() && !is_exr_path(out.path))
    throw output_error(out, fmt::format("AOVs ({}) are written as EXR layers: the output '{}' must be .exr",
                                        set.names(), out.path));
  return range;
}

std::string format_ranges(const std::vector<std::pair<int, int>>& ranges) {
  std::string out;
  for (const auto& [a, b] : ranges) out += fmt::format("{}{}-{}", out.empty() ? "" : ",", a, b);
  return out;
}

std::vector<std::pair<int, int>> parse_ranges(const std::string& text) {
  static const std::regex re(R"((\d+)-(\d+))");
  std::vector<std::pair<int, int>> out;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    std::string item = text.substr(start, end - start);
    std::smatch m;
    if (!std::regex_match(item, m, re) || std::stoll(m[1]) >= std::stoll(m[2]) || std::stoll(m[2]) > INT32_MAX)
      throw Error(fmt::format("malformed sample range '{}' (expected FIRST-END[,FIRST-END...])", text));
    out.emplace_back(std::stoi(m[1]), std::stoi(m[2]));
    start = end + 1;
  }
  return out;
}

std::vector<std::pair<std::string, std::string>> render_metadata(const RenderStats& s) {
  int first = s.first_sample;
  return {{"penumbra:version", PENUMBRA_VERSION_STRING},
          {"penumbra:scene_hash", s.scene_hash},
          {"penumbra:integrator", s.integrator},
          {"penumbra:sampler", s.sampler},
          {"penumbra:spp", std::to_string(s.spp)},
          {"penumbra:spp_total", std::to_string(s.spp_total)},
          {"penumbra:seed", std::to_string(s.seed)},
          {"penumbra:sample_range", s.spp > 0 ? format_ranges({{first, first + s.spp}}) : ""},
          {"penumbra:scene", s.scene_file},
          {"penumbra:aovs", s.aovs}};
}

void write_render_image(const RenderResult& result) {
  const RenderStats& s = result.stats;
  if (result.aovs.empty()) {
    write_image(s.output, result.image, render_metadata(s));
    return;
  }
  LayeredImage image;
  image.width = result.image.width;
  image.height = result.image.height;
  image.layers.push_back(ImageLayer{"", {"R", "G", "B"}, result.image.pixels});
  image.layers.insert(image.layers.end(), result.aovs.begin(), result.aovs.end());
  image.metadata = render_metadata(s);
  write_layered_exr(s.output, image);
}

}  // namespace penumbra
