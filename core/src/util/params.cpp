#include <penumbra/params.h>

#include <fmt/core.h>

#include <algorithm>
#include <sstream>

namespace penumbra {

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

void ParamSet::add(Param p) {
  if (const Param* old = find(p.name))
    throw Error(p.loc, fmt::format("parameter '{}' given twice (first at {})", p.name, old->loc.str()));
  params_.push_back(std::move(p));
}

static Param* find_in(std::vector<Param>& v, const std::string& name) {
  for (auto& p : v)
    if (p.name == name) return &p;
  return nullptr;
}

void ParamSet::set_int(const std::string& name, int v) {
  Param* p = find_in(params_, name);
  if (!p) { params_.push_back(Param{"integer", name, {}, {}, {}, {}}); p = &params_.back(); }
  p->type = "integer";
  p->numbers = {static_cast<double>(v)};
}

void ParamSet::set_bool(const std::string& name, bool v) {
  Param* p = find_in(params_, name);
  if (!p) { params_.push_back(Param{"bool", name, {}, {}, {}, {}}); p = &params_.back(); }
  p->type = "bool";
  p->numbers.clear();
  p->strings.clear();
  p->bools = {v};
}

void ParamSet::set_string(const std::string& name, const std::string& v) {
  Param* p = find_in(params_, name);
  if (!p) { params_.push_back(Param{"string", name, {}, {}, {}, {}}); p = &params_.back(); }
  p->type = "string";
  p->strings = {v};
}

const Param* ParamSet::find(const std::string& name) const {
  for (const auto& p : params_)
    if (p.name == name) return &p;
  return nullptr;
}

// Base type of a spec type ("point3[]" -> "point3") and whether it takes an array.
static std::pair<std::string, bool> spec_base(const std::string& type) {
  if (type.size() > 2 && type.compare(type.size() - 2, 2, "[]") == 0)
    return {type.substr(0, type.size() - 2), true};
  return {type, false};
}

// Texturable spec types: "float texture" (a float or a float texture's name), "rgb texture" (a colour
// or a spectrum texture's name) and "texture" (texture plugins' inputs, of the directive's kind).
static bool is_texturable(const std::string& spec) {
  return spec == "float texture" || spec == "rgb texture" || spec == "texture";
}

// Scene-file types a spec type accepts (pbrt-v4 spellings and synonyms).
static bool type_accepts(const std::string& spec, const std::string& given) {
  if (spec == given) return true;
  // Spectra and blackbodies reach plugins as RGB (parser/spectrum_params.cpp converts them).
  if (spec == "float texture") return given == "float" || given == "texture";
  if (spec == "rgb texture") return given == "rgb" || given == "spectrum" || given == "blackbody" || given == "texture";
  if (spec == "texture") return given == "float" || given == "rgb" || given == "spectrum";
  if (spec == "rgb") return given == "spectrum" || given == "blackbody";
  if (spec == "float|spectrum")
    return given == "float" || given == "spectrum" || given == "blackbody" || given == "rgb";
  if (spec == "point3") return given == "point";
  if (spec == "vector3") return given == "vector";
  if (spec == "normal") return given == "normal3";
  if (spec == "point2") return given == "vector2";
  return false;
}

static int components(const std::string& base) {
  // A blackbody has been converted to RGB by the time parameters are checked.
  if (base == "rgb" || base == "spectrum" || base == "blackbody" || base == "point3" || base == "vector3" ||
      base == "normal")
    return 3;
  if (base == "point2" || base == "vector2") return 2;
  return 1;
}

// Parses a spec default ("0.5 0.5 0.5", "true", "box") into a Param of the spec's type.
static Param parse_default(const ParamSpec& s) {
  auto [base, array] = spec_base(s.type);
  Param p{base, s.name, {}, {}, {}, {}};
  std::istringstream in(s.default_value ? s.default_value : "");
  if (base == "string") {
    p.strings.push_back(s.default_value ? s.default_value : "");
  } else if (base == "bool") {
    std::string w;
    while (in >> w) p.bools.push_back(w == "true");
  } else {
    double x;
    while (in >> x) p.numbers.push_back(x);
  }
  return p;
}

void ParamSet::validate(std::span<const ParamSpec> spec, const std::string& what) {
  defaults_.clear();
  for (const auto& s : spec)
    if (s.default_value && *s.default_value && std::string(s.type) != "unsupported")
      defaults_.push_back(parse_default(s));
  auto known = [&](const Param& p) {
    return std::any_of(spec.begin(), spec.end(), [&](const ParamSpec& s) { return p.name == s.name; });
  };
  std::erase_if(params_, [&](const Param& p) { return p.from_attribute && !known(p); });
  for (const auto& p : params_) {
    const ParamSpec* match = nullptr;
    for (const auto& s : spec)
      if (p.name == s.name) match = &s;
    if (!match) {
      std::string best;
      size_t best_d = SIZE_MAX;
      for (const auto& s : spec) {
        size_t d = edit_distance(p.name, s.name);
        if (d < best_d) { best_d = d; best = s.name; }
      }
      std::string hint;
      if (!best.empty() && best_d <= std::max<size_t>(2, p.name.size() / 3))
        hint = fmt::format("; did you mean '{}'?", best);
      throw Error(p.loc, fmt::format("unknown parameter '{}' for {}{}", p.name, what, hint));
    }
    if (std::string(match->type) == "unsupported")
      throw Error(p.loc, fmt::format("parameter '{}' of {} is not supported by Penumbra{}{}", p.name,
                                     what, *match->doc ? ": " : "", match->doc));
    auto [base, array] = spec_base(match->type);
    if (!type_accepts(base, p.type))
      throw Error(p.loc, fmt::format("parameter '{}' of {} must have type '{}', not '{}'", p.name, what,
                                     base == "float texture" ? "float' or 'texture"
                                     : base == "rgb texture"  ? "rgb' or 'texture"
                                     : base == "float|spectrum" ? "float' or 'spectrum"
                                                                : base,
                                     p.type));
    // A texturable parameter takes as many values as the type it was given with.
    size_t n = p.count(), k = static_cast<size_t>(components(is_texturable(base) ? p.type : base));
    if (base == "float|spectrum" && p.type != "float") k = 3;
    if (!array && n != k)
      throw Error(p.loc, fmt::format("parameter '{}' of {} takes {} value{}, got {}", p.name, what, k,
                                     k == 1 ? "" : "s", n));
    if (array && (n == 0 || n % k != 0))
      throw Error(p.loc, fmt::format("parameter '{}' of {} needs a multiple of {} values, got {}",
                                     p.name, what, k, n));
    if (base == "integer")
      for (double v : p.numbers)
        if (v != static_cast<double>(static_cast<long long>(v)))
          throw Error(p.loc, fmt::format("parameter '{}' of {} must be an integer, got {}", p.name,
                                         what, v));
  }
}

const Param* ParamSet::find_or_default(const std::string& name) const {
  if (const Param* p = find(name)) return p;
  for (const auto& d : defaults_)
    if (d.name == name) return &d;
  return nullptr;
}

int ParamSet::get_int(const std::string& name, int fallback) const {
  const Param* p = find_or_default(name);
  return p && !p->numbers.empty() ? static_cast<int>(p->numbers[0]) : fallback;
}
float ParamSet::get_float(const std::string& name, float fallback) const {
  const Param* p = find_or_default(name);
  if (p && p->type != "float" && p->numbers.size() == 3)  // a "float|spectrum" given as a spectrum
    return luminance(Rgb(p->numbers[0], p->numbers[1], p->numbers[2]));
  return p && !p->numbers.empty() ? static_cast<float>(p->numbers[0]) : fallback;
}
bool ParamSet::get_bool(const std::string& name, bool fallback) const {
  const Param* p = find_or_default(name);
  return p && !p->bools.empty() ? p->bools[0] : fallback;
}
std::string ParamSet::get_string(const std::string& name, const std::string& fallback) const {
  const Param* p = find_or_default(name);
  return p && !p->strings.empty() ? p->strings[0] : fallback;
}
Rgb ParamSet::get_rgb(const std::string& name, Rgb fallback) const {
  const Param* p = find_or_default(name);
  if (!p || p->numbers.size() < 3) return fallback;
  return Rgb(p->numbers[0], p->numbers[1], p->numbers[2]);
}
Vec3 ParamSet::get_point3(const std::string& name, Vec3 fallback) const {
  const Param* p = find_or_default(name);
  if (!p || p->numbers.size() < 3) return fallback;
  return Vec3(p->numbers[0], p->numbers[1], p->numbers[2]);
}
std::vector<int> ParamSet::get_ints(const std::string& name) const {
  std::vector<int> out;
  if (const Param* p = find_or_default(name))
    for (double v : p->numbers) out.push_back(static_cast<int>(v));
  return out;
}
std::vector<float> ParamSet::get_floats(const std::string& name) const {
  std::vector<float> out;
  if (const Param* p = find_or_default(name))
    for (double v : p->numbers) out.push_back(static_cast<float>(v));
  return out;
}
std::vector<Vec2> ParamSet::get_point2s(const std::string& name) const {
  std::vector<Vec2> out;
  if (const Param* p = find_or_default(name))
    for (size_t i = 0; i + 1 < p->numbers.size(); i += 2)
      out.emplace_back(p->numbers[i], p->numbers[i + 1]);
  return out;
}
std::vector<Vec3> ParamSet::get_point3s(const std::string& name) const {
  std::vector<Vec3> out;
  if (const Param* p = find_or_default(name))
    for (size_t i = 0; i + 2 < p->numbers.size(); i += 3)
      out.emplace_back(p->numbers[i], p->numbers[i + 1], p->numbers[i + 2]);
  return out;
}
FileLoc ParamSet::loc_of(const std::string& name) const {
  const Param* p = find(name);
  return p ? p->loc : FileLoc{};
}

}  // namespace penumbra
