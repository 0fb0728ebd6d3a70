// pbrt's perspective camera: pinhole or thin lens, fov along the shorter image axis, raster (0,0)
// at the top-left, camera space looking down +z with +y up. Importance follows pbrt-v3: the camera
// transform is assumed rigid (a mirror such as pbrt's `Scale -1 1 1` is fine), so camera-space
// directions keep their lengths and solid angles.
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
  Rgb We(const Ray& ray, Vec2* p_raster = nullptr) const override;
  void pdf_we(const Ray& ray, float* pdf_pos, float* pdf_dir) const override;
  std::optional<CameraWiSample> sample_wi(const Vec3& p_ref, Vec2 u) const override;
  bool connectible() const override { return true; }
  void approximate_dp_dxy(const Vec3& p, const Vec3& n, Vec3* dpdx, Vec3* dpdy) const override;

 private:
  /// Raster position of the camera-space ray (o, unit d), through the plane in focus; false when it
  /// misses the film. `cos_theta` receives d.z.
  bool raster_of(const Vec3& o, const Vec3& d, Vec2* p_raster, float* cos_theta) const;

  Mat4 to_world_, from_world_;
  Point2i resolution_;
  Vec2 screen_min_, screen_max_;
  float tan_half_fov_;
  float lens_radius_, focal_distance_;
  float film_area_ = 1.f;  // area of the film's image on the z = 1 plane of camera space
  float lens_area_ = 1.f;  // 1 for a pinhole, so that its position density is a unit delta
  Vec2 pixel_spread_{0.f};  // camera-space size of one pixel on the z = 1 plane (x and y)
};

std::span<const ParamSpec> perspective_camera_params();

}  // namespace penumbra
