#include "scene/media.h"

#include <penumbra/error.h>

#include <fmt/core.h>

#include <limits>

namespace penumbra {

namespace {

// pbrt-v4's homogeneous medium, with its defaults (sigma_a = sigma_s = 1 per unit length).
const ParamSpec kHomogeneousParams[] = {
    {"rgb", "sigma_a", "1 1 1", "absorption coefficient per unit length (times scale)"},
    {"rgb", "sigma_s", "1 1 1", "scattering coefficient: must be 0 (scattering media are not simulated yet)"},
    {"float", "scale", "1", "multiplies sigma_a and sigma_s"},
    {"float", "g", "0", "Henyey-Greenstein asymmetry (no effect without scattering)"},
    {"rgb", "Le", "0 0 0", "emission: must be 0 (emissive media are not simulated yet)"},
    {"float", "Lescale", "1", "multiplies Le"},
    {"unsupported", "preset", "", "named scattering presets are not supported (they scatter)"},
};

}  // namespace

MediaTable::MediaTable(SceneDescription& desc) : desc_(desc) {
  if (!desc.camera_medium.empty())
    throw Error(desc.camera_medium_loc,
                fmt::format("the camera is inside medium '{}': Penumbra simulates media only inside closed "
                            "surfaces whose MediumInterface bounds them, not around the camera",
                            desc.camera_medium));
}

int MediaTable::resolve(const std::string& name, const FileLoc& loc) {
  if (name.empty()) return -1;
  if (auto it = index_.find(name); it != index_.end()) return it->second;
  auto named = desc_.named_media.find(name);
  if (named == desc_.named_media.end())
    throw Error(loc, fmt::format("MediumInterface names medium '{}', which no MakeNamedMedium defines", name));
  MediumEntity& m = desc_.media[named->second];
  if (m.type != "homogeneous")
    throw Error(m.loc, fmt::format("medium type '{}' is not supported: Penumbra simulates \"homogeneous\" media "
                                   "that absorb without scattering",
                                   m.type));
  m.params.validate(kHomogeneousParams, fmt::format("medium '{}'", name));
  float scale = m.params.get_float("scale");
  if (!(scale >= 0.f) || !std::isfinite(scale)) throw Error(m.params.loc_of("scale"), "scale must be >= 0");
  Rgb sigma_a = scale * m.params.get_rgb("sigma_a"), sigma_s = scale * m.params.get_rgb("sigma_s");
  auto valid = [](Rgb c) { return c.r >= 0.f && c.g >= 0.f && c.b >= 0.f && std::isfinite(c.r + c.g + c.b); };
  if (!valid(sigma_a)) throw Error(m.params.loc_of("sigma_a"), "sigma_a must be finite and >= 0");
  if (!is_black(sigma_s))
    throw Error(m.params.has("sigma_s") ? m.params.loc_of("sigma_s") : m.loc,
                fmt::format("medium '{}' scatters (sigma_s {} {} {}{}): Penumbra simulates media that only "
                            "absorb; give \"rgb sigma_s\" [0 0 0]",
                            name, sigma_s.r, sigma_s.g, sigma_s.b, m.params.has("sigma_s") ? "" : ", pbrt-v4's default"));
  if (!is_black(m.params.get_float("Lescale") * m.params.get_rgb("Le")))
    throw Error(m.params.loc_of("Le"), fmt::format("medium '{}' emits: emissive media are not simulated yet", name));
  if (sigma_a_.size() >= size_t(std::numeric_limits<int16_t>::max()))
    throw Error(m.loc, "too many media");
  sigma_a_.push_back(sigma_a);
  index_[name] = static_cast<int>(sigma_a_.size()) - 1;
  return index_[name];
}

MediumInterface MediaTable::interface_of(const ShapeEntity& s) {
  MediumInterface mi;
  mi.inside = static_cast<int16_t>(resolve(s.medium_inside, s.medium_loc));
  mi.outside = static_cast<int16_t>(resolve(s.medium_outside, s.medium_loc));
  return mi;
}

}  // namespace penumbra
