// Texture "scale": the product of a texture and a float texture (pbrt-v4's ScaleTexture).
//
// | parameter | default | meaning                                                      |
// |-----------|---------|--------------------------------------------------------------|
// | tex       | 1       | value or texture of the texture's type                       |
// | scale     | 1       | float value or float texture multiplying it                  |
#include <penumbra/plugin.h>
#include <penumbra/texture.h>

namespace {

using namespace penumbra;

template <typename T>
class ScaleTexture final : public TextureOf<T>::Texture {
 public:
  ScaleTexture(typename TextureOf<T>::Input tex, TexturedFloat scale) : tex_(tex), scale_(scale) {}
  T evaluate(const TextureEvalContext& ctx) const override {
    float s = scale_.evaluate(ctx);
    if (s == 0.f) return T(0.f);  // pbrt-v4 skips the other lookup too
    return s * tex_.evaluate(ctx);
  }

 private:
  typename TextureOf<T>::Input tex_;
  TexturedFloat scale_;
};

const ParamSpec kParams[] = {
    {"texture", "tex", "1", "value or texture (of the texture's type) to scale"},
    {"float texture", "scale", "1", "float value or float texture multiplying it"},
};

template <typename T>
Object* make(const CreateContext& ctx) {
  return new ScaleTexture<T>(ctx.input<T>("tex"), ctx.float_input("scale"));
}

Object* create(const CreateContext& ctx) { return ctx.spectrum_texture ? make<Rgb>(ctx) : make<float>(ctx); }

}  // namespace

PENUMBRA_PLUGIN(Texture, "scale", "a texture times a float texture", kParams, create)
