#include "spectra/named_spectra.h"

#include <penumbra/params.h>

#include <algorithm>
#include <cstring>

namespace penumbra::spectra {

const TabulatedSpectrum* find_table(const std::string& name) {
  for (int i = 0; i < kNamedTableCount; ++i)
    if (name == kNamedTables[i].name) return &kNamedTables[i];
  return nullptr;
}

std::optional<Spectrum> named_spectrum(const std::string& name) {
  const TabulatedSpectrum* t = find_table(name);
  if (!t) return std::nullopt;
  Spectrum s(std::vector<double>(t->lambda, t->lambda + t->count),
             std::vector<double>(t->value, t->value + t->count));
  if (name.rfind("stdillum-", 0) == 0) {
    glm::dvec3 xyz = spectrum_to_xyz(s, false);
    double y_integral = spectrum_to_xyz(Spectrum({kLambdaMin, kLambdaMax}, {1.0, 1.0}), false).y;
    s = s.scaled(y_integral / xyz.y);
  }
  return s;
}

std::vector<std::string> named_spectrum_names() {
  std::vector<std::string> names;
  for (int i = 0; i < kNamedTableCount; ++i) names.emplace_back(kNamedTables[i].name);
  std::sort(names.begin(), names.end());
  return names;
}

std::vector<std::string> closest_spectrum_names(const std::string& name, size_t max) {
  std::vector<std::pair<size_t, std::string>> scored;
  for (const auto& n : named_spectrum_names()) scored.emplace_back(edit_distance(name, n), n);
  std::stable_sort(scored.begin(), scored.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::string> out;
  for (size_t i = 0; i < scored.size() && i < max; ++i) out.push_back(scored[i].second);
  return out;
}

}  // namespace penumbra::spectra
