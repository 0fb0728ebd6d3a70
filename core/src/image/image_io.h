// Image files in and out through OpenImageIO. Float formats store the renderer's linear values as
// they are; 8-bit formats go through an OpenColorIO display view, because a PNG holds display code
// values, not radiance.
#pragma once

#include <penumbra/image.h>

#include <string>

namespace penumbra {

/// The OpenColorIO config used for 8-bit output: $OCIO when set, else the shipped config from
/// <exe dir>/../share/penumbra/ocio/config.ocio or, in a build tree, the source tree's data/ocio.
/// Throws Error listing the places it looked when there is none.
std::string ocio_config_path();

/// Loads and validates an OpenColorIO config file; throws Error naming it with OCIO's complaint.
void check_ocio_config(const std::string& path);

/// Why write_image() could not write `path`, or "" when it can, found out before anything is
/// rendered: an unknown or missing extension, a folder that is missing or refuses new files
/// (output_path_problem), or, for 8-bit formats, no usable OpenColorIO config.
std::string image_output_problem(const std::string& path);

/// True for a .exr path (any case): the one format that holds AOV layers and split-render parts.
bool is_exr_path(const std::string& path);

}  // namespace penumbra
