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

}  // namespace penumbra
