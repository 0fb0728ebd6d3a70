#include "spectra/spd_file.h"

#include <fmt/core.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

namespace penumbra::spectra {

Spectrum read_spd_file(const std::string& path, const FileLoc& loc) {
  std::ifstream in(path);
  if (!in) throw Error(loc, fmt::format("cannot open spectrum file '{}'", path));
  std::vector<double> numbers;
  std::vector<int> lines;  // source line of each number
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    for (std::string w; words >> w;) {
      char* end = nullptr;
      double v = std::strtod(w.c_str(), &end);
      if (end == w.c_str() || *end != '\0')
        throw Error(loc, fmt::format("spectrum file '{}', line {}: '{}' is not a number", path, line_no, w));
      numbers.push_back(v);
      lines.push_back(line_no);
    }
  }
  if (numbers.size() < 2 || numbers.size() % 2 != 0)
    throw Error(loc, fmt::format("spectrum file '{}' must hold (wavelength, value) pairs, got {} number{}", path,
                                 numbers.size(), numbers.size() == 1 ? "" : "s"));
  std::vector<double> lambda, value;
  for (size_t i = 0; i < numbers.size(); i += 2) {
    if (!lambda.empty() && numbers[i] <= lambda.back())
      throw Error(loc, fmt::format("spectrum file '{}', line {}: wavelength {} does not increase (previous {})",
                                   path, lines[i], numbers[i], lambda.back()));
    lambda.push_back(numbers[i]);
    value.push_back(numbers[i + 1]);
  }
  return Spectrum(std::move(lambda), std::move(value));
}

}  // namespace penumbra::spectra
