#include "scene/surface_params.h"

#include <penumbra/plugin.h>

#include <fmt/core.h>

#include <filesystem>

namespace penumbra {

SurfaceDetail take_surface_detail(ParamSet& params, const std::string& base_dir, const TextureTable& textures) {
  SurfaceDetail detail;
  const Param* disp = params.find("displacement");
  const Param* nmap = params.find("normalmap");
  if (!disp && !nmap) return detail;
  ParamSet own, rest;
  for (const Param& p : params.params()) (p.name == "displacement" || p.name == "normalmap" ? own : rest).add(p);
  if (disp) {
    const Param& p = *own.find("displacement");
    if (p.type != "texture" && p.type != "float")
      throw Error(p.loc, fmt::format("parameter 'displacement' must have type 'float' or 'texture', not '{}'", p.type));
    if (p.count() != 1) throw Error(p.loc, fmt::format("parameter 'displacement' takes 1 value, got {}", p.count()));
    CreateContext ctx{own, {}, base_dir};
    ctx.textures = &textures;
    detail.displacement = ctx.float_input("displacement");
    // A constant displacement moves a flat surface without tilting it; on a curved one pbrt-v4's
    // d dn/du terms scale dp/du and dp/dv alike, which leaves the normal as it is too.
    detail.bump = !detail.displacement.is_constant();
  }
  if (nmap) {
    const Param& p = *own.find("normalmap");
    if (p.type != "string")
      throw Error(p.loc, fmt::format("parameter 'normalmap' must have type 'string', not '{}'", p.type));
    if (p.strings.size() != 1) throw Error(p.loc, fmt::format("parameter 'normalmap' takes 1 value, got {}", p.count()));
    if (!p.strings[0].empty()) {
      std::filesystem::path file(p.strings[0]);
      if (!file.is_absolute() && !base_dir.empty()) file = std::filesystem::path(base_dir) / file;
      detail.normal_map = load_normal_map(file.string(), p.loc);
    }
  }
  params = std::move(rest);
  return detail;
}

AlphaCutout shape_alpha(const ParamSet& params, const std::string& base_dir, const TextureTable& textures) {
  AlphaCutout cut;
  const Param* p = params.find("alpha");
  if (!p) return cut;
  CreateContext ctx{params, {}, base_dir};
  ctx.textures = &textures;
  cut.alpha = ctx.float_input("alpha");
  if (cut.alpha.is_constant()) {
    float a = cut.alpha.constant();
    if (!(a >= 0.f && a <= 1.f)) throw Error(p->loc, fmt::format("alpha must be in [0, 1], got {}", a));
  }
  return cut;
}

}  // namespace penumbra
