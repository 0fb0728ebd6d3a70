#include "texture/texture_table.h"

#include <penumbra/plugin.h>

#include <fmt/core.h>

namespace penumbra {

void TextureTable::declare(const std::string& name, bool spectrum, const FileLoc& loc) {
  declared_[{name, spectrum}] = Declared{spectrum, loc};
}

const FloatTexture* TextureTable::find_float(const std::string& name) const {
  auto it = floats_.find(name);
  return it == floats_.end() ? nullptr : it->second;
}

const SpectrumTexture* TextureTable::find_spectrum(const std::string& name) const {
  auto it = spectra_.find(name);
  return it == spectra_.end() ? nullptr : it->second;
}

const TextureTable::Declared* TextureTable::declared(const std::string& name, bool spectrum) const {
  auto it = declared_.find({name, spectrum});
  return it == declared_.end() ? nullptr : &it->second;
}

namespace {

const char* kind_name(bool spectrum) { return spectrum ? "spectrum" : "float"; }

// Why `texture` cannot be used as a texture of kind `spectrum` for parameter `param`.
[[noreturn]] void missing_texture(const TextureTable* table, const Param& p, bool spectrum) {
  const std::string& name = p.strings[0];
  if (table) {
    if (const auto* d = table->declared(name, spectrum))
      throw Error(p.loc, fmt::format("{} texture '{}' is defined later (at {}); a texture must be defined "
                                     "before it is used",
                                     kind_name(spectrum), name, d->loc.str()));
    if (const auto* d = table->declared(name, !spectrum))
      throw Error(p.loc, fmt::format("parameter '{}' needs a {} texture, but '{}' is a {} texture (defined at {})",
                                     p.name, kind_name(spectrum), name, kind_name(!spectrum), d->loc.str()));
  }
  throw Error(p.loc, fmt::format("{} texture '{}' is not defined", kind_name(spectrum), name));
}

}  // namespace

TexturedFloat CreateContext::float_input(const std::string& name) const {
  const Param* p = params.find(name);
  if (p && p->type == "texture") {
    const FloatTexture* t = textures ? textures->find_float(p->strings[0]) : nullptr;
    if (!t) missing_texture(textures, *p, false);
    return TexturedFloat(t);
  }
  if (p && p->type != "float")
    throw Error(p->loc, fmt::format("parameter '{}' needs a float or a float texture, not '{}'", name, p->type));
  return TexturedFloat(params.get_float(name));
}

TexturedRgb CreateContext::rgb_input(const std::string& name, RgbKind kind) const {
  const Param* p = params.find(name);
  if (p && p->type == "texture") {
    const SpectrumTexture* t = textures ? textures->find_spectrum(p->strings[0]) : nullptr;
    if (!t) missing_texture(textures, *p, true);
    return TexturedRgb(t, kind);
  }
  if (p && p->type != "rgb" && p->type != "spectrum")
    throw Error(p->loc, fmt::format("parameter '{}' needs an rgb value or a spectrum texture, not '{}'", name, p->type));
  // A one-number default ("1" in a texture plugin's table) stands for grey.
  std::vector<float> v = params.get_floats(name);
  if (v.size() == 1) return TexturedRgb(Rgb(v[0]), kind);
  return TexturedRgb(params.get_rgb(name), kind);
}

}  // namespace penumbra

namespace penumbra {

// Textures compute colours; the parameter that reads them turns the colour into a spectrum.
Rgb TexturedRgb::evaluate_spectral(const TextureEvalContext& ctx) const {
  Rgb rgb = value_;
  if (texture_) {
    TextureEvalContext rgb_ctx = ctx;
    rgb_ctx.wavelengths = nullptr;
    rgb = texture_->evaluate(rgb_ctx);
  }
  return kind_ == RgbKind::Albedo ? ctx.wavelengths->albedo(rgb) : ctx.wavelengths->unbounded(rgb);
}

}  // namespace penumbra
