// `penumbra converge`: error versus time of integrator x sampler configurations against a reference,
// averaged over independent runs, written as CSV and JSON for scripts/plot-convergence.py.
#pragma once

#include "render/render_session.h"

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace penumbra::cli {

/// One configuration: "bdpt/hrr=true/hrrconnections=32:sobol" is integrator "bdpt" with two
/// parameter overrides and sampler "sobol"; `name` is the text as given (results, plots).
struct ConvergeConfig {
  std::string name;
  std::string integrator;
  std::string sampler;                 // empty: the scene's
  std::vector<ParamOverride> params;   // applied like --param
};

struct ConvergeSettings {
  std::string scene;
  std::string reference;                 // EXR of the reference (or empty with make_reference)
  double make_reference = 0.0;           // seconds for a new reference (two independent halves)
  int make_reference_spp = 0;            // or samples per pixel of each half (0: by time)
  std::string reference_config;          // empty: an unbiased integrator not compared (path, else bdpt, else both)
  std::vector<ConvergeConfig> configs;
  double time = 60.0;                    // budget per run, seconds
  int runs = 8;
  int snapshots = 8;                     // log-spaced: time / 2^(snapshots-1) ... time
  std::string out_dir = "study";
  std::optional<std::pair<int, int>> resolution;
  int threads = 0;
};

/// Parses "path:sobol,bdpt/maxdepth=8:halton" (a missing sampler means the scene's). `option` names
/// the command-line option in errors ("--configs", "--reference-config").
std::vector<ConvergeConfig> parse_configs(const std::string& text, const std::string& option = "--configs");

int run_converge(const ConvergeSettings& settings);

}  // namespace penumbra::cli
