// pbrt-v4's spherical camera: every film point is a direction from the camera's position, by the
// equal-area octahedral map of the film's unit square (the default, "string mapping" "equalarea":
// each pixel of a square film sees the same solid angle) or by latitude-longitude
// ("equirectangular": x is the azimuth, y the polar angle from camera-space +y). As in pbrt-v4 the
// direction's y and z are swapped, so the camera's up (+y) is the map's pole. Light paths cannot
// connect to it (pbrt-v4 has no importance for it either): the Camera defaults stay.
#pragma once

#include <penumbra/camera.h>
#include <penumbra/params.h>

#include <span>

namespace penumbra {

class SphericalCamera final : public Camera {
 public:
  enum class Mapping { EqualArea, Equirectangular };
  /// `loc`: the Camera directive (errors that no parameter explains point at it).
  SphericalCamera(const ParamSet& params, const Mat4& camera_to_world, Point2i resolution, const FileLoc& loc);
  Point2i resolution() const override { return resolution_; }
  std::optional<Ray> generate_ray(const CameraSample& s) const override;
  /// Camera-space direction of a point of the film's unit square.
  Vec3 direction(Vec2 uv) const;
  void approximate_dp_dxy(const Vec3& p, const Vec3& n, Vec3* dpdx, Vec3* dpdy) const override;

 private:
  Mat4 to_world_;
  Vec3 origin_;
  Point2i resolution_;
  Mapping mapping_;
  float pixel_angle_;  // the smallest angle between neighbouring pixels' directions (radians)
};

std::span<const ParamSpec> spherical_camera_params();

}  // namespace penumbra
