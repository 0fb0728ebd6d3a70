#include "parser/spectrum_params.h"

#include <fmt/core.h>

#include <filesystem>

#include "spectra/named_spectra.h"
#include "spectra/spd_file.h"

namespace penumbra {

namespace {

namespace fs = std::filesystem;
using spectra::Spectrum;

std::string quoted_list(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "'" : ", '") + n + "'";
  return s;
}

Spectrum spectrum_from_string(const Param& p, const std::string& base_dir) {
  const std::string& text = p.strings[0];
  if (auto named = spectra::named_spectrum(text)) return *named;
  fs::path path(text);
  if (path.is_relative()) path = fs::path(base_dir) / path;
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) return spectra::read_spd_file(path.string(), p.loc);
  throw Error(p.loc, fmt::format("unknown spectrum '{}' for parameter '{}': not one of pbrt-v4's named spectra, "
                                 "and no spectrum file '{}'; closest names: {}",
                                 text, p.name, path.string(), quoted_list(spectra::closest_spectrum_names(text))));
}

Spectrum spectrum_from_pairs(const Param& p) {
  const auto& v = p.numbers;
  if (v.size() < 4 || v.size() % 2 != 0)
    throw Error(p.loc, fmt::format("spectrum '{}' takes 3 RGB values or at least two (wavelength, value) pairs, "
                                   "got {} value{}",
                                   p.name, v.size(), v.size() == 1 ? "" : "s"));
  std::vector<double> lambda, value;
  for (size_t i = 0; i < v.size(); i += 2) {
    if (!lambda.empty() && v[i] <= lambda.back())
      throw Error(p.loc, fmt::format("spectrum '{}': wavelengths must increase, but {} follows {}", p.name, v[i],
                                     lambda.back()));
    lambda.push_back(v[i]);
    value.push_back(v[i + 1]);
  }
  return Spectrum(std::move(lambda), std::move(value));
}

// The RGB of one spectrum or blackbody parameter; nullopt for 3 numbers (already RGB).
std::optional<Spectrum> spectrum_of(const Param& p, const std::string& base_dir) {
  if (p.type == "blackbody") {
    if (p.numbers.size() != 1)
      throw Error(p.loc, fmt::format("blackbody '{}' takes one temperature in kelvin, got {} values", p.name,
                                     p.numbers.size()));
    if (!(p.numbers[0] > 0.0))
      throw Error(p.loc, fmt::format("blackbody '{}' needs a temperature > 0 K, got {}", p.name, p.numbers[0]));
    return Spectrum::blackbody(p.numbers[0]);
  }
  if (!p.strings.empty()) {
    if (p.strings.size() != 1 || !p.numbers.empty())
      throw Error(p.loc, fmt::format("spectrum '{}' takes one spectrum name or file, or numbers", p.name));
    return spectrum_from_string(p, base_dir);
  }
  if (p.numbers.size() == 3) return std::nullopt;  // RGB (Penumbra's shorthand)
  return spectrum_from_pairs(p);
}

}  // namespace

SpectrumUse spectrum_use_of(const std::string& directive) {
  return directive == "LightSource" || directive == "AreaLightSource" ? SpectrumUse::Emission
                                                                       : SpectrumUse::Reflectance;
}

ParamSet resolve_spectra(const ParamSet& params, SpectrumUse use, const std::string& base_dir) {
  ParamSet out;
  for (Param p : params.params()) {
    if (p.type == "spectrum" || p.type == "blackbody") {
      if (std::optional<Spectrum> s = spectrum_of(p, base_dir)) {
        Rgb rgb = use == SpectrumUse::Emission ? spectra::emission_to_rgb(*s) : spectra::reflectance_to_rgb(*s);
        p.numbers = {rgb.r, rgb.g, rgb.b};
        p.strings.clear();
      }
    }
    out.add(std::move(p));
  }
  return out;
}

}  // namespace penumbra
