#include "scene/perspective_camera.h"

#include <penumbra/sampling.h>

#include "scene/screen_window.h"

namespace penumbra {

static const ParamSpec kParams[] = {
    {"float", "fov", "90", "field of view in degrees, along the shorter image axis"},
    {"float", "lensradius", "0", "radius of the thin lens (0: pinhole)"},
    {"float", "focaldistance", "1000000", "distance of the plane in focus"},
    {"float", "frameaspectratio", "", "aspect ratio of the screen window (default: the film's)"},
    {"float[]", "screenwindow", "", "screen window xmin xmax ymin ymax"},
    {"unsupported", "shutteropen", "", "Penumbra renders no motion blur"},
    {"unsupported", "shutterclose", "", "Penumbra renders no motion blur"},
};

std::span<const ParamSpec> perspective_camera_params() { return kParams; }

PerspectiveCamera::PerspectiveCamera(const ParamSet& params, const Mat4& camera_to_world,
                                     Point2i resolution, Vec2 filter_radius)
    : to_world_(camera_to_world), resolution_(resolution), margin_(glm::max(filter_radius - 0.5f, Vec2(0.f))) {
  ScreenWindow w = screen_window(params, resolution);
  screen_min_ = w.min;
  screen_max_ = w.max;
  float fov = params.get_float("fov");
  if (!(fov > 0.f && fov < 180.f))
    throw Error(params.loc_of("fov"), "fov must be in (0, 180) degrees");
  tan_half_fov_ = std::tan(radians(fov) / 2.f);
  lens_radius_ = params.get_float("lensradius");
  focal_distance_ = params.get_float("focaldistance");
  if (lens_radius_ < 0.f) throw Error(params.loc_of("lensradius"), "lensradius must be >= 0");
  if (!(focal_distance_ > 0.f))
    throw Error(params.loc_of("focaldistance"), "focaldistance must be > 0");
  from_world_ = glm::inverse(to_world_);
  lens_centre_ = Vec3(to_world_ * Vec4(Vec3(0.f), 1.f));
  lens_centre_camera_ = Vec3(from_world_ * Vec4(lens_centre_, 1.f));
  // generate_ray() maps the raster rectangle linearly onto the screen window scaled by tan(fov/2)
  // on the z = 1 plane, so that rectangle is the film every importance density refers to.
  Vec2 extent = (screen_max_ - screen_min_) * tan_half_fov_;
  film_area_ = std::abs(extent.x * extent.y);
  lens_area_ = lens_radius_ > 0.f ? Pi * lens_radius_ * lens_radius_ : 1.f;
  pixel_spread_ = Vec2(std::abs(extent.x) / resolution.x, std::abs(extent.y) / resolution.y);
  plane_ = lens_radius_ > 0.f ? focal_distance_ : 1.f;
  screen_of_plane_ = 1.f / (plane_ * tan_half_fov_);
  raster_per_screen_ = Vec2(resolution_.x / (screen_max_.x - screen_min_.x), resolution_.y / (screen_max_.y - screen_min_.y));
  axis_ = glm::normalize(Vec3(to_world_ * Vec4(0.f, 0.f, 1.f, 0.f)));
  // The raster position's point on the z = 1 plane is linear in it (the screen window scaled by
  // tan(fov/2), raster y downwards): camera_dir_per_pixel_ per pixel from the top-left corner
  // camera_dir_at_raster_origin_. A pinhole's ray direction is that point turned to world space, so
  // its map is the same one with the camera-to-world rotation folded in.
  camera_dir_per_pixel_ = Vec2((screen_max_.x - screen_min_.x) * tan_half_fov_ / resolution_.x,
                               -(screen_max_.y - screen_min_.y) * tan_half_fov_ / resolution_.y);
  camera_dir_at_raster_origin_ = Vec3(screen_min_.x * tan_half_fov_, screen_max_.y * tan_half_fov_, 1.f);
  glm::mat3 rotation(to_world_);
  dir_per_x_ = camera_dir_per_pixel_.x * rotation[0];
  dir_per_y_ = camera_dir_per_pixel_.y * rotation[1];
  dir_at_raster_origin_ = rotation * camera_dir_at_raster_origin_;
}

// pbrt-v4's estimate: rotate camera space so that p lies on +z, offset the central ray's direction
// by one pixel's spread (the smallest over the image, which the centre has) and intersect the two
// offset rays with p's tangent plane. A thin lens is treated as its pinhole (its rays through one
// film point meet in the plane of focus, not at p).
void PerspectiveCamera::approximate_dp_dxy(const Vec3& p, const Vec3& n, Vec3* dpdx, Vec3* dpdy) const {
  *dpdx = *dpdy = Vec3(0.f);
  Vec3 pc = Vec3(from_world_ * Vec4(p, 1.f));
  Vec3 nc = glm::transpose(glm::mat3(to_world_)) * n;  // normals: inverse transpose of camera-from-world
  float dist = glm::length(pc);
  if (!(dist > 0.f)) return;
  Frame down_z(pc / dist);  // down_z.n: the direction to p
  Vec3 nz = down_z.to_local(nc);
  if (nz.z == 0.f) return;
  // Tangent plane: dot(nz, x) = nz.z * dist. Rays from the origin along (spread, 0, 1) and (0, spread, 1).
  auto hit = [&](const Vec3& d) -> Vec3 {
    float denom = glm::dot(nz, d);
    if (std::abs(denom) < 1e-6f) return Vec3(0.f);
    return d * (nz.z * dist / denom) - Vec3(0.f, 0.f, dist);
  };
  // The frame's s and t axes are arbitrary around the direction to p; the spreads along camera x
  // and y are carried into the rotated frame so that dpdx follows the image's x axis.
  Vec3 ex = down_z.to_local(Vec3(1.f, 0.f, 0.f)), ey = down_z.to_local(Vec3(0.f, 1.f, 0.f));
  Vec3 hx = hit(Vec3(0.f, 0.f, 1.f) + pixel_spread_.x * ex);
  Vec3 hy = hit(Vec3(0.f, 0.f, 1.f) - pixel_spread_.y * ey);  // raster y grows downwards
  Vec3 wx = down_z.to_world(hx), wy = down_z.to_world(hy);
  *dpdx = Vec3(to_world_ * Vec4(wx, 0.f));
  *dpdy = Vec3(to_world_ * Vec4(wy, 0.f));
}

std::optional<Ray> PerspectiveCamera::generate_ray(const CameraSample& s) const {
  std::optional<Ray> ray(std::in_place);  // filled where the caller receives it (no copy out)
  if (lens_radius_ == 0.f) {
    ray->o = lens_centre_;
    ray->d = glm::normalize(s.p_film.x * dir_per_x_ + s.p_film.y * dir_per_y_ + dir_at_raster_origin_);
    ray->tmax = Infinity;
    return ray;
  }
  Vec3 dir = camera_dir_at_raster_origin_ + Vec3(s.p_film * camera_dir_per_pixel_, 0.f);  // dir.z == 1
  Vec2 lens = lens_radius_ * sample_uniform_disk_concentric(s.p_lens);
  Vec3 focus = dir * focal_distance_;
  Vec3 origin(lens, 0.f);
  dir = focus - origin;
  ray->o = Vec3(to_world_ * Vec4(origin, 1.f));
  ray->d = glm::normalize(Vec3(to_world_ * Vec4(dir, 0.f)));
  ray->tmax = Infinity;
  return ray;
}

}  // namespace penumbra

namespace penumbra {

bool PerspectiveCamera::raster_of(const Vec3& o, const Vec3& d, Vec2* p_raster, float* cos_theta) const {
  *cos_theta = d.z;
  if (!(d.z > 0.f)) return false;
  // A thin lens maps the ray to where it crosses the plane in focus; every ray of a film point
  // passes through the same point there. A pinhole's rays all start at the origin.
  Vec3 p = o + d * ((plane_ - o.z) / d.z);
  Vec2 screen = Vec2(p.x, p.y) * screen_of_plane_;
  Vec2 r((screen.x - screen_min_.x) * raster_per_screen_.x, (screen_max_.y - screen.y) * raster_per_screen_.y);
  if (p_raster) *p_raster = r;
  return r.x >= -margin_.x && r.y >= -margin_.y && r.x < resolution_.x + margin_.x && r.y < resolution_.y + margin_.y;
}

// Rays from the lens centre (a pinhole's, and bidirectional methods' t = 1 connections) skip one
// matrix product: its camera-space position is kept.
Vec3 PerspectiveCamera::to_camera_point(const Vec3& p) const {
  return p == lens_centre_ ? lens_centre_camera_ : Vec3(from_world_ * Vec4(p, 1.f));
}

// The cosine between the camera's axis and a ray leaving a lens point, and where the ray lands on
// the film; false when it misses the film (with its margin).
bool PerspectiveCamera::film_cos(const Ray& ray, Vec2* p_raster, float* cos_theta) const {
  Vec3 o = to_camera_point(ray.o);
  Vec3 d = glm::normalize(Vec3(from_world_ * Vec4(ray.d, 0.f)));
  return raster_of(o, d, p_raster, cos_theta);
}

// On the z = 1 plane dA = r^2 / cos(theta) dw with r = 1 / cos(theta), so a density uniform over
// the film is 1 / (A cos^3) per solid angle; dividing once more by cos(theta) normalises We cos.
float PerspectiveCamera::importance_at(float cos_theta) const {
  float cos2 = cos_theta * cos_theta;
  return 1.f / (film_area_ * lens_area_ * cos2 * cos2);
}

float PerspectiveCamera::pdf_dir_at(float cos_theta) const {
  return 1.f / (film_area_ * cos_theta * cos_theta * cos_theta);
}

Rgb PerspectiveCamera::We(const Ray& ray, Vec2* p_raster) const {
  float cos_theta;
  if (!film_cos(ray, p_raster, &cos_theta)) return Rgb(0.f);
  return Rgb(importance_at(cos_theta));
}

void PerspectiveCamera::pdf_we(const Ray& ray, float* pdf_pos, float* pdf_dir) const {
  float cos_theta;
  if (!film_cos(ray, nullptr, &cos_theta)) {
    *pdf_pos = *pdf_dir = 0.f;
    return;
  }
  *pdf_pos = 1.f / lens_area_;
  *pdf_dir = pdf_dir_at(cos_theta);
}

std::optional<CameraWiSample> PerspectiveCamera::sample_wi(const Vec3& p_ref, Vec2 u) const {
  Vec3 lens(0.f);
  if (lens_radius_ > 0.f) lens = Vec3(lens_radius_ * sample_uniform_disk_concentric(u), 0.f);
  // The one object every path returns, filled where the caller receives it (no copy out).
  std::optional<CameraWiSample> out;
  Vec3 p_lens = lens_radius_ > 0.f ? Vec3(to_world_ * Vec4(lens, 1.f)) : lens_centre_;
  Vec3 d = p_lens - p_ref;
  float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.f)) return out;
  Vec3 wi = d / std::sqrt(dist2);
  float cos_lens = std::abs(glm::dot(axis_, wi));
  if (cos_lens == 0.f) return out;
  // We and pdf_we of the ray from the lens point towards p_ref, from one film_cos().
  Vec2 p_raster(0.f);
  float cos_theta;
  if (!film_cos(Ray{p_lens, -wi, Infinity}, &p_raster, &cos_theta)) return out;
  CameraWiSample& s = out.emplace();
  s.p_lens = p_lens;
  s.wi = wi;
  s.We = Rgb(importance_at(cos_theta));
  s.p_raster = p_raster;
  s.pdf = dist2 / (cos_lens * lens_area_);  // uniform by lens area, converted to solid angle at p_ref
  s.pdf_pos = 1.f / lens_area_;
  s.pdf_dir = pdf_dir_at(cos_theta);
  return out;
}

}  // namespace penumbra
