// pbrt-v4's orthographic camera: parallel rays along camera-space +z, starting on the z = 0 plane at
// the screen-window point of the film position (raster (0,0) at the top-left, +y up). The screen
// window defaults to [-aspect, aspect] x [-1, 1] (or [-1, 1] x [-1/aspect, 1/aspect] for portrait
// images) with aspect = frameaspectratio or the film's; "screenwindow" sets it directly.
// Its rays are a delta in direction, so light paths cannot connect to it: it keeps the Camera
// defaults for importance (We = 0, no sample_wi), which removes bidirectional t = 1 strategies.
#pragma once

#include <penumbra/camera.h>
#include <penumbra/params.h>

#include <span>

namespace penumbra {

class OrthographicCamera final : public Camera {
 public:
  /// Parameters: see orthographic_camera_params().
  OrthographicCamera(const ParamSet& params, const Mat4& camera_to_world, Point2i resolution);
  Point2i resolution() const override { return resolution_; }
  std::optional<Ray> generate_ray(const CameraSample& s) const override;

 private:
  Mat4 to_world_;
  Point2i resolution_;
  Vec2 screen_min_, screen_max_;
};

std::span<const ParamSpec> orthographic_camera_params();

}  // namespace penumbra
