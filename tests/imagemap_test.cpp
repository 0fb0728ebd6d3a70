// The "imagemap" texture on images generated here: texels at known (u, v) under each wrap mode,
// bilinear interpolation between texel centres, trilinear filtering between MIP levels the test
// builds itself (2x2 box averages), EWA on images with a known average, the 8-bit decodings
// (sRGB, linear, gamma) and the sharing of one pyramid between textures.
#include "parser/scene_description.h"
#include "registry/registry.h"
#include "scene/scene_builder.h"
#include "support/command.h"

#include <penumbra/image.h>
#include <penumbra/plugin.h>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <fmt/core.h>

#include <cmath>

using namespace penumbra;

namespace {

// A width x height float image whose texel (x, y) (row 0 at the top) is value(x, y) in every channel.
std::string write_float_image(const std::string& dir, const std::string& name, int w, int h,
                              const std::function<float(int, int)>& value) {
  ImageRgb img;
  img.width = w, img.height = h;
  img.pixels.resize(size_t(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) img.pixels[3 * (size_t(y) * w + x) + c] = value(x, y) + 0.001f * c;
  std::string path = dir + "/" + name;
  write_image(path, img);
  return path;
}

// An 8-bit RGB PNG with the given bytes in every channel of a 1-row image.
std::string write_png_row(const std::string& dir, const std::string& name, const std::vector<uint8_t>& row) {
  std::string path = dir + "/" + name;
  auto out = OIIO::ImageOutput::create(path);
  OIIO::ImageSpec spec(static_cast<int>(row.size()), 1, 3, OIIO::TypeDesc::UINT8);
  out->open(path, spec);
  std::vector<uint8_t> px;
  for (uint8_t b : row) px.insert(px.end(), {b, b, b});
  out->write_image(OIIO::TypeDesc::UINT8, px.data());
  out->close();
  return path;
}

struct Textures {
  Registry registry{Registry::default_search_dirs()};
  BuiltScene built;
  explicit Textures(const std::string& directives) {
    SceneDescription d = parse_scene_string("WorldBegin\n" + directives, "imagemap.pbrt");
    d.film.params.set_int("xresolution", 4);
    d.film.params.set_int("yresolution", 4);
    built = build_scene(d, registry);
  }
  const FloatTexture& f(const std::string& name) const { return *built.texture_table.find_float(name); }
  const SpectrumTexture& s(const std::string& name) const { return *built.texture_table.find_spectrum(name); }
};

// The (u, v) of texel (x, y)'s centre in a w x h image: v runs upwards, rows downwards.
TextureEvalContext texel_centre(float x, float y, int w, int h) {
  TextureEvalContext c;
  c.uv = Vec2((x + 0.5f) / w, 1.f - (y + 0.5f) / h);
  return c;
}

float texel_value(int x, int y) { return 1.f + x + 4.f * y; }  // the 4x4 test image

}  // namespace

class Imagemap : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::temp_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    grid_ = write_float_image(dir_, "grid.exr", 4, 4, texel_value);
  }
  std::string texture(const std::string& name, const std::string& file, const std::string& extra, bool spectrum = false) {
    return fmt::format("Texture \"{}\" \"{}\" \"imagemap\" \"string filename\" \"{}\" {}\n", name,
                       spectrum ? "spectrum" : "float", file, extra);
  }
  std::string dir_, grid_;
};

TEST_F(Imagemap, PointFilterReturnsTheTexelAtItsCentre) {
  Textures t(texture("g", grid_, R"("string filter" "point")", true));
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      Rgb v = t.s("g").evaluate(texel_centre(x, y, 4, 4));
      EXPECT_FLOAT_EQ(v.r, texel_value(x, y));
      EXPECT_FLOAT_EQ(v.b, texel_value(x, y) + 0.002f);
    }
}

// Outside [0, 1]: repeat wraps around, clamp holds the edge texel, black is zero.
TEST_F(Imagemap, WrapModesOutsideTheImage) {
  Textures t(texture("r", grid_, R"("string filter" "point" "string wrap" "repeat")") +
             texture("c", grid_, R"("string filter" "point" "string wrap" "clamp")") +
             texture("b", grid_, R"("string filter" "point" "string wrap" "black")"));
  TextureEvalContext c = texel_centre(5, 2, 4, 4);  // one texel right of the image's texel 4 = 0
  EXPECT_FLOAT_EQ(t.f("r").evaluate(c), texel_value(1, 2) + 0.001f);  // float: mean of R, G, B
  EXPECT_FLOAT_EQ(t.f("c").evaluate(c), texel_value(3, 2) + 0.001f);
  EXPECT_FLOAT_EQ(t.f("b").evaluate(c), 0.f);
  c = texel_centre(-1, -2, 4, 4);
  EXPECT_FLOAT_EQ(t.f("r").evaluate(c), texel_value(3, 2) + 0.001f);
  EXPECT_FLOAT_EQ(t.f("c").evaluate(c), texel_value(0, 0) + 0.001f);
  EXPECT_FLOAT_EQ(t.f("b").evaluate(c), 0.f);
}

// Bilinear: halfway between texel centres the value is their mean; at the image's edge the texel
// beyond comes from the wrap mode.
TEST_F(Imagemap, BilinearBetweenTexelCentres) {
  Textures t(texture("r", grid_, R"("string filter" "bilinear")") +
             texture("c", grid_, R"("string filter" "bilinear" "string wrap" "clamp")") +
             texture("b", grid_, R"("string filter" "bilinear" "string wrap" "black")"));
  auto at = [](float x, float y) { return texel_centre(x, y, 4, 4); };
  const float g = 0.001f;  // the mean of the channels' offsets
  EXPECT_NEAR(t.f("r").evaluate(at(1.5f, 2.f)), 0.5f * (texel_value(1, 2) + texel_value(2, 2)) + g, 1e-5f);
  EXPECT_NEAR(t.f("r").evaluate(at(1.25f, 1.5f)),
              0.375f * (texel_value(1, 1) + texel_value(1, 2)) + 0.125f * (texel_value(2, 1) + texel_value(2, 2)) + g, 1e-5f);
  // u = 0: halfway between texel -1 and texel 0 of row 1.
  EXPECT_NEAR(t.f("r").evaluate(at(-0.5f, 1.f)), 0.5f * (texel_value(3, 1) + texel_value(0, 1)) + g, 1e-5f);
  EXPECT_NEAR(t.f("c").evaluate(at(-0.5f, 1.f)), texel_value(0, 1) + g, 1e-5f);
  EXPECT_NEAR(t.f("b").evaluate(at(-0.5f, 1.f)), 0.5f * (texel_value(0, 1) + g), 1e-5f);
}

// Trilinear on an 8x8 image: level 1 (4x4) and level 2 (2x2) are built here by 2x2 box averages.
// A footprint of width w picks level 3 + log2(w); at 1.25 the value is 3/4 of level 1's bilinear
// value plus 1/4 of level 2's. Between levels 0 and 1, pbrt-v4 uses level 0 alone.
TEST_F(Imagemap, TrilinearBlendsTheTwoLevelsAroundTheFootprint) {
  auto v0 = [](int x, int y) { return float((x * 7 + y * 3) % 11); };
  std::string file = write_float_image(dir_, "mip.exr", 8, 8, v0);
  std::vector<std::vector<float>> level1(4, std::vector<float>(4)), level2(2, std::vector<float>(2));
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x)
      level1[y][x] = 0.25f * (v0(2 * x, 2 * y) + v0(2 * x + 1, 2 * y) + v0(2 * x, 2 * y + 1) + v0(2 * x + 1, 2 * y + 1));
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x)
      level2[y][x] = 0.25f * (level1[2 * y][2 * x] + level1[2 * y][2 * x + 1] + level1[2 * y + 1][2 * x] + level1[2 * y + 1][2 * x + 1]);
  auto bilerp = [](const std::vector<std::vector<float>>& l, float s, float t) {  // repeat wrap
    int n = static_cast<int>(l.size());
    float x = s * n - 0.5f, y = t * n - 0.5f;
    int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    float dx = x - x0, dy = y - y0;
    auto at = [&](int xx, int yy) { return l[((yy % n) + n) % n][((xx % n) + n) % n]; };
    return (1 - dx) * (1 - dy) * at(x0, y0) + dx * (1 - dy) * at(x0 + 1, y0) + (1 - dx) * dy * at(x0, y0 + 1) +
           dx * dy * at(x0 + 1, y0 + 1);
  };
  Textures t(texture("tri", file, R"("string filter" "trilinear")"));
  float s = 0.37f, st = 0.61f;  // image (s, t), t from the top
  TextureEvalContext c;
  c.uv = Vec2(s, 1.f - st);
  float width = std::exp2(1.25f - 3.f);  // level 1.25
  c.dudx = width / 2.f;
  float want = 0.75f * bilerp(level1, s, st) + 0.25f * bilerp(level2, s, st) + 0.001f;
  EXPECT_NEAR(t.f("tri").evaluate(c), want, 1e-4f);
  // A 1 % error in the blend would show: the two levels differ by more than that here.
  EXPECT_GT(std::abs(bilerp(level1, s, st) - bilerp(level2, s, st)), 0.04f * want);
  // Wider than the image: the 1x1 level, the image's mean.
  c.dudx = 4.f;
  double mean = 0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) mean += v0(x, y) / 64.0;
  EXPECT_NEAR(t.f("tri").evaluate(c), mean + 0.001, 1e-4);
}

// EWA weighs texels by a Gaussian of their distance in the footprint's ellipse: normalised, so a
// constant image stays constant, and symmetric, so on a linear ramp the value at a point is the
// ramp's value there, however elongated the ellipse.
TEST_F(Imagemap, EwaIsANormalisedSymmetricAverage) {
  std::string flat = write_float_image(dir_, "flat.exr", 16, 16, [](int, int) { return 0.6f; });
  std::string ramp = write_float_image(dir_, "ramp.exr", 16, 16, [](int x, int) { return float(x); });
  Textures t(texture("flat", flat, R"("string filter" "ewa")") +
             texture("ramp", ramp, R"("string filter" "ewa" "string wrap" "clamp")"));
  TextureEvalContext c;
  c.uv = Vec2(0.5f, 0.5f);
  c.dudx = 0.05f, c.dvdx = 0.01f, c.dudy = -0.004f, c.dvdy = 0.12f;
  EXPECT_NEAR(t.f("flat").evaluate(c), 0.601f, 1e-5f);
  EXPECT_NEAR(t.f("ramp").evaluate(c), 7.5f + 0.001f, 1e-3f);  // the texel centres 7 and 8 straddle s = 0.5
  c.uv = Vec2(0.25f, 0.5f);
  EXPECT_NEAR(t.f("ramp").evaluate(c), 3.5f + 0.001f, 1e-3f);
}

// 8-bit files are decoded by "encoding": sRGB by default (reference values of the sRGB curve:
// 10 -> 0.0030353, 128 -> 0.2158605, 255 -> 1), linear as value / 255, "gamma 2.2" as its power.
TEST_F(Imagemap, EightBitEncodings) {
  std::string png = write_png_row(dir_, "row.png", {0, 10, 128, 255});
  Textures t(texture("srgb", png, R"("string filter" "point")") +
             texture("lin", png, R"("string filter" "point" "string encoding" "linear")") +
             texture("gam", png, R"("string filter" "point" "string encoding" "gamma 2.2")"));
  auto at = [](int x) { return texel_centre(x, 0, 4, 1); };
  EXPECT_NEAR(t.f("srgb").evaluate(at(0)), 0.f, 1e-7f);
  EXPECT_NEAR(t.f("srgb").evaluate(at(1)), 0.0030353f, 1e-6f);
  EXPECT_NEAR(t.f("srgb").evaluate(at(2)), 0.2158605f, 1e-6f);
  EXPECT_NEAR(t.f("srgb").evaluate(at(3)), 1.f, 1e-6f);
  EXPECT_NEAR(t.f("lin").evaluate(at(2)), 128.f / 255.f, 1e-6f);
  EXPECT_NEAR(t.f("gam").evaluate(at(2)), std::pow(128.f / 255.f, 2.2f), 1e-6f);
}

// Float files are linear whatever "encoding" says; scale multiplies and invert takes 1 - value.
TEST_F(Imagemap, FloatFilesScaleAndInvert) {
  std::string quarter = write_float_image(dir_, "q.exr", 2, 2, [](int, int) { return 0.25f; });
  Textures t(texture("a", quarter, R"("string encoding" "sRGB" "float scale" [ 3 ])") +
             texture("b", quarter, R"("float scale" [ 3 ] "bool invert" true)"));
  EXPECT_NEAR(t.f("a").evaluate(texel_centre(0, 0, 2, 2)), 3 * 0.251f, 1e-5f);
  EXPECT_NEAR(t.f("b").evaluate(texel_centre(0, 0, 2, 2)), 1.f - 3 * 0.251f, 1e-5f);
}

// Non-power-of-two images are resized up (level 0 becomes 4x4 here); the resampling keeps a
// constant image constant and the 1x1 level keeps the mean of a linear ramp.
TEST_F(Imagemap, NonPowerOfTwoImagesKeepTheirMean) {
  std::string ramp = write_float_image(dir_, "ramp3.exr", 3, 3, [](int x, int) { return float(x); });
  Textures t(texture("r", ramp, R"("string filter" "trilinear" "string wrap" "clamp")"));
  TextureEvalContext c;
  c.uv = Vec2(0.5f, 0.5f);
  EXPECT_NEAR(t.f("r").evaluate(c), 1.001f, 1e-5f);  // the centre of the ramp
  c.dudx = 2.f;                                      // the 1x1 level
  EXPECT_NEAR(t.f("r").evaluate(c), 1.001f, 1e-3f);
}

// One pyramid per (file, encoding, wrap): two textures of the same file share it, another wrap
// mode builds a second one, and a later scene naming the file again while it is alive builds none.
TEST_F(Imagemap, PyramidsAreBuiltOncePerFileAndSettings) {
  auto built = [&](const Object& o) {
    for (auto& [k, v] : o.statistics())
      if (k == "mipmaps_built_in_process") return v;
    return -1.0;
  };
  std::string other = write_float_image(dir_, "other.exr", 2, 2, [](int, int) { return 1.f; });
  Textures before(texture("z", other, ""));
  double count0 = built(before.f("z"));
  Textures t(texture("a", grid_, "") + texture("b", grid_, R"("string filter" "trilinear")", true) +
             texture("c", grid_, R"("string wrap" "clamp")"));
  EXPECT_EQ(built(t.f("c")), count0 + 2);
  Textures again(texture("d", grid_, "") + texture("e", grid_, R"("string wrap" "clamp")"));
  EXPECT_EQ(built(again.f("d")), count0 + 2);
  for (auto& [k, v] : t.f("a").statistics())
    if (k == "mipmap_levels") {
      EXPECT_EQ(v, 3.0);  // 4x4, 2x2, 1x1
    }
}

TEST_F(Imagemap, FilenameIsRelativeToTheSceneFile) {
  std::string scene = test::write_file(dir_, "sub/scene.pbrt",
                                       "WorldBegin\nTexture \"t\" \"float\" \"imagemap\" \"string filename\" \"rel.exr\"\n");
  write_float_image(dir_, "sub/rel.exr", 2, 2, [](int, int) { return 0.5f; });
  Registry registry(Registry::default_search_dirs());
  SceneDescription d = parse_scene_file(scene);
  BuiltScene b = build_scene(d, registry);
  EXPECT_NEAR(b.texture_table.find_float("t")->evaluate(texel_centre(0, 0, 2, 2)), 0.501f, 1e-5f);
}

TEST_F(Imagemap, BadSettingsAreLocatedErrors) {
  auto error_of = [&](const std::string& extra) -> std::string {
    try {
      Textures t(texture("t", grid_, extra));
    } catch (const Error& e) {
      return e.loc().str() + ": " + e.what();
    }
    return "no error";
  };
  // The error points at the offending parameter of line 2.
  std::string line = texture("t", grid_, R"("string filter" "gaussian")");
  size_t column = line.find(R"("string filter")") + 1;
  EXPECT_EQ(error_of(R"("string filter" "gaussian")"),
            fmt::format("imagemap.pbrt:2:{}: unknown filter \"gaussian\"; available: point, bilinear, trilinear, ewa", column));
  EXPECT_NE(error_of(R"("string wrap" "mirror")").find("unknown wrap mode \"mirror\"; available: repeat, black, clamp"),
            std::string::npos);
  EXPECT_NE(error_of(R"("string encoding" "gamma")").find("unknown encoding \"gamma\""), std::string::npos);
  try {
    Textures t("Texture \"t\" \"float\" \"imagemap\" \"string filename\" \"" + dir_ + "/none.png\"\n");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.loc().line, 2);
    EXPECT_EQ(e.loc().column, 32);  // the filename parameter
    EXPECT_NE(std::string(e.what()).find("none.png"), std::string::npos);
  }
}
