// The command-line program's subcommands.
#pragma once

#include "render/render_session.h"

namespace penumbra::cli {

/// Renders and writes outputs; returns the exit status.
int run_render(const RenderSettings& settings);
/// Lists every plugin on the search path with its parameters; returns the exit status.
int run_plugins(const std::vector<std::string>& dirs);
/// Merges the parts of a split render into `output`; returns the exit status.
int run_merge(const std::vector<std::string>& parts, const std::string& output);
/// The bundled Cornell box: installed copy first, then the source tree.
std::string default_scene();

}  // namespace penumbra::cli
