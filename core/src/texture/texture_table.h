// The scene's named textures, filled by the scene builder in file order and handed to factories
// (CreateContext::textures) so that `"texture reflectance" "name"` finds its texture. Float and
// spectrum textures have separate names, as in pbrt-v4.
#pragma once

#include <penumbra/error.h>
#include <penumbra/texture.h>

#include <map>
#include <string>

namespace penumbra {

class TextureTable {
 public:
  struct Declared {
    bool spectrum = false;
    FileLoc loc;  // the Texture directive
  };
  /// Every Texture directive of the scene, before any is created (for "defined later" messages).
  void declare(const std::string& name, bool spectrum, const FileLoc& loc);
  void add(const std::string& name, const FloatTexture* t) { floats_[name] = t; }
  void add(const std::string& name, const SpectrumTexture* t) { spectra_[name] = t; }

  const FloatTexture* find_float(const std::string& name) const;
  const SpectrumTexture* find_spectrum(const std::string& name) const;
  /// The directive declaring `name` as the given kind, or null.
  const Declared* declared(const std::string& name, bool spectrum) const;

 private:
  std::map<std::string, const FloatTexture*> floats_;
  std::map<std::string, const SpectrumTexture*> spectra_;
  std::map<std::pair<std::string, bool>, Declared> declared_;
};

}  // namespace penumbra
