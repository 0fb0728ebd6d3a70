// Texture "directionmix": blends two textures by how much the surface faces a direction,
// a = |n . dir|, value = a tex1 + (1 - a) tex2 (pbrt-v4's DirectionMixTexture). n is the geometric
// normal; dir is given in the space of the Texture directive and normalised in the world.
//
// | parameter    | default | meaning                                          |
// |--------------|---------|--------------------------------------------------|
// | tex1         | 0       | value or texture, where the surface faces dir    |
// | tex2         | 1       | value or texture, where it is edge-on to dir     |
// | vector3 dir  | 0 1 0   | the direction                                    |
#include <penumbra/plugin.h>
#include <penumbra/texture.h>

namespace {

using namespace penumbra;

template <typename T>
class DirectionMixTexture final : public TextureOf<T>::Texture {
 public:
  using Input = typename TextureOf<T>::Input;
  DirectionMixTexture(Input tex1, Input tex2, Vec3 dir) : tex1_(tex1), tex2_(tex2), dir_(dir) {}
  T evaluate(const TextureEvalContext& ctx) const override {
    float a = std::min(1.f, std::abs(glm::dot(ctx.n, dir_)));
    T t1(0.f), t2(0.f);
    if (a != 0.f) t1 = tex1_.evaluate(ctx);
    if (a != 1.f) t2 = tex2_.evaluate(ctx);
    return a * t1 + (1.f - a) * t2;
  }

 private:
  Input tex1_, tex2_;
  Vec3 dir_;
};

const ParamSpec kParams[] = {
    {"texture", "tex1", "0", "value or texture where the surface faces dir"},
    {"texture", "tex2", "1", "value or texture where the surface is edge-on to dir"},
    {"vector3", "dir", "0 1 0", "the direction (texture space)"},
};

template <typename T>
Object* make(const CreateContext& ctx) {
  Vec3 dir = Vec3(ctx.to_world * Vec4(ctx.params.get_point3("dir"), 0.f));
  if (!(glm::length(dir) > 0.f)) throw Error(ctx.params.loc_of("dir"), "dir must not be zero");
  return new DirectionMixTexture<T>(ctx.input<T>("tex1"), ctx.input<T>("tex2"), glm::normalize(dir));
}

Object* create(const CreateContext& ctx) { return ctx.spectrum_texture ? make<Rgb>(ctx) : make<float>(ctx); }

}  // namespace

PENUMBRA_PLUGIN(Texture, "directionmix", "blend of two textures by the normal's alignment with a direction", kParams, create)
