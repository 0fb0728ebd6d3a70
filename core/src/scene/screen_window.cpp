#include "scene/screen_window.h"

namespace penumbra {

ScreenWindow screen_window(const ParamSet& params, Point2i resolution) {
  float aspect = params.has("frameaspectratio") ? params.get_float("frameaspectratio")
                                                : static_cast<float>(resolution.x) / static_cast<float>(resolution.y);
  if (!(aspect > 0.f)) throw Error(params.loc_of("frameaspectratio"), "frameaspectratio must be > 0");
  ScreenWindow w;
  if (aspect > 1.f) {
    w.min = Vec2(-aspect, -1.f), w.max = Vec2(aspect, 1.f);
  } else {
    w.min = Vec2(-1.f, -1.f / aspect), w.max = Vec2(1.f, 1.f / aspect);
  }
  std::vector<float> sw = params.get_floats("screenwindow");
  if (!sw.empty()) {
    if (sw.size() != 4) throw Error(params.loc_of("screenwindow"), "screenwindow takes 4 values: xmin xmax ymin ymax");
    if (!(sw[0] < sw[1] && sw[2] < sw[3]))
      throw Error(params.loc_of("screenwindow"), "screenwindow needs xmin < xmax and ymin < ymax");
    w.min = Vec2(sw[0], sw[2]), w.max = Vec2(sw[1], sw[3]);
  }
  return w;
}

}  // namespace penumbra
