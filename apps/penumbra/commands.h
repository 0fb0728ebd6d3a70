// The command-line program's subcommands.
#pragma once

#include "render/render_session.h"

namespace penumbra::cli {

/// Exit status of a render ended early by SIGINT or SIGTERM that wrote its image (and checkpoint):
/// EX_TEMPFAIL, "try again" (a second signal exits with 128 + the signal's number instead).
inline constexpr int kExitInterrupted = 75;
/// Renders and writes outputs; returns the exit status.
int run_render(const RenderSettings& settings);
/// Lists every plugin on the search path with its parameters; returns the exit status.
int run_plugins(const std::vector<std::string>& dirs);
/// Merges the parts of a split render into `output`; returns the exit status.
int run_merge(const std::vector<std::string>& parts, const std::string& output);
/// The bundled Cornell box: installed copy first, then the source tree.
std::string default_scene();

}  // namespace penumbra::cli
