#include "scene/perspective_camera.h"

#include <penumbra/sampling.h>

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
                                     Point2i resolution)
    : to_world_(camera_to_world), resolution_(resolution) {
  float aspect = params.has("frameaspectratio")
                     ? params.get_float("frameaspectratio")
                     : static_cast<float>(resolution.x) / static_cast<float>(resolution.y);
  if (aspect > 1.f) {
    screen_min_ = Vec2(-aspect, -1.f), screen_max_ = Vec2(aspect, 1.f);
  } else {
    screen_min_ = Vec2(-1.f, -1.f / aspect), screen_max_ = Vec2(1.f, 1.f / aspect);
  }
  std::vector<float> sw = params.get_floats("screenwindow");
  if (!sw.empty()) {
    if (sw.size() != 4) throw Error(params.loc_of("screenwindow"), "screenwindow takes 4 values");
    screen_min_ = Vec2(sw[0], sw[2]), screen_max_ = Vec2(sw[1], sw[3]);
  }
  float fov = params.get_float("fov");
  if (!(fov > 0.f && fov < 180.f))
    throw Error(params.loc_of("fov"), "fov must be in (0, 180) degrees");
  tan_half_fov_ = std::tan(radians(fov) / 2.f);
  lens_radius_ = params.get_float("lensradius");
  focal_distance_ = params.get_float("focaldistance");
  if (lens_radius_ < 0.f) throw Error(params.loc_of("lensradius"), "lensradius must be >= 0");
  if (!(focal_distance_ > 0.f))
    throw Error(params.loc_of("focaldistance"), "focaldistance must be > 0");
}

std::optional<Ray> PerspectiveCamera::generate_ray(const CameraSample& s) const {
  Vec2 screen(screen_min_.x + (s.p_film.x / resolution_.x) * (screen_max_.x - screen_min_.x),
              screen_max_.y - (s.p_film.y / resolution_.y) * (screen_max_.y - screen_min_.y));
  Vec3 dir(screen.x * tan_half_fov_, screen.y * tan_half_fov_, 1.f);
  Vec3 origin(0.f);
  if (lens_radius_ > 0.f) {
    Vec2 lens = lens_radius_ * sample_uniform_disk_concentric(s.p_lens);
    Vec3 focus = dir * focal_distance_;  // dir.z == 1
    origin = Vec3(lens, 0.f);
    dir = focus - origin;
  }
  Vec3 o = Vec3(to_world_ * Vec4(origin, 1.f));
  Vec3 d = glm::normalize(Vec3(to_world_ * Vec4(dir, 0.f)));
  return Ray{o, d, Infinity};
}

}  // namespace penumbra
