#include "scene/orthographic_camera.h"

#include "scene/screen_window.h"

namespace penumbra {

static const ParamSpec kParams[] = {
    {"float", "frameaspectratio", "", "aspect ratio of the screen window (default: the film's)"},
    {"float[]", "screenwindow", "", "screen window xmin xmax ymin ymax (camera-space units)"},
    {"unsupported", "lensradius", "", "Penumbra's orthographic camera is a pinhole (no depth of field)"},
    {"unsupported", "focaldistance", "", "Penumbra's orthographic camera is a pinhole (no depth of field)"},
    {"unsupported", "shutteropen", "", "Penumbra renders no motion blur"},
    {"unsupported", "shutterclose", "", "Penumbra renders no motion blur"},
};

std::span<const ParamSpec> orthographic_camera_params() { return kParams; }

OrthographicCamera::OrthographicCamera(const ParamSet& params, const Mat4& camera_to_world, Point2i resolution)
    : to_world_(camera_to_world), resolution_(resolution) {
  ScreenWindow w = screen_window(params, resolution);
  screen_min_ = w.min;
  screen_max_ = w.max;
}

std::optional<Ray> OrthographicCamera::generate_ray(const CameraSample& s) const {
  Vec2 screen(screen_min_.x + (s.p_film.x / resolution_.x) * (screen_max_.x - screen_min_.x),
              screen_max_.y - (s.p_film.y / resolution_.y) * (screen_max_.y - screen_min_.y));
  Vec3 o = Vec3(to_world_ * Vec4(screen.x, screen.y, 0.f, 1.f));
  Vec3 d = glm::normalize(Vec3(to_world_ * Vec4(0.f, 0.f, 1.f, 0.f)));
  return Ray{o, d, Infinity};
}

}  // namespace penumbra
