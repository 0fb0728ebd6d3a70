// pbrt's perspective camera: pinhole or thin lens, fov along the shorter image axis, raster (0,0)
// at the top-left, camera space looking down +z with +y up.
#pragma once

#include <penumbra/camera.h>
#include <penumbra/params.h>

#include <span>

namespace penumbra {

class PerspectiveCamera final : public Camera {
 public:
  /// Parameters: see kPerspectiveCameraParams.
  PerspectiveCamera(const ParamSet& params, const Mat4& camera_to_world, Point2i resolution);
  Point2i resolution() const override { return resolution_; }
  std::optional<Ray> generate_ray(const CameraSample& s) const override;

 private:
  Mat4 to_world_;
  Point2i resolution_;
  Vec2 screen_min_, screen_max_;
  float tan_half_fov_;
  float lens_radius_, focal_distance_;
};

std::span<const ParamSpec> perspective_camera_params();

}  // namespace penumbra
