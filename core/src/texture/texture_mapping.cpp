#include <penumbra/plugin.h>
#include <penumbra/texture_mapping.h>

#include <fmt/core.h>

namespace penumbra {

TextureMapping2D TextureMapping2D::uv(float su, float sv, float du, float dv) {
  TextureMapping2D m;
  m.su_ = su, m.sv_ = sv, m.du_ = du, m.dv_ = dv;
  return m;
}

TextureMapping2D TextureMapping2D::create(const CreateContext& ctx) {
  const ParamSet& p = ctx.params;
  std::string kind = p.get_string("mapping", "uv");
  TextureMapping2D m;
  m.texture_from_world_ = glm::inverse(ctx.to_world);
  m.du_ = p.get_float("udelta", 0.f);
  m.dv_ = p.get_float("vdelta", 0.f);
  if (kind == "uv") {
    m.kind_ = Kind::Uv;
    m.su_ = p.get_float("uscale", 1.f);
    m.sv_ = p.get_float("vscale", 1.f);
  } else if (kind == "spherical") {
    m.kind_ = Kind::Spherical;
  } else if (kind == "cylindrical") {
    m.kind_ = Kind::Cylindrical;
  } else if (kind == "planar") {
    m.kind_ = Kind::Planar;
    m.vs_ = p.get_point3("v1", Vec3(1.f, 0.f, 0.f));
    m.vt_ = p.get_point3("v2", Vec3(0.f, 1.f, 0.f));
  } else {
    throw Error(p.loc_of("mapping"),
                fmt::format("unknown texture mapping '{}'; available: uv, spherical, cylindrical, planar", kind));
  }
  return m;
}

TexCoord2D TextureMapping2D::map(const TextureEvalContext& ctx) const {
  TexCoord2D c;
  if (kind_ == Kind::Uv) {
    c.st = Vec2(su_ * ctx.uv.x + du_, sv_ * ctx.uv.y + dv_);
    c.dsdx = su_ * ctx.dudx, c.dsdy = su_ * ctx.dudy;
    c.dtdx = sv_ * ctx.dvdx, c.dtdy = sv_ * ctx.dvdy;
    return c;
  }
  Vec3 p = Vec3(texture_from_world_ * Vec4(ctx.p, 1.f));
  Vec3 dpdx = Vec3(texture_from_world_ * Vec4(ctx.dpdx, 0.f));
  Vec3 dpdy = Vec3(texture_from_world_ * Vec4(ctx.dpdy, 0.f));
  // ds/dp and dt/dp: the footprint in (s, t) is their dot product with dp/dx and dp/dy.
  Vec3 dsdp(0.f), dtdp(0.f);
  float x2y2 = p.x * p.x + p.y * p.y;
  switch (kind_) {
    case Kind::Spherical: {
      // s = theta / pi with cos(theta) = z / |p|; t = phi / 2pi with phi = atan2(y, x) in [0, 2pi).
      float r2 = x2y2 + p.z * p.z;
      float rxy = std::sqrt(x2y2);
      if (r2 > 0.f && rxy > 0.f) {
        dsdp = Vec3(p.x * p.z / rxy, p.y * p.z / rxy, -rxy) / (Pi * r2);
        dtdp = Vec3(-p.y, p.x, 0.f) / (2.f * Pi * x2y2);
      }
      float len = std::sqrt(r2);
      float theta = len > 0.f ? std::acos(std::clamp(p.z / len, -1.f, 1.f)) : 0.f;
      float phi = std::atan2(p.y, p.x);
      if (phi < 0.f) phi += 2.f * Pi;
      c.st = Vec2(theta * InvPi, phi * Inv2Pi);
      break;
    }
    case Kind::Cylindrical:
      if (x2y2 > 0.f) dsdp = Vec3(-p.y, p.x, 0.f) / (2.f * Pi * x2y2);
      dtdp = Vec3(0.f, 0.f, 1.f);
      c.st = Vec2((Pi + std::atan2(p.y, p.x)) * Inv2Pi, p.z);
      break;
    case Kind::Planar:
      dsdp = vs_, dtdp = vt_;
      c.st = Vec2(du_ + glm::dot(p, vs_), dv_ + glm::dot(p, vt_));
      break;
    case Kind::Uv: break;
  }
  c.dsdx = glm::dot(dsdp, dpdx), c.dsdy = glm::dot(dsdp, dpdy);
  c.dtdx = glm::dot(dtdp, dpdx), c.dtdy = glm::dot(dtdp, dpdy);
  return c;
}

}  // namespace penumbra
