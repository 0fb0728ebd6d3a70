// Texture "constant": the same value everywhere (pbrt-v4's ConstantTexture).
//
// | parameter | default | meaning                                           |
// |-----------|---------|---------------------------------------------------|
// | value     | 1       | a float (float texture) or an rgb (spectrum one)  |
#include <penumbra/plugin.h>
#include <penumbra/texture.h>

namespace {

using namespace penumbra;

template <typename T>
class ConstantTexture final : public TextureOf<T>::Texture {
 public:
  explicit ConstantTexture(T value) : value_(value) {}
  T evaluate(const TextureEvalContext&) const override { return value_; }

 private:
  T value_;
};

const ParamSpec kParams[] = {
    {"texture", "value", "1", "the value: float or rgb, as the texture's type"},
};

template <typename T>
Object* make(const CreateContext& ctx) {
  auto in = ctx.input<T>("value");
  if (!in.is_constant()) throw Error(ctx.params.loc_of("value"), "the value of a constant texture must be a value, not a texture");
  return new ConstantTexture<T>(in.constant());
}

Object* create(const CreateContext& ctx) { return ctx.spectrum_texture ? make<Rgb>(ctx) : make<float>(ctx); }

}  // namespace

PENUMBRA_PLUGIN(Texture, "constant", "the same value everywhere", kParams, create)
