// The participating media Penumbra simulates: pbrt-v4's MakeNamedMedium "homogeneous" media that
// absorb without scattering (coloured glass, liquids), each bounded by the surfaces whose
// MediumInterface names it on one side. Only media a shape or the camera uses are resolved; what
// cannot be simulated yet (scattering, emission, other medium types, a camera inside a medium) is an
// error at its directive or parameter.
#pragma once

#include <penumbra/color.h>
#include <penumbra/interaction.h>

#include <map>
#include <string>
#include <vector>

#include "parser/scene_description.h"

namespace penumbra {

class MediaTable {
 public:
  /// Checks the camera's medium (vacuum only, for now).
  explicit MediaTable(SceneDescription& desc);
  /// The interface of a shape, resolving (and checking) the media it names.
  MediumInterface interface_of(const ShapeEntity& s);
  /// Absorption coefficient (sigma_a times scale) of each resolved medium, by interface index.
  const std::vector<Rgb>& sigma_a() const { return sigma_a_; }

 private:
  int resolve(const std::string& name, const FileLoc& loc);
  SceneDescription& desc_;
  std::map<std::string, int> index_;  // medium name -> index into sigma_a_
  std::vector<Rgb> sigma_a_;
};

}  // namespace penumbra
