// Texture "mix": (1 - amount) tex1 + amount tex2 (pbrt-v4's MixTexture).
//
// | parameter | default | meaning                                          |
// |-----------|---------|--------------------------------------------------|
// | tex1      | 0       | value or texture of the texture's type           |
// | tex2      | 1       | value or texture of the texture's type           |
// | amount    | 0.5     | float value or float texture: weight of tex2     |
#include <penumbra/plugin.h>
#include <penumbra/texture.h>

namespace {

using namespace penumbra;

template <typename T>
class MixTexture final : public TextureOf<T>::Texture {
 public:
  using Input = typename TextureOf<T>::Input;
  MixTexture(Input tex1, Input tex2, TexturedFloat amount) : tex1_(tex1), tex2_(tex2), amount_(amount) {}
  T evaluate(const TextureEvalContext& ctx) const override {
    float a = amount_.evaluate(ctx);
    T t1(0.f), t2(0.f);  // a texture whose weight is 0 is not looked up
    if (a != 1.f) t1 = tex1_.evaluate(ctx);
    if (a != 0.f) t2 = tex2_.evaluate(ctx);
    return (1.f - a) * t1 + a * t2;
  }

 private:
  Input tex1_, tex2_;
  TexturedFloat amount_;
};

const ParamSpec kParams[] = {
    {"texture", "tex1", "0", "value or texture (of the texture's type) weighted by 1 - amount"},
    {"texture", "tex2", "1", "value or texture (of the texture's type) weighted by amount"},
    {"float texture", "amount", "0.5", "float value or float texture: the weight of tex2"},
};

template <typename T>
Object* make(const CreateContext& ctx) {
  return new MixTexture<T>(ctx.input<T>("tex1"), ctx.input<T>("tex2"), ctx.float_input("amount"));
}

Object* create(const CreateContext& ctx) { return ctx.spectrum_texture ? make<Rgb>(ctx) : make<float>(ctx); }

}  // namespace

PENUMBRA_PLUGIN(Texture, "mix", "blend of two textures by a float texture", kParams, create)
