// The command-line program's subcommands.
#pragma once

#include "render/render_session.h"

namespace penumbra::cli {

/// Renders and writes outputs; returns the exit status.
int run_render(const RenderSettings& settings);
/// Lists every plugin on the search path with its parameters; returns the exit status.
int run_plugins(const std::vector<std::string>& dirs);
/// The bundled Cornell box: installed copy first, then the source tree.
std::string default_scene();

}  // namespace penumbra::cli
