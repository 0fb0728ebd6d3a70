// Textures as plugins: `Texture "name" "float"|"spectrum" "class" ...` creates a FloatTexture or a
// SpectrumTexture from the plugin penumbra-texture-<class>.so. Textures are evaluated where a hit
// is shaded, at a TextureEvalContext: the point, its normal, its (u, v) and the footprint of one
// pixel there (how far p, u and v move from one pixel to the next), which image textures use to
// pick a MIP-map level.
//
// Materials and textures take their texturable parameters as TexturedFloat / TexturedRgb: a
// constant or a texture, read from the parameter list by CreateContext::float_input() and
// rgb_input() (plugin.h), which resolve `"texture reflectance" "name"` to the named texture.
#pragma once

#include <penumbra/color.h>
#include <penumbra/math.h>
#include <penumbra/object.h>
#include <penumbra/spectrum.h>

#include <cstdint>

namespace penumbra {

/// Where a texture is looked up. The footprint (dpdx ... dvdy) is zero where the runtime did not
/// estimate one (textures then filter as for an infinitely small pixel).
struct TextureEvalContext {
  Vec3 p{0.f};   // world-space point
  Vec3 n{0.f};   // geometric normal there
  Vec2 uv{0.f};  // surface parameterisation
  Vec3 dpdx{0.f}, dpdy{0.f};  // change of p from one pixel to the next (x: right, y: down)
  float dudx = 0.f, dudy = 0.f, dvdx = 0.f, dvdy = 0.f;
  /// The path's wavelengths in a spectral render (null in an RGB one): TexturedRgb then gives the
  /// parameter's spectrum at them. Texture plugins are always evaluated in RGB.
  const SampledWavelengths* wavelengths = nullptr;
};

class FloatTexture : public Object {
 public:
  ~FloatTexture() override;
  virtual float evaluate(const TextureEvalContext& ctx) const = 0;
};

/// Colour textures: linear Rec.709 RGB (reflectances, scales; not clamped).
class SpectrumTexture : public Object {
 public:
  ~SpectrumTexture() override;
  virtual Rgb evaluate(const TextureEvalContext& ctx) const = 0;
};

/// A float parameter that is a constant or a texture. Evaluating a constant costs one branch.
class TexturedFloat {
 public:
  TexturedFloat() = default;
  explicit TexturedFloat(float value) : value_(value) {}
  explicit TexturedFloat(const FloatTexture* texture) : texture_(texture) {}
  bool is_constant() const { return texture_ == nullptr; }
  /// The constant (meaningful only when is_constant()).
  float constant() const { return value_; }
  float evaluate(const TextureEvalContext& ctx) const {
    return texture_ ? texture_->evaluate(ctx) : value_;
  }

 private:
  float value_ = 0.f;
  const FloatTexture* texture_ = nullptr;
};

/// What an RGB parameter is, which decides its spectrum in a spectral render.
enum class RgbKind : uint8_t {
  Albedo,     // a reflectance or transmittance: clamped to [0, 1], SampledWavelengths::albedo()
  Unbounded,  // an index of refraction, absorption or scale: SampledWavelengths::unbounded()
};

/// An RGB parameter that is a constant or a spectrum texture. evaluate() gives linear RGB, or in a
/// spectral render (ctx.wavelengths set) the parameter's spectrum at the path's wavelengths; a
/// material whose constants are made into a BSDF once must therefore evaluate them per hit when
/// CreateContext::spectral is set.
class TexturedRgb {
 public:
  TexturedRgb() = default;
  explicit TexturedRgb(Rgb value, RgbKind kind = RgbKind::Albedo) : value_(value), kind_(kind) {}
  explicit TexturedRgb(const SpectrumTexture* texture, RgbKind kind = RgbKind::Albedo)
      : texture_(texture), kind_(kind) {}
  bool is_constant() const { return texture_ == nullptr; }
  Rgb constant() const { return value_; }
  RgbKind kind() const { return kind_; }
  Rgb evaluate(const TextureEvalContext& ctx) const {
    if (ctx.wavelengths) return evaluate_spectral(ctx);
    return texture_ ? texture_->evaluate(ctx) : value_;
  }

 private:
  Rgb evaluate_spectral(const TextureEvalContext& ctx) const;
  Rgb value_{0.f};
  const SpectrumTexture* texture_ = nullptr;
  RgbKind kind_ = RgbKind::Albedo;
};

/// The interface and parameter type of a texture of values T (float or Rgb), for plugins that
/// implement both kinds with one template: `class Mix : public TextureOf<T>::Texture`.
template <typename T>
struct TextureOf;
template <>
struct TextureOf<float> {
  using Texture = FloatTexture;
  using Input = TexturedFloat;
};
template <>
struct TextureOf<Rgb> {
  using Texture = SpectrumTexture;
  using Input = TexturedRgb;
};

}  // namespace penumbra
