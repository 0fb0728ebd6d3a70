// penumbra: render pbrt-v4 scene files with plugin integrators, samplers, materials and lights.
//   penumbra                       renders the bundled Cornell box
//   penumbra render SCENE [opts]   renders a scene, command-line options override the file
//   penumbra [opts] SCENE          the same (pbrt's habit: no subcommand means render)
//   penumbra plugins               lists the plugins found and their parameters
//   penumbra merge PARTS -o OUT    combines the parts of a split render (docs/farm.md)
//   penumbra envmap IN OUT --to M  converts an environment image (docs/environment-maps.md)
#include "commands.h"
#include "converge.h"
#include "envmap_command.h"
#include "number_options.h"

#include <penumbra/error.h>
#include <penumbra/version.h>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <algorithm>
#include <cstdio>
#include <regex>
#include <string>
#include <vector>

namespace {

std::pair<int, int> parse_resolution(const std::string& text) {
  std::smatch m;
  static const std::regex re(R"((\d{1,9})[xX](\d{1,9}))");
  if (!std::regex_match(text, m, re) || std::stoi(m[1]) == 0 || std::stoi(m[2]) == 0)
    throw penumbra::Error(fmt::format("--res: expected WIDTHxHEIGHT (e.g. 320x240), got '{}'", text));
  return {std::stoi(m[1]), std::stoi(m[2])};
}

// pbrt renders `pbrt [options] scene.pbrt`: without a subcommand (and with arguments that are not
// --help or --version), `render` is meant.
std::vector<std::string> arguments_with_subcommand(const CLI::App& app, int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "--version") return args;
  auto named = app.get_subcommands([&](const CLI::App* sub) { return sub->check_name(args[0]); });
  if (!named.empty()) return args;
  args.insert(args.begin(), "render");
  return args;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Penumbra " PENUMBRA_VERSION_STRING ": a plugin-based physically based renderer"};
  app.set_version_flag("--version", PENUMBRA_VERSION_STRING);
  app.require_subcommand(0, 1);

  penumbra::RenderSettings settings;
  std::string res;
  int spp = 0;
  uint32_t seed = 0;
  auto* render = app.add_subcommand("render", "Render a scene file");
  render->add_option("scene", settings.scene_file, "pbrt-v4 scene file")->required()->check(CLI::ExistingFile);
  render->add_option("-o,--output,--outfile", settings.output,
                     "output image (.exr, .hdr, .tif, .png); default: the Film's filename");
  auto* spp_opt = render->add_option("--spp", spp, "samples per pixel (overrides the Sampler's pixelsamples)")
                      ->check(penumbra::cli::positive_whole_number());
  render->add_option("--time", settings.time_budget, "time budget in seconds (renders whole passes until it is spent)")
      ->check(penumbra::cli::positive_number("seconds"));
  render->add_option("--threads,--nthreads", settings.threads, "worker threads (default: all cores)")
      ->check(penumbra::cli::whole_number(1, 1024, "a whole number of threads from 1 to 1024"));
  auto* seed_opt = render->add_option("--seed", seed, "sampler seed")->check(penumbra::cli::seed_number());
  render->add_option("--integrator", settings.integrator, "integrator plugin to use instead of the scene's");
  std::vector<std::string> params;
  render->add_option("--param", params, "NAME=VALUE: set an integrator parameter, typed by the integrator's table "
                     "(after --integrator; repeatable), e.g. --param maxdepth=8")
      ->allow_extra_args(false);
  render->add_option("--sampler", settings.sampler, "sampler plugin to use instead of the scene's");
  render->add_flag("--spectral", settings.spectral, "spectral transport: three sampled wavelengths per pixel "
                   "sample, colours as smooth spectra, as pbrt-v4 renders (the Film's \"spectral\")");
  render->add_option("--res", res, "image resolution WIDTHxHEIGHT");
  render->add_option("--stats", settings.stats_file, "write render statistics as JSON");
  render->add_flag("-q,--quiet", settings.quiet, "no progress output");
  render->add_flag("--strict", settings.strict, "scenes that render black (no WorldBegin, nothing to render, no "
                   "light) are errors instead of warnings");
  render->add_option("--firefly-threshold", settings.firefly_threshold,
                     "count samples whose largest component exceeds this (stats: firefly_samples)")
      ->check(penumbra::cli::positive_number());
  render->add_option("--aov", settings.aovs, "auxiliary outputs as EXR layers: albedo, normal, depth, samples, "
                     "variance, nonfinite, all")->delimiter(',');
  int spp_total = 0, spp_count = 0;
  render->add_option("--checkpoint", settings.checkpoint_file, "write checkpoints to FILE (on SIGINT/SIGTERM, and with "
                     "--checkpoint-every); default on interruption: the image's path + .checkpoint");
  render->add_option("--checkpoint-every", settings.checkpoint_every, "also write a checkpoint after the first pass "
                     "at least this many seconds after the previous one")->check(penumbra::cli::positive_number("seconds"));
  render->add_option("--resume", settings.resume_file, "continue the render saved in this checkpoint (same scene and "
                     "options: anything else is refused)");
  auto* total_opt = render->add_option("--spp-total", spp_total, "split render: samples per pixel of the whole render")
                        ->check(penumbra::cli::positive_whole_number());
  render->add_option("--spp-offset", settings.spp_offset, "split render: index of this part's first sample")
      ->check(penumbra::cli::non_negative_whole_number())->needs(total_opt);
  auto* count_opt = render->add_option("--spp-count", spp_count, "split render: samples in this part (default: the rest)")
                        ->check(penumbra::cli::positive_whole_number())->needs(total_opt);

  penumbra::cli::ConvergeSettings conv;
  std::string conv_configs, conv_res;
  auto* converge = app.add_subcommand("converge", "Measure error versus time of integrator:sampler configurations");
  converge->add_option("scene", conv.scene, "pbrt-v4 scene file")->required()->check(CLI::ExistingFile);
  converge->add_option("--configs", conv_configs, "comma-separated integrator[/NAME=VALUE...][:sampler] list, e.g. "
                       "path:sobol,bdpt/maxdepth=8:sobol; NAME=VALUE sets an integrator parameter as --param does")->required();
  converge->add_option("--reference", conv.reference, "reference image (EXR); reference-variance.exr beside it is used if present")->check(CLI::ExistingFile);
  auto* make_ref = converge->add_option("--make-reference", conv.make_reference,
                                        "render a reference for this many seconds (two halves)")
                       ->check(penumbra::cli::positive_number("seconds"));
  converge->add_option("--make-reference-spp", conv.make_reference_spp,
                       "render a reference of two halves of this many samples per pixel each (instead of a time)")
      ->check(penumbra::cli::positive_whole_number())->excludes(make_ref);
  converge->add_option("--reference-config", conv.reference_config, "integrator[/NAME=VALUE...][:sampler] for --make-reference (default: path, or bdpt when path is compared, or one half each)");
  converge->add_option("--time", conv.time, "time budget per run, seconds")->check(penumbra::cli::positive_number("seconds"));
  converge->add_option("--runs", conv.runs, "independent runs per configuration (medians, quartiles and bootstrap intervals over them)")
      ->check(penumbra::cli::whole_number(1, 1000, "a whole number of runs from 1 to 1000"));
  converge->add_option("--snapshots", conv.snapshots, "log-spaced snapshots per run")
      ->check(penumbra::cli::whole_number(2, 64, "a whole number of snapshots from 2 to 64"));
  converge->add_option("-o,--output,--outfile", conv.out_dir, "output folder");
  converge->add_option("--res", conv_res, "image resolution WIDTHxHEIGHT");
  converge->add_option("--threads,--nthreads", conv.threads, "worker threads")
      ->check(penumbra::cli::whole_number(1, 1024, "a whole number of threads from 1 to 1024"));

  std::vector<std::string> merge_parts;
  std::string merge_output;
  auto* merge = app.add_subcommand("merge", "Combine the parts of a split render into one image");
  merge->add_option("parts", merge_parts, "EXR parts written with --spp-total")->required()->check(CLI::ExistingFile);
  merge->add_option("-o,--output,--outfile", merge_output, "merged image (.exr)")->required();

  penumbra::cli::EnvmapSettings env;
  auto* envmap = app.add_subcommand("envmap", "Convert an environment image between pbrt-v4's equal-area map and equirectangular");
  envmap->add_option("input", env.input, "environment image")->required()->check(CLI::ExistingFile);
  envmap->add_option("output", env.output, "converted image (.exr, .pfm, .hdr, .tif)")->required();
  envmap->add_option("--to", env.to, "mapping to write: equalarea (pbrt-v4's) or equirectangular")->required();
  envmap->add_option("--from", env.from, "mapping of the input (default: square = equalarea, 2:1 = equirectangular)");
  envmap->add_option("--size", env.size, "output width: N x N equal area, N x N/2 equirectangular (default: as many texels as the input)")
      ->check(penumbra::cli::positive_whole_number());

  std::vector<std::string> plugin_dirs;
  auto* plugins = app.add_subcommand("plugins", "List plugins with their parameters");
  plugins->add_option("--dir", plugin_dirs, "search these folders instead of the default path");

  try {
    std::vector<std::string> args = arguments_with_subcommand(app, argc, argv);
    std::reverse(args.begin(), args.end());  // CLI11 takes the arguments last first
    app.parse(args);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "error: %s\nRun with --help for usage.\n", e.what());
    return 1;
  }

  try {
    if (*plugins) return penumbra::cli::run_plugins(plugin_dirs);
    if (*merge) return penumbra::cli::run_merge(merge_parts, merge_output);
    if (*envmap) return penumbra::cli::run_envmap(env);
    if (*converge) {
      conv.configs = penumbra::cli::parse_configs(conv_configs);
      if (!conv_res.empty()) conv.resolution = parse_resolution(conv_res);
      return penumbra::cli::run_converge(conv);
    }
    if (!*render) settings.scene_file = penumbra::cli::default_scene();
    if (*spp_opt) settings.spp = spp;
    if (*seed_opt) settings.seed = seed;
    if (*total_opt) settings.spp_total = spp_total;
    if (*count_opt) settings.spp_count = spp_count;
    if (!res.empty()) settings.resolution = parse_resolution(res);
    for (const std::string& p : params) settings.integrator_params.push_back(penumbra::parse_param_override(p));
    settings.handle_signals = true;
    return penumbra::cli::run_render(settings);
  } catch (const penumbra::Error& e) {
    std::fprintf(stderr, "%s\n", e.formatted().c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
