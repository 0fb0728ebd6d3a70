// The camera maps film positions (in raster coordinates, pixels) and lens samples to world rays.
#pragma once

#include <penumbra/interaction.h>
#include <penumbra/math.h>

#include <optional>

namespace penumbra {

struct CameraSample {
  Vec2 p_film;      // raster position: (0,0) is the top-left corner of the image
  Vec2 p_lens{0.5f};
};

class Camera {
 public:
  virtual ~Camera();
  virtual Point2i resolution() const = 0;
  /// A world-space ray with a unit direction, or empty if none leaves the lens.
  virtual std::optional<Ray> generate_ray(const CameraSample& s) const = 0;
};

}  // namespace penumbra
