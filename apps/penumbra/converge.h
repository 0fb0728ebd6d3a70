// `penumbra converge`: error versus time of integrator x sampler configurations against a reference,
// averaged over independent runs, written as CSV and JSON for scripts/plot-convergence.py.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace penumbra::cli {

struct ConvergeSettings {
  std::string scene;
  std::string reference;                 // EXR of the reference (or empty with make_reference)
  double make_reference = 0.0;           // seconds for a new reference (two independent halves)
  std::string reference_config = "path:sobol";
  std::vector<std::pair<std::string, std::string>> configs;  // (integrator, sampler)
  double time = 60.0;                    // budget per run, seconds
  int runs = 4;
  int snapshots = 8;                     // log-spaced: time / 2^(snapshots-1) ... time
  std::string out_dir = "study";
  std::optional<std::pair<int, int>> resolution;
  int threads = 0;
};

/// Parses "path:sobol,bdpt:halton" (a missing sampler means the scene's).
std::vector<std::pair<std::string, std::string>> parse_configs(const std::string& text);

int run_converge(const ConvergeSettings& settings);

}  // namespace penumbra::cli
