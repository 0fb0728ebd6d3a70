// Spectrum parameters become RGB when a scene is read: `"spectrum eta" "metal-Au-eta"`,
// `"spectrum reflectance" [400 0.2 700 0.8]`, `"spectrum L" "lamp.spd"` and `"blackbody L" [3000]`
// are each replaced by three numbers (linear Rec.709), so plugins only ever see RGB. The rules
// (reflectance-like under the reference white D65, emission at luminance 1) are in
// spectra/spectrum.h and docs/scene-format.md.
#pragma once

#include <penumbra/params.h>

#include <string>

namespace penumbra {

/// How a directive's spectra are meant: emission for LightSource and AreaLightSource, reflectance
/// (and other material or texture quantities: eta, k, ...) everywhere else.
enum class SpectrumUse { Reflectance, Emission };

/// The use of the spectra of directive `directive` ("LightSource", "Material", ...).
SpectrumUse spectrum_use_of(const std::string& directive);

/// `params` with every "spectrum" and "blackbody" parameter converted to RGB (its type stays as
/// written). Spectrum files are relative to `base_dir`. Throws Error at the parameter: an unknown
/// spectrum name (with the closest names), a bad value count, a missing or malformed file.
ParamSet resolve_spectra(const ParamSet& params, SpectrumUse use, const std::string& base_dir);

}  // namespace penumbra
