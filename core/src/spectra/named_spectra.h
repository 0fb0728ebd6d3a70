// pbrt-v4's named spectra ("metal-Au-eta", "glass-BK7", "stdillum-D65", ...), looked up by name.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "spectra/spectrum.h"
#include "spectra/spectrum_tables.h"

namespace penumbra::spectra {

/// The raw table of a named spectrum, or nullptr.
const TabulatedSpectrum* find_table(const std::string& name);

/// A named spectrum as pbrt-v4 defines it: the table, with the standard illuminants ("stdillum-*")
/// scaled to luminance 1 (integral S y / integral y = 1) as pbrt-v4 does. Empty if unknown.
std::optional<Spectrum> named_spectrum(const std::string& name);

/// Every name, sorted.
std::vector<std::string> named_spectrum_names();

/// Up to `max` names closest to `name` by edit distance (for "did you mean" messages).
std::vector<std::string> closest_spectrum_names(const std::string& name, size_t max = 3);

}  // namespace penumbra::spectra
