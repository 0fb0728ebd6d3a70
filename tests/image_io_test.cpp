// Image output: float formats keep linear values, 8-bit formats are encoded through the OpenColorIO
// display view, and every failure names the file involved.
#include "image/image_io.h"

#include <penumbra/error.h>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <optional>
#include <string>

#include <sys/resource.h>
#include <unistd.h>

namespace penumbra {
namespace {

namespace fs = std::filesystem;

// Sets an environment variable for one scope and restores the previous value.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_)
      setenv(name_, old_->c_str(), 1);
    else
      unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

// A fresh directory per test, removed afterwards. $OCIO is cleared so that a developer's own config
// does not change the expected code values.
class ImageIo : public ::testing::Test {
 protected:
  void SetUp() override {
    no_ocio_.emplace("OCIO", "");
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           (std::string("penumbra-image-io-") + info->name() + "-" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
  std::optional<ScopedEnv> no_ocio_;
};

// A 7x5 image whose pixels differ (to catch transposed or flipped rows) and span a wide range.
ImageRgb gradient() {
  ImageRgb img{7, 5, {}};
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      img.pixels.push_back(0.01f + 0.3f * x);
      img.pixels.push_back(std::pow(2.f, float(y) - 3.f));
      img.pixels.push_back(float(x * y) * 0.25f + 0.001f);
    }
  return img;
}

ImageRgb constant(float v, int w = 4, int h = 3) { return ImageRgb{w, h, std::vector<float>(size_t(w) * h * 3, v)}; }

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// 8-bit code values as stored in the file, read without any conversion.
std::vector<int> read_bytes(const std::string& path) {
  ImageRgb img = read_image(path);
  std::vector<int> codes;
  for (float v : img.pixels) codes.push_back(int(std::lround(v * 255.f)));
  return codes;
}

TEST_F(ImageIo, ExrRoundTripIsExactWithMetadataInHeader) {
  ImageRgb img = gradient();
  write_image(path("a.exr"), img, {{"penumbra:integrator", "path"}, {"penumbra:spp", "64"}});
  ImageRgb back = read_image(path("a.exr"));
  ASSERT_EQ(back.width, img.width);
  ASSERT_EQ(back.height, img.height);
  EXPECT_EQ(back.pixels, img.pixels);

  auto in = OIIO::ImageInput::open(path("a.exr"));
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().format, OIIO::TypeDesc::FLOAT);  // float, not half
  EXPECT_EQ(in->spec().get_string_attribute("penumbra:integrator"), "path");
  EXPECT_EQ(in->spec().get_string_attribute("penumbra:spp"), "64");
}

TEST_F(ImageIo, HdrRoundTripIsWithinRgbePrecision) {
  ImageRgb img = gradient();
  write_image(path("a.hdr"), img);
  ImageRgb back = read_image(path("a.hdr"));
  ASSERT_EQ(back.pixels.size(), img.pixels.size());
  // RGBE shares one exponent per pixel: each channel is good to 2^-8 of the pixel's largest one.
  for (size_t p = 0; p < img.pixels.size(); p += 3) {
    float largest = std::max({img.pixels[p], img.pixels[p + 1], img.pixels[p + 2]});
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(back.pixels[p + c], img.pixels[p + c], largest / 128.f) << p;
  }
}

TEST_F(ImageIo, TiffAndPfmRoundTripsAreExact) {
  ImageRgb img = gradient();
  for (const char* name : {"a.tif", "a.tiff", "a.pfm"}) {
    write_image(path(name), img);
    ImageRgb back = read_image(path(name));
    EXPECT_EQ(back.width, img.width) << name;
    EXPECT_EQ(back.height, img.height) << name;
    EXPECT_EQ(back.pixels, img.pixels) << name;
  }
}

TEST_F(ImageIo, PngStandardViewEncodesSrgb) {
  // sRGB encoding: 0.18 -> 1.055 * 0.18^(1/2.4) - 0.055 = 0.4614 -> 117.6 -> 118.
  for (auto [linear, code] : {std::pair{0.18f, 118}, {1.f, 255}, {0.f, 0}, {4.f, 255}, {-1.f, 0}}) {
    write_image(path("a.png"), constant(linear));
    for (int v : read_bytes(path("a.png"))) ASSERT_NEAR(v, code, 1) << linear;
  }
}

TEST_F(ImageIo, PngDefaultViewIsStandard) {
  write_image(path("default.png"), constant(0.18f));
  write_image(path("standard.png"), constant(0.18f), {}, "Standard");
  EXPECT_EQ(read_bytes(path("default.png")), read_bytes(path("standard.png")));
}

TEST_F(ImageIo, PngKeepsRowOrderAndChannels) {
  ImageRgb img{2, 2, {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1}};  // red, green / blue, white
  write_image(path("a.png"), img);
  EXPECT_EQ(read_bytes(path("a.png")), (std::vector<int>{255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255}));
}

TEST_F(ImageIo, FilmicViewCompressesHighlightsMonotonically) {
  // y = log2(1 + 6x) / log2(1 + 6 * 16.29), then the sRGB encoding (see data/ocio/config.ocio).
  auto expected_code = [](double x) {
    double y = std::log2(1.0 + 6.0 * x) * 0.1509271008;
    double e = y <= 0.0031308 ? 12.92 * y : 1.055 * std::pow(y, 1.0 / 2.4) - 0.055;
    return int(std::lround(std::clamp(e, 0.0, 1.0) * 255.0));
  };
  int previous = -1;
  for (float x : {0.f, 0.01f, 0.18f, 1.f, 4.f, 16.29f, 100.f}) {
    write_image(path("f.png"), constant(x), {}, "Filmic");
    int code = read_bytes(path("f.png"))[0];
    EXPECT_NEAR(code, expected_code(x), 1) << x;
    EXPECT_GE(code, previous) << x;
    previous = code;
  }
  EXPECT_EQ(expected_code(0.0), 0);
  EXPECT_LT(expected_code(1.0), 200);  // unlike Standard, white is not yet clipped
}

TEST_F(ImageIo, JpegWritesThroughTheDisplayView) {
  write_image(path("a.jpg"), constant(0.18f, 16, 16));
  for (int v : read_bytes(path("a.jpg"))) ASSERT_NEAR(v, 118, 2);  // JPEG is lossy, but flat is flat
}

TEST_F(ImageIo, UnknownViewIsAnErrorListingTheViews) {
  std::string msg = error_of([&] { write_image(path("a.png"), constant(0.5f), {}, "Cinematic"); });
  EXPECT_NE(msg.find("a.png"), std::string::npos) << msg;
  EXPECT_NE(msg.find("Cinematic"), std::string::npos) << msg;
  EXPECT_NE(msg.find("Standard, Filmic"), std::string::npos) << msg;
}

TEST_F(ImageIo, UnknownExtensionIsAnErrorListingSupportedOnes) {
  std::string msg = error_of([&] { write_image(path("render.bmpx"), constant(0.5f)); });
  EXPECT_NE(msg.find("render.bmpx"), std::string::npos) << msg;
  EXPECT_NE(msg.find(".exr"), std::string::npos) << msg;
  EXPECT_NE(msg.find(".png"), std::string::npos) << msg;
  EXPECT_FALSE(fs::exists(path("render.bmpx")));
}

TEST_F(ImageIo, ExtensionMatchingIgnoresCase) {
  write_image(path("A.EXR"), constant(0.5f));
  EXPECT_EQ(read_image(path("A.EXR")).pixels, constant(0.5f).pixels);
}

TEST_F(ImageIo, WriteFailureNamesTheFile) {
  for (const char* name : {"out.exr", "out.png", "out.pfm"}) {
    std::string target = path(std::string("no/such/dir/") + name);
    std::string msg = error_of([&] { write_image(target, constant(0.5f)); });
    EXPECT_NE(msg.find(target), std::string::npos) << msg;
  }
}

TEST_F(ImageIo, MalformedImageIsAnError) {
  ImageRgb bad{4, 4, std::vector<float>(10, 0.f)};
  std::string msg = error_of([&] { write_image(path("bad.exr"), bad); });
  EXPECT_NE(msg.find("bad.exr"), std::string::npos) << msg;
}

TEST_F(ImageIo, MissingFileOnReadNamesTheFile) {
  std::string missing = path("missing.exr");
  std::string msg = error_of([&] { read_image(missing); });
  EXPECT_NE(msg.find(missing), std::string::npos) << msg;
}

TEST(OcioConfig, ShippedConfigLoadsAndValidates) {
  EXPECT_NO_THROW(check_ocio_config(PENUMBRA_SOURCE_DIR "/data/ocio/config.ocio"));
}

TEST(OcioConfig, ShippedConfigIsFoundWithoutOcioVariable) {
  // Either the install-tree copy next to the executable or the source tree's: both must validate.
  ScopedEnv env("OCIO", "");
  std::string found = ocio_config_path();
  EXPECT_EQ(fs::path(found).filename(), "config.ocio");
  EXPECT_NO_THROW(check_ocio_config(found)) << found;
}

TEST_F(ImageIo, OcioVariablePointingToMissingFileIsAClearError) {
  std::string missing = path("nowhere/config.ocio");
  ScopedEnv env("OCIO", missing);
  EXPECT_EQ(ocio_config_path(), missing);
  std::string msg = error_of([&] { write_image(path("a.png"), constant(0.5f)); });
  EXPECT_NE(msg.find(missing), std::string::npos) << msg;
  EXPECT_NE(msg.find("$OCIO"), std::string::npos) << msg;
}

TEST_F(ImageIo, OcioVariableSelectsAnotherConfig) {
  // A copy of the shipped config whose Standard view is replaced by an identity display: 0.5 stays
  // 0.5 (code 128) instead of being sRGB-encoded (188).
  std::ifstream src(PENUMBRA_SOURCE_DIR "/data/ocio/config.ocio");
  std::string text((std::istreambuf_iterator<char>(src)), std::istreambuf_iterator<char>());
  std::string from = "from_display_reference: !<ExponentWithLinearTransform> {gamma: 2.4, offset: 0.055, direction: inverse}";
  size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, from.size(), "from_display_reference: !<MatrixTransform> {}");
  std::ofstream(path("identity.ocio")) << text;

  ScopedEnv env("OCIO", path("identity.ocio"));
  write_image(path("a.png"), constant(0.5f));
  for (int v : read_bytes(path("a.png"))) ASSERT_NEAR(v, 128, 1);
}

TEST_F(ImageIo, HeadersClaimingHugeImagesAreRefusedBeforeAllocating) {
  // A 100000 x 100000 PFM header over 64 bytes of data: 120 GB of floats if believed.
  std::ofstream(path("huge.pfm"), std::ios::binary) << "PF\n100000 100000\n-1.0\n" << std::string(64, '\0');
  std::string message = error_of([&] { read_image(path("huge.pfm")); });
  EXPECT_NE(message.find("huge.pfm': 100000x100000 pixels with 3 channels is outside what Penumbra reads"),
            std::string::npos)
      << message;
  // Control: a small image of the same format reads.
  write_image(path("small.pfm"), gradient());
  EXPECT_EQ(read_image(path("small.pfm")).width, gradient().width);
}

// The process's peak resident memory so far, in MiB (Linux reports ru_maxrss in KiB).
double peak_rss_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) / 1024.0;
}

// An OpenEXR file of 64 bytes whose first attribute, a string, claims 1.8 GiB of data. OpenEXR's C++
// reader allocated and zeroed the claimed size before finding the file too short (scripts/fuzz.sh
// image, 1 Dec); the core reader refuses it from the sizes.
std::string exr_with_huge_attribute() {
  std::string bytes("\x76\x2f\x31\x01\x02\x00\x00\x00", 8);  // magic, version 2, single part
  bytes += std::string("comments\0string\0", 16);
  bytes += std::string("\x00\x00\x00\x70", 4);  // size 0x70000000, little-endian
  bytes += std::string(36, 'a');
  return bytes;
}

// Reads `file`, which must be refused with an error naming it, and returns how far the peak memory
// grew meanwhile, in MiB. A valid image of the same format is read first, so that loading
// OpenImageIO's format plugin is not counted.
double growth_refusing(const std::string& file, const std::string& warm_up) {
  write_image(warm_up, gradient());
  read_image(warm_up);
  double before = peak_rss_mib();
  std::string message = error_of([&] { read_image(file); });
  double grown = peak_rss_mib() - before;
  EXPECT_NE(message.find("cannot read image '" + file + "'"), std::string::npos) << message;
  return grown;
}

TEST_F(ImageIo, ExrHeaderClaimingHugeAttributeIsRefusedWithoutAllocatingIt) {
  std::ofstream(path("attribute.exr"), std::ios::binary) << exr_with_huge_attribute();
  double before = peak_rss_mib();
  double grown = growth_refusing(path("attribute.exr"), path("warm.exr"));
  EXPECT_LT(grown, 256.0) << "peak memory grew by " << grown << " MiB reading a 64-byte file";
  // Control for the measurement: touching 512 MiB shows as growth.
  std::vector<char> touched(size_t(512) << 20, 1);
  EXPECT_GT(peak_rss_mib() - before, 400.0) << int(touched[touched.size() / 2]);
}

TEST_F(ImageIo, TruncatedFileClaimingLargeImageFailsBeforeAllocatingIt) {
  // 16384 x 8192 floats (1.5 GiB as RGB, the largest image read) claimed over 512 KiB of data (more
  // than 1/4096 of it): the header is believed, but the reader fills its buffer only with the rows
  // it decodes.
  std::ofstream(path("large.pfm"), std::ios::binary) << "PF\n16384 8192\n-1.0\n" << std::string(524288, '\0');
  double grown = growth_refusing(path("large.pfm"), path("warm.pfm"));
  EXPECT_LT(grown, 256.0) << "peak memory grew by " << grown << " MiB reading a 512 KiB file";
  EXPECT_EQ(error_of([&] { read_image(path("large.pfm")); }).find("its header claims"), std::string::npos);
}

// The bytes of a 20 x 12 ZIP-compressed OpenEXR file (one chunk of 16 rows holds all 12) whose data
// window is then widened to `width` columns, as a fuzzer's mutation did: the header stays consistent
// (still one chunk), the chunk's data is far too short.
std::string exr_widened_to(const std::string& file, int width) {
  ImageRgb img{20, 12, std::vector<float>(20 * 12 * 3, 0.5f)};
  write_image(file, img);
  std::ifstream in(file, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string key("dataWindow\0box2i\0", 17);
  size_t at = bytes.find(key);
  if (at == std::string::npos) return "";
  size_t xmax = at + key.size() + 4 + 8;  // after the size field and xMin, yMin
  for (int i = 0; i < 4; ++i) bytes[xmax + i] = char(((width - 1) >> (8 * i)) & 0xff);
  return bytes;
}

TEST_F(ImageIo, ExrClaimingAWideImageIsRefusedOrFailsWithoutAllocatingIt) {
  // Found by scripts/fuzz.sh image in CI (6 Dec): 18175319 x 12 float RGB is 2.6 GB, which the reader
  // allocated at once (a band of 64 rows held the whole image). Now refused from the header.
  std::string wide = exr_widened_to(path("wide.exr"), 18175319);
  ASSERT_FALSE(wide.empty());
  std::ofstream(path("wide.exr"), std::ios::binary) << wide;
  std::string message = error_of([&] { read_image(path("wide.exr")); });
  EXPECT_NE(message.find("wide.exr': 18175319x12 pixels with 3 channels is outside what Penumbra reads"),
            std::string::npos)
      << message;
  // Under those limits (8,000,000 x 12: 1.1 GB as RGB floats) the header is believed, but 1.1 GB of
  // pixels from a 2.6 KB file is more than any codec compresses: refused before a decoder allocates
  // its chunk (which peaked at 2.2 GB under scripts/fuzz.sh).
  std::string believed = exr_widened_to(path("believed.exr"), 8000000);
  std::ofstream(path("believed.exr"), std::ios::binary) << believed;
  double grown = growth_refusing(path("believed.exr"), path("warm.exr"));
  EXPECT_LT(grown, 64.0) << "peak memory grew by " << grown << " MiB reading a " << believed.size() << "-byte file";
  message = error_of([&] { read_image(path("believed.exr")); });
  EXPECT_NE(message.find("believed.exr': its header claims 1099 MiB of pixel data (8000000x12 pixels, 3 channels)"),
            std::string::npos)
      << message;
  // Control: a valid EXR from the same writer reads (growth_refusing() wrote warm.exr).
  EXPECT_EQ(read_image(path("warm.exr")).width, gradient().width);
}

// A 37 x 150 image with distinct pixels: more rows than one read band (64) and a width that is not a
// multiple of the tile size.
ImageRgb tall_image() {
  ImageRgb img{37, 150, {}};
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < 3; ++c) img.pixels.push_back(float(x) + 100.f * float(y) + 0.25f * float(c));
  return img;
}

TEST_F(ImageIo, ScanlineAndTiledFilesReadBandByBandExactly) {
  ImageRgb img = tall_image();
  write_image(path("scanline.exr"), img);
  EXPECT_EQ(read_image(path("scanline.exr")).pixels, img.pixels);
  for (int tile : {16, 48, 200}) {
    OIIO::ImageSpec spec(img.width, img.height, 3, OIIO::TypeDesc::FLOAT);
    spec.tile_width = spec.tile_height = tile;
    std::string name = path("tiled" + std::to_string(tile) + ".exr");
    auto out = OIIO::ImageOutput::create(name);
    ASSERT_TRUE(out && out->open(name, spec) && out->write_image(OIIO::TypeDesc::FLOAT, img.pixels.data()) &&
                out->close());
    auto in = OIIO::ImageInput::open(name);
    ASSERT_EQ(in->spec().tile_width, tile);  // really tiled
    ImageRgb back = read_image(name);
    ASSERT_EQ(back.width, img.width);
    ASSERT_EQ(back.height, img.height);
    EXPECT_EQ(back.pixels, img.pixels) << "tile " << tile;
  }
}

}  // namespace
}  // namespace penumbra
