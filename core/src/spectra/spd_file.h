// Spectrum files (.spd) as pbrt-v4 reads them: whitespace-separated numbers, '#' starts a comment
// to the end of the line, read as (lambda in nm, value) pairs with increasing wavelengths.
#pragma once

#include <penumbra/error.h>

#include <string>

#include "spectra/spectrum.h"

namespace penumbra::spectra {

/// Reads `path`; errors (missing file, a word that is not a number, an odd count, wavelengths that
/// do not increase) are thrown at `loc`, naming the file and the offending line.
Spectrum read_spd_file(const std::string& path, const FileLoc& loc);

}  // namespace penumbra::spectra
