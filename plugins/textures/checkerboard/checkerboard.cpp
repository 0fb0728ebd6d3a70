// Texture "checkerboard": alternating unit squares of (s, t), tex1 on the square at the origin and
// wherever floor(s) + floor(t) is even, tex2 elsewhere (pbrt-v4's 2D checkerboard). The pattern is
// filtered over the pixel footprint in closed form: the square wave c(x) = +-1 convolved with a
// triangle filter of half-width r is the second difference (D(x+r) - 2 D(x) + D(x-r)) / r^2 of its
// double integral D, with r = 1.5 times the larger of the footprint's extents along s (and t), as
// in pbrt-v4. With no footprint the pattern is exact.
//
// | parameter         | default | meaning                                  |
// |-------------------|---------|------------------------------------------|
// | tex1              | 1       | value or texture on the even squares     |
// | tex2              | 0       | value or texture on the odd squares      |
// | integer dimension | 2       | must be 2 (3D checkerboards: not yet)    |
// | mapping..         |         | see texture_mapping.h                    |
#include <penumbra/plugin.h>
#include <penumbra/texture.h>
#include <penumbra/texture_mapping.h>

#include <cmath>

namespace {

using namespace penumbra;

// Double integral of the square wave c (+1 on [0, 1), -1 on [1, 2), period 2) from 0: each period
// adds 1; within one it is y^2 / 2, then -y^2 / 2 + 2y - 1.
float square_wave_double_integral(float x) {
  float periods = std::floor(x / 2.f);
  float y = x - 2.f * periods;
  float within = y <= 1.f ? 0.5f * y * y : -0.5f * y * y + 2.f * y - 1.f;
  return periods + within;
}

// c(x) filtered by a triangle of half-width r.
float filtered_square_wave(float x, float r) {
  if (std::floor(x - r) == std::floor(x + r)) return (static_cast<int>(std::floor(x)) & 1) ? -1.f : 1.f;
  return (square_wave_double_integral(x + r) - 2.f * square_wave_double_integral(x) +
          square_wave_double_integral(x - r)) /
         (r * r);
}

template <typename T>
class CheckerboardTexture final : public TextureOf<T>::Texture {
 public:
  using Input = typename TextureOf<T>::Input;
  CheckerboardTexture(TextureMapping2D mapping, Input tex1, Input tex2)
      : mapping_(mapping), tex1_(tex1), tex2_(tex2) {}

  T evaluate(const TextureEvalContext& ctx) const override {
    TexCoord2D c = mapping_.map(ctx);
    float rs = 1.5f * std::max(std::abs(c.dsdx), std::abs(c.dsdy));
    float rt = 1.5f * std::max(std::abs(c.dtdx), std::abs(c.dtdy));
    // Weight of tex2: 0 on even squares, 1 on odd ones, in between where the filter straddles edges.
    float w = 0.5f - 0.5f * filtered_square_wave(c.st.x, rs) * filtered_square_wave(c.st.y, rt);
    T a(0.f), b(0.f);
    if (w != 1.f) a = tex1_.evaluate(ctx);
    if (w != 0.f) b = tex2_.evaluate(ctx);
    return (1.f - w) * a + w * b;
  }

 private:
  TextureMapping2D mapping_;
  Input tex1_, tex2_;
};

const ParamSpec kParams[] = {
    {"texture", "tex1", "1", "value or texture on the squares where floor(s) + floor(t) is even"},
    {"texture", "tex2", "0", "value or texture on the other squares"},
    {"integer", "dimension", "2", "2 (a 3D checkerboard is not supported yet)"},
    PENUMBRA_TEXTURE_MAPPING_PARAMS,
};

template <typename T>
Object* make(const CreateContext& ctx) {
  return new CheckerboardTexture<T>(TextureMapping2D::create(ctx), ctx.input<T>("tex1"), ctx.input<T>("tex2"));
}

Object* create(const CreateContext& ctx) {
  int dim = ctx.params.get_int("dimension");
  if (dim != 2)
    throw Error(ctx.params.loc_of("dimension"),
                dim == 3 ? "3D checkerboards are not supported yet (only \"dimension\" 2)"
                         : "checkerboard \"dimension\" must be 2");
  return ctx.spectrum_texture ? make<Rgb>(ctx) : make<float>(ctx);
}

}  // namespace

PENUMBRA_PLUGIN(Texture, "checkerboard", "2D checkerboard of two textures, filtered over the footprint", kParams, create)
