// Texture "bilerp": bilinear interpolation of four corner values over the mapped (s, t),
// (1-s)(1-t) v00 + s(1-t) v10 + (1-s)t v01 + st v11, not wrapped outside [0, 1] (pbrt-v4's
// BilerpTexture).
//
// | parameter | default | meaning                          |
// |-----------|---------|----------------------------------|
// | v00       | 0       | value at (s, t) = (0, 0)         |
// | v01       | 1       | value at (0, 1)                  |
// | v10       | 0       | value at (1, 0)                  |
// | v11       | 1       | value at (1, 1)                  |
// | mapping.. |         | see texture_mapping.h            |
#include <penumbra/plugin.h>
#include <penumbra/texture.h>
#include <penumbra/texture_mapping.h>

namespace {

using namespace penumbra;

template <typename T>
class BilerpTexture final : public TextureOf<T>::Texture {
 public:
  BilerpTexture(TextureMapping2D mapping, T v00, T v01, T v10, T v11)
      : mapping_(mapping), v00_(v00), v01_(v01), v10_(v10), v11_(v11) {}
  T evaluate(const TextureEvalContext& ctx) const override {
    Vec2 st = mapping_.map(ctx).st;
    float s = st.x, t = st.y;
    return (1.f - s) * (1.f - t) * v00_ + s * (1.f - t) * v10_ + (1.f - s) * t * v01_ + s * t * v11_;
  }

 private:
  TextureMapping2D mapping_;
  T v00_, v01_, v10_, v11_;
};

const ParamSpec kParams[] = {
    {"texture", "v00", "0", "value at (s, t) = (0, 0)"},
    {"texture", "v01", "1", "value at (0, 1)"},
    {"texture", "v10", "0", "value at (1, 0)"},
    {"texture", "v11", "1", "value at (1, 1)"},
    PENUMBRA_TEXTURE_MAPPING_PARAMS,
};

template <typename T>
Object* make(const CreateContext& ctx) {
  T v[4];
  const char* names[4] = {"v00", "v01", "v10", "v11"};
  for (int i = 0; i < 4; ++i) {
    auto in = ctx.input<T>(names[i]);
    if (!in.is_constant()) throw Error(ctx.params.loc_of(names[i]), "bilerp corners are values, not textures");
    v[i] = in.constant();
  }
  return new BilerpTexture<T>(TextureMapping2D::create(ctx), v[0], v[1], v[2], v[3]);
}

Object* create(const CreateContext& ctx) { return ctx.spectrum_texture ? make<Rgb>(ctx) : make<float>(ctx); }

}  // namespace

PENUMBRA_PLUGIN(Texture, "bilerp", "bilinear interpolation of four corner values", kParams, create)
