#include "scene/spherical_camera.h"

#include <penumbra/equal_area.h>
#include <penumbra/error.h>
#include <penumbra/interaction.h>

#include <fmt/core.h>

#include <cmath>

namespace penumbra {

static const ParamSpec kParams[] = {
    {"string", "mapping", "equalarea", "film to directions: equalarea (pbrt-v4's default) or equirectangular"},
    {"float", "frameaspectratio", "", "accepted as pbrt-v4 does (no effect: the whole film maps to the sphere)"},
    {"float[]", "screenwindow", "", "accepted as pbrt-v4 does (no effect: the whole film maps to the sphere)"},
    {"unsupported", "lensradius", "", "a spherical camera has no lens"},
    {"unsupported", "focaldistance", "", "a spherical camera has no lens"},
    {"unsupported", "shutteropen", "", "Penumbra renders no motion blur"},
    {"unsupported", "shutterclose", "", "Penumbra renders no motion blur"},
};

std::span<const ParamSpec> spherical_camera_params() { return kParams; }

SphericalCamera::SphericalCamera(const ParamSet& params, const Mat4& camera_to_world, Point2i resolution,
                                 const FileLoc& loc)
    : to_world_(camera_to_world), origin_(Vec3(camera_to_world * Vec4(0.f, 0.f, 0.f, 1.f))), resolution_(resolution) {
  std::string m = params.get_string("mapping");
  if (m == "equalarea") {
    mapping_ = Mapping::EqualArea;
    if (resolution.x != resolution.y)
      throw Error(params.has("mapping") ? params.loc_of("mapping") : loc,
                  fmt::format("the equal-area spherical camera needs a square film, not {}x{} (pbrt-v4 refuses it "
                              "too); use \"string mapping\" \"equirectangular\" for a 2:1 film",
                              resolution.x, resolution.y));
    pixel_angle_ = std::sqrt(4.f * Pi / (float(resolution.x) * float(resolution.y)));
  } else if (m == "equirectangular") {
    mapping_ = Mapping::Equirectangular;
    pixel_angle_ = std::min(Pi / resolution.y, 2.f * Pi / resolution.x);
  } else {
    throw Error(params.loc_of("mapping"), fmt::format("unknown mapping '{}'; available: equalarea, equirectangular", m));
  }
}

Vec3 SphericalCamera::direction(Vec2 uv) const {
  Vec3 d;
  if (mapping_ == Mapping::Equirectangular) {
    float theta = Pi * uv.y, phi = 2.f * Pi * uv.x;
    d = Vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
  } else {
    d = equal_area_square_to_sphere(wrap_equal_area_square(uv));
  }
  return Vec3(d.x, d.z, d.y);
}

std::optional<Ray> SphericalCamera::generate_ray(const CameraSample& s) const {
  Vec2 uv(s.p_film.x / resolution_.x, s.p_film.y / resolution_.y);
  Vec3 d = glm::normalize(Vec3(to_world_ * Vec4(direction(uv), 0.f)));
  return Ray{origin_, d, Infinity};
}

// Rays one pixel angle apart in two directions across the view ray, met with p's tangent plane.
void SphericalCamera::approximate_dp_dxy(const Vec3& p, const Vec3& n, Vec3* dpdx, Vec3* dpdy) const {
  Vec3 to_p = p - origin_;
  float distance = glm::length(to_p);
  *dpdx = *dpdy = Vec3(0.f);
  if (!(distance > 0.f)) return;
  Vec3 w = to_p / distance;
  Frame f(w);
  auto offset = [&](const Vec3& t) {
    Vec3 d = w + pixel_angle_ * t;
    float denom = glm::dot(d, n);
    if (std::abs(denom) < 1e-6f) return Vec3(0.f);
    return origin_ + (glm::dot(to_p, n) / denom) * d - p;
  };
  *dpdx = offset(f.to_world(Vec3(1.f, 0.f, 0.f)));
  *dpdy = offset(f.to_world(Vec3(0.f, 1.f, 0.f)));
}

}  // namespace penumbra
