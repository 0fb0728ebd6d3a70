// The screen window shared by the perspective and orthographic cameras (pbrt-v4's rule): by default
// [-aspect, aspect] x [-1, 1] for landscape and [-1, 1] x [-1/aspect, 1/aspect] for portrait, with
// aspect = "frameaspectratio" or the film's width / height; "screenwindow" [xmin xmax ymin ymax]
// replaces it. Errors are located at the parameter.
#pragma once

#include <penumbra/math.h>
#include <penumbra/params.h>

namespace penumbra {

struct ScreenWindow {
  Vec2 min, max;
};

ScreenWindow screen_window(const ParamSet& params, Point2i resolution);

}  // namespace penumbra
