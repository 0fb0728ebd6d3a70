// pbrt-v4's 2D texture mappings, for texture plugins: they turn a TextureEvalContext into texture
// coordinates (s, t) and their change from one pixel to the next.
//
//   "uv"          s = uscale u + udelta, t = vscale v + vdelta
//   "spherical"   around the texture space origin: s = theta / pi, t = phi / 2pi (z is the pole;
//                 pbrt-v4's order, s along the meridians)
//   "cylindrical" around texture space z: s = (pi + atan2(y, x)) / 2pi, t = z
//   "planar"      s = udelta + (p . v1), t = vdelta + (p . v2)
//
// Texture space is the space of the Texture directive (its current transform maps it to the world).
// A texture plugin lists the mapping's parameters in its table with PENUMBRA_TEXTURE_MAPPING_PARAMS
// and builds the mapping with TextureMapping2D::create(ctx).
#pragma once

#include <penumbra/math.h>
#include <penumbra/texture.h>

namespace penumbra {

struct CreateContext;

struct TexCoord2D {
  Vec2 st{0.f};
  float dsdx = 0.f, dsdy = 0.f, dtdx = 0.f, dtdy = 0.f;
};

class TextureMapping2D {
 public:
  enum class Kind { Uv, Spherical, Cylindrical, Planar };

  /// From the parameters "mapping", "uscale", "vscale", "udelta", "vdelta", "v1", "v2" and the
  /// directive's transform; an unknown mapping is an error at its parameter.
  static TextureMapping2D create(const CreateContext& ctx);
  /// The uv mapping with the given scales and offsets.
  static TextureMapping2D uv(float su = 1.f, float sv = 1.f, float du = 0.f, float dv = 0.f);

  TexCoord2D map(const TextureEvalContext& ctx) const;
  Kind kind() const { return kind_; }

 private:
  Kind kind_ = Kind::Uv;
  float su_ = 1.f, sv_ = 1.f, du_ = 0.f, dv_ = 0.f;
  Mat4 texture_from_world_{1.f};
  Vec3 vs_{1.f, 0.f, 0.f}, vt_{0.f, 1.f, 0.f};
};

}  // namespace penumbra

/// The mapping's entries of a texture plugin's parameter table.
#define PENUMBRA_TEXTURE_MAPPING_PARAMS                                                              \
  {"string", "mapping", "uv", "uv, spherical, cylindrical or planar"},                               \
      {"float", "uscale", "1", "uv mapping: scale of u"},                                            \
      {"float", "vscale", "1", "uv mapping: scale of v"},                                            \
      {"float", "udelta", "0", "uv and planar mappings: offset of s"},                               \
      {"float", "vdelta", "0", "uv and planar mappings: offset of t"},                               \
      {"vector3", "v1", "1 0 0", "planar mapping: s axis (texture space)"},                          \
      {"vector3", "v2", "0 1 0", "planar mapping: t axis (texture space)"}
