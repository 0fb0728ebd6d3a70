// One MIP pyramid per (file, encoding, wrap mode), built on first use and shared by every texture
// of the process that asks for the same: real scenes name one image in several textures.
#pragma once

#include "mipmap.h"

#include <penumbra/error.h>

#include <memory>
#include <string>

namespace imagemap {

/// How integer (8/16-bit) files are decoded to linear values; float files are linear already.
struct Encoding {
  enum class Kind { Srgb, Linear, Gamma } kind = Kind::Srgb;
  float gamma = 1.f;
};

/// Parses "sRGB", "linear" or "gamma G"; throws at `loc` otherwise.
Encoding parse_encoding(const std::string& text, const penumbra::FileLoc& loc);

/// The shared pyramid of `path`; read errors are reported at `loc`.
std::shared_ptr<const MipMap> load_mipmap(const std::string& path, const Encoding& encoding, WrapMode wrap,
                                          const penumbra::FileLoc& loc);

/// Pyramids built so far in this process (tests check that equal requests share one).
int mipmaps_built();

}  // namespace imagemap
