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
  /// Parameters: see kPerspectiveCameraParams. `filter_radius`: the film's pixel filter radius, in
  /// pixels. Camera rays leave the film rectangle by up to radius - 1/2 (the filter's samples around
  /// the border pixels), so importance (We, pdf_we, sample_wi) extends as far: a light path reaching
  /// the camera there splats onto the border pixels as their camera samples there count for them.
  PerspectiveCamera(const ParamSet& params, const Mat4& camera_to_world, Point2i resolution,
                    Vec2 filter_radius = Vec2(0.5f));
  Point2i resolution() const override { return resolution_; }
  std::optional<Ray> generate_ray(const CameraSample& s) const override;
  Rgb We(const Ray& ray, Vec2* p_raster = nullptr) const override;
  void pdf_we(const Ray& ray, float* pdf_pos, float* pdf_dir) const override;
  std::optional<CameraWiSample> sample_wi(const Vec3& p_ref, Vec2 u) const override;
  bool connectible() const override { return true; }
  void approximate_dp_dxy(const Vec3& p, const Vec3& n, Vec3* dpdx, Vec3* dpdy) const override;

 private:
  /// Raster position of the camera-space ray (o, unit d), through the plane in focus; false when it
  /// misses the film and its filter margin. `cos_theta` receives d.z.
  bool raster_of(const Vec3& o, const Vec3& d, Vec2* p_raster, float* cos_theta) const;
  /// raster_of() for a world-space ray leaving a lens point: what We, pdf_we and sample_wi share.
  bool film_cos(const Ray& ray, Vec2* p_raster, float* cos_theta) const;
  float importance_at(float cos_theta) const;  // We at the given cosine (one value for every channel)
  float pdf_dir_at(float cos_theta) const;     // pdf_we()'s directional density at the given cosine
  /// A world-space point in camera space.
  Vec3 to_camera_point(const Vec3& p) const;

  Mat4 to_world_, from_world_;
  // The lens centre (a pinhole's every ray origin) in world space, and taken back to camera space,
  // each computed once by the expression the per-ray code would use, so the values are the same.
  Vec3 lens_centre_{0.f}, lens_centre_camera_{0.f};
  Point2i resolution_;
  Vec2 screen_min_, screen_max_;
  float tan_half_fov_;
  float lens_radius_, focal_distance_;
  float film_area_ = 1.f;  // area of the film's image on the z = 1 plane of camera space
  float lens_area_ = 1.f;  // 1 for a pinhole, so that its position density is a unit delta
  Vec2 pixel_spread_{0.f};  // camera-space size of one pixel on the z = 1 plane (x and y)
  // Constants of raster_of() and sample_wi(), which light tracing calls for every light vertex.
  float plane_ = 1.f;               // the plane raster_of() intersects: z = 1, or the plane in focus
  float screen_of_plane_ = 1.f;     // 1 / (plane_ tan(fov / 2)): plane coordinates to screen units
  Vec2 raster_per_screen_{0.f};     // raster pixels per screen unit, x and y
  Vec3 axis_{0.f, 0.f, 1.f};        // the viewing direction in world space
  Vec2 margin_{0.f};                // filter radius - 1/2: how far (pixels) importance reaches beyond the film
  // Raster position (x, y) to its point on camera space's z = 1 plane:
  // camera_dir_at_raster_origin_ + (x, y, 0) * camera_dir_per_pixel_; and a pinhole's ray direction
  // (before normalisation), the same in world space: x dir_per_x_ + y dir_per_y_ + dir_at_raster_origin_.
  Vec2 camera_dir_per_pixel_{0.f};
  Vec3 camera_dir_at_raster_origin_{0.f, 0.f, 1.f};
  Vec3 dir_per_x_{0.f}, dir_per_y_{0.f}, dir_at_raster_origin_{0.f, 0.f, 1.f};
};

std::span<const ParamSpec> perspective_camera_params();

}  // namespace penumbra
