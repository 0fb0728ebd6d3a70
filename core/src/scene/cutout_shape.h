// The shape of an area light that has an alpha cut-out ("float alpha" / "texture alpha" on a shape
// with AreaLightSource): sampled as the shape itself (uniform over all of it, as pbrt-v4), with
// present() telling the light where the cut-out removes the surface, so that it emits nothing from
// there. Hits already honour the cut-out (alpha_cutout.h), so both ways of finding the light see
// the same emitter: exactly for alpha 0 and 1, in expectation for alpha in between (a ray keeps a
// hit with probability alpha, a light sample is present with probability alpha).
#pragma once

#include "scene/alpha_cutout.h"

#include <penumbra/shape.h>

namespace penumbra {

class CutoutShape final : public Shape {
 public:
  CutoutShape(const Shape& shape, AlphaCutout cutout) : shape_(shape), cutout_(std::move(cutout)) {}
  float area() const override { return shape_.area(); }
  ShapeSample sample_area(Vec2 u) const override { return shape_.sample_area(u); }
  std::optional<ShapeSample> sample_solid_angle(const ShapeSampleContext& ctx, Vec2 u) const override {
    return shape_.sample_solid_angle(ctx, u);
  }
  float pdf_solid_angle(const ShapeSampleContext& ctx, const Vec3& wi, const Vec3& p_hit,
                        const Vec3& n_hit) const override {
    return shape_.pdf_solid_angle(ctx, wi, p_hit, n_hit);
  }
  bool present(const ShapeSample& s) const override;

 private:
  const Shape& shape_;
  AlphaCutout cutout_;
};

}  // namespace penumbra
