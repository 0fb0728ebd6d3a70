// Texture "imagemap": an image file through OpenImageIO, looked up through a MIP pyramid
// (pbrt-v4's ImageTexture). The mapped t runs upwards while images store their top row first, so
// the image is looked up at (s, 1 - t). The value is scale * lookup, then 1 - value if "invert",
// clamped at zero. A float texture takes the mean of the image's RGB channels.
//
// | parameter           | default    | meaning                                                   |
// |---------------------|------------|-----------------------------------------------------------|
// | string filename     |            | image file, relative to the scene file                    |
// | string filter       | bilinear   | point, bilinear, trilinear or ewa                         |
// | float maxanisotropy | 8          | ewa: longest allowed ratio of the footprint's axes        |
// | string wrap         | repeat     | repeat, black or clamp outside [0, 1]                     |
// | float scale         | 1          | multiplies the looked-up value                            |
// | bool invert         | false      | 1 - value                                                 |
// | string encoding     | sRGB       | 8/16-bit files: sRGB, linear or "gamma G"; float files are linear |
// | mapping..           |            | see texture_mapping.h                                     |
#include "mipmap_cache.h"

#include <penumbra/plugin.h>
#include <penumbra/texture.h>
#include <penumbra/texture_mapping.h>

#include <fmt/core.h>

#include <filesystem>

namespace {

using namespace penumbra;
using imagemap::Filter;
using imagemap::MipMap;
using imagemap::WrapMode;

struct LookupSettings {
  Filter filter = Filter::Bilinear;
  float max_anisotropy = 8.f;
  float scale = 1.f;
  bool invert = false;
};

template <typename T>
class ImageTexture final : public TextureOf<T>::Texture {
 public:
  ImageTexture(TextureMapping2D mapping, std::shared_ptr<const MipMap> mip, LookupSettings s, std::string file)
      : mapping_(mapping), mip_(std::move(mip)), s_(s), file_(std::move(file)) {}

  T evaluate(const TextureEvalContext& ctx) const override {
    TexCoord2D c = mapping_.map(ctx);
    // Flipping t flips its derivatives too (only EWA's ellipse orientation notices).
    Rgb v = s_.scale * mip_->filter(s_.filter, Vec2(c.st.x, 1.f - c.st.y), Vec2(c.dsdx, -c.dtdx),
                                    Vec2(c.dsdy, -c.dtdy), s_.max_anisotropy);
    if (s_.invert) v = Rgb(1.f) - v;
    v = glm::max(v, Rgb(0.f));
    if constexpr (std::is_same_v<T, float>) return (v.r + v.g + v.b) / 3.f;
    else return v;
  }

  std::vector<std::string> structures_built() const override { return {"mipmap"}; }
  std::vector<std::pair<std::string, double>> statistics() const override {
    return {{"mipmap_levels", static_cast<double>(mip_->levels())},
            {"mipmaps_built_in_process", static_cast<double>(imagemap::mipmaps_built())}};
  }

 private:
  TextureMapping2D mapping_;
  std::shared_ptr<const MipMap> mip_;
  LookupSettings s_;
  std::string file_;
};

const ParamSpec kParams[] = {
    {"string", "filename", "", "image file (any format OpenImageIO reads), relative to the scene file"},
    {"string", "filter", "bilinear", "point, bilinear, trilinear or ewa"},
    {"float", "maxanisotropy", "8", "ewa: largest ratio of the footprint's axes"},
    {"string", "wrap", "repeat", "repeat, black or clamp outside [0, 1]"},
    {"float", "scale", "1", "multiplies the looked-up value"},
    {"bool", "invert", "false", "use 1 - value"},
    {"string", "encoding", "sRGB", "8/16-bit files: sRGB, linear or \"gamma G\" (float files are linear)"},
    PENUMBRA_TEXTURE_MAPPING_PARAMS,
};

Filter parse_filter(const ParamSet& p) {
  std::string f = p.get_string("filter");
  if (f == "point") return Filter::Point;
  if (f == "bilinear") return Filter::Bilinear;
  if (f == "trilinear") return Filter::Trilinear;
  if (f == "ewa" || f == "EWA") return Filter::Ewa;
  throw Error(p.loc_of("filter"), fmt::format("unknown filter \"{}\"; available: point, bilinear, trilinear, ewa", f));
}

WrapMode parse_wrap(const ParamSet& p) {
  std::string w = p.get_string("wrap");
  if (w == "repeat") return WrapMode::Repeat;
  if (w == "black") return WrapMode::Black;
  if (w == "clamp") return WrapMode::Clamp;
  throw Error(p.loc_of("wrap"), fmt::format("unknown wrap mode \"{}\"; available: repeat, black, clamp", w));
}

Object* create(const CreateContext& ctx) {
  const ParamSet& p = ctx.params;
  std::string file = p.get_string("filename");
  if (file.empty()) throw Error(ctx.loc, "imagemap needs \"string filename\"");
  std::filesystem::path path(file);
  if (path.is_relative() && !ctx.scene_dir.empty()) path = std::filesystem::path(ctx.scene_dir) / path;
  LookupSettings s;
  s.filter = parse_filter(p);
  s.max_anisotropy = p.get_float("maxanisotropy");
  if (!(s.max_anisotropy >= 1.f)) throw Error(p.loc_of("maxanisotropy"), "maxanisotropy must be >= 1");
  s.scale = p.get_float("scale");
  s.invert = p.get_bool("invert");
  imagemap::Encoding enc = imagemap::parse_encoding(p.get_string("encoding"), p.loc_of("encoding"));
  auto mip = imagemap::load_mipmap(path.string(), enc, parse_wrap(p), p.has("filename") ? p.loc_of("filename") : ctx.loc);
  TextureMapping2D mapping = TextureMapping2D::create(ctx);
  if (ctx.spectrum_texture) return new ImageTexture<Rgb>(mapping, mip, s, path.string());
  return new ImageTexture<float>(mapping, mip, s, path.string());
}

}  // namespace

PENUMBRA_PLUGIN(Texture, "imagemap", "image file through a MIP pyramid (point, bilinear, trilinear, EWA)", kParams, create)
