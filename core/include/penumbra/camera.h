// The camera maps film positions (in raster coordinates, pixels) and lens samples to world rays.
// Bidirectional methods also need the camera as an emitter of importance (pbrt-v3's We, Pdf_We and
// Sample_Wi) to connect light-path vertices to the film.
#pragma once

#include <penumbra/color.h>
#include <penumbra/interaction.h>
#include <penumbra/math.h>

#include <optional>

namespace penumbra {

struct CameraSample {
  Vec2 p_film;      // raster position: (0,0) is the top-left corner of the image
  Vec2 p_lens{0.5f};
};

/// A lens point chosen to connect a point of the scene to the camera.
struct CameraWiSample {
  Rgb We{0.f};       // importance leaving the lens point towards the reference point
  Vec3 wi{0.f};      // unit direction from the reference point to the lens point
  float pdf = 0.f;   // density of the lens point, per unit solid angle at the reference point
  Vec2 p_raster{0.f};  // where the connection lands on the film
  Vec3 p_lens{0.f};  // world-space lens point (the shadow ray's target; not on any surface)
  // What pdf_we() gives for the ray from p_lens towards the reference point (-wi), so that a
  // bidirectional connection through the lens needs no second call.
  float pdf_pos = 0.f;
  float pdf_dir = 0.f;
};

class Camera {
 public:
  virtual ~Camera();
  virtual Point2i resolution() const = 0;
  /// A world-space ray with a unit direction, or empty if none leaves the lens.
  virtual std::optional<Ray> generate_ray(const CameraSample& s) const = 0;

  // Importance, normalised so that the integral of We cos(theta) over the lens area and the
  // directions through the film is 1: pixel values estimated by splatting light paths (divided by
  // the samples per pixel) then match those estimated from camera rays. The defaults describe a
  // camera that light paths cannot connect to.

  /// Importance carried by `ray` leaving a lens point; 0 when the ray misses the film. `p_raster`
  /// receives the raster position the ray corresponds to.
  virtual Rgb We(const Ray& ray, Vec2* p_raster = nullptr) const { return Rgb(0.f); }
  /// Densities of generate_ray() producing `ray`: per unit lens area (1 for a pinhole) and per unit
  /// solid angle of its direction (0 outside the film).
  virtual void pdf_we(const Ray& ray, float* pdf_pos, float* pdf_dir) const { *pdf_pos = *pdf_dir = 0.f; }
  /// Chooses a lens point (u: uniform over the lens) seen from `p_ref`. Empty when the connection
  /// misses the film. A camera that implements it also fills the sample's pdf_pos and pdf_dir with
  /// what pdf_we() gives for the ray from the lens point towards p_ref.
  virtual std::optional<CameraWiSample> sample_wi(const Vec3& p_ref, Vec2 u) const { return std::nullopt; }
  /// Whether light paths can connect to the lens (We, pdf_we and sample_wi describe it). False for a
  /// camera whose rays are a delta in direction (orthographic): bidirectional methods then treat the
  /// lens vertex as specular (no t = 1 strategy), and a light tracer cannot render through it.
  virtual bool connectible() const { return false; }

  /// Approximate change of a surface point p (normal n) from one pixel to the next, for texture
  /// filtering where no ray differentials exist (pbrt-v4's estimate: the camera's smallest
  /// per-pixel ray spread, intersected with the tangent plane at p). Zero by default.
  virtual void approximate_dp_dxy(const Vec3& p, const Vec3& n, Vec3* dpdx, Vec3* dpdy) const {
    *dpdx = *dpdy = Vec3(0.f);
  }
};

}  // namespace penumbra
