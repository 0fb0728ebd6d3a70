// No silent results: every class of bad input of issue 16 ends with a message that names the option
// or the file (file:line:col where there is one) and a non-zero exit, or, for scenes that would
// render black, a warning that --strict turns into an error. Readers refuse devices and FIFOs;
// quotes of scene lines are bounded and never show a file that is not a scene.
#include "support/command.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <fmt/core.h>

#include <sys/stat.h>

#include <cstring>
#include <filesystem>

using namespace penumbra;
using ::testing::HasSubstr;
using ::testing::Not;
namespace fs = std::filesystem;

namespace {

const std::string kCornell = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt";
// A reader that blocks or runs forever is stopped here and shows as exit code 124.
const std::string kTimeout = "timeout 30";

const std::string kCamera = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\n"
                            "Film \"rgb\" \"integer xresolution\" [ 8 ] \"integer yresolution\" [ 8 ]\n";
const std::string kLight = "LightSource \"point\" \"point3 from\" [ 0 0 5 ] \"rgb I\" [ 10 10 10 ]\n";

test::CommandResult render_scene(const std::string& dir, const std::string& text, std::vector<std::string> extra = {}) {
  std::string scene = test::write_file(dir, "scene.pbrt", text);
  std::vector<std::string> args = {"render", scene, "-o", dir + "/out.exr", "--spp", "1", "-q"};
  args.insert(args.end(), extra.begin(), extra.end());
  return test::run_penumbra(args, kTimeout);
}

std::string base64(const std::string& data) {
  static const char* chars = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < data.size(); i += 3) {
    auto byte = [&](size_t k) { return k < data.size() ? static_cast<uint32_t>(static_cast<unsigned char>(data[k])) : 0u; };
    uint32_t v = byte(i) << 16 | byte(i + 1) << 8 | byte(i + 2);
    out += chars[v >> 18 & 63];
    out += chars[v >> 12 & 63];
    out += i + 1 < data.size() ? chars[v >> 6 & 63] : '=';
    out += i + 2 < data.size() ? chars[v & 63] : '=';
  }
  return out;
}

template <typename T>
void append(std::string& out, T v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

// One triangle as glTF: positions then uint32 indices in one buffer, given by `uri`.
std::string triangle_gltf(const std::string& uri, size_t byte_length) {
  return fmt::format(R"({{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}], "nodes": [{{"mesh": 0}}],
  "meshes": [{{"name": "tri", "primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}}],
  "buffers": [{{"byteLength": {}, "uri": "{}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 36}}, {{"buffer": 0, "byteOffset": 36, "byteLength": 12}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}},
                {{"bufferView": 1, "componentType": 5125, "count": 3, "type": "SCALAR"}}]}})",
                     byte_length, uri);
}

std::string triangle_buffer(uint32_t last_index) {
  std::string buf;
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) append(buf, v);
  for (uint32_t i : {0u, 1u, last_index}) append(buf, i);
  return buf;
}

}  // namespace

// ---- scenes that render black ------------------------------------------------------------------

TEST(BadInput, ScenesThatRenderBlackWarnAndStrictMakesThemErrors) {
  struct Case {
    const char* name;
    std::string text, message;
  } cases[] = {
      {"empty", "", "scene file '{scene}' has no WorldBegin: it describes no world, so the image is black"},
      {"no-world", kCamera + "Sampler \"independent\"\n", "scene file '{scene}' has no WorldBegin"},
      {"nothing", kCamera + "WorldBegin\n", "nothing to render: the scene has no shapes and no light sources"},
      {"only-point-light", kCamera + "WorldBegin\n" + kLight, "nothing to render: the scene has no shapes"},
      {"no-light", kCamera + "WorldBegin\nShape \"sphere\"\n", "no light sources defined in the scene; rendering a black image"},
  };
  for (const Case& c : cases) {
    std::string dir = test::temp_dir(std::string("black-") + c.name);
    std::string message = c.message;
    if (size_t at = message.find("{scene}"); at != std::string::npos) message.replace(at, 7, dir + "/scene.pbrt");
    test::CommandResult r = render_scene(dir, c.text);
    EXPECT_EQ(r.exit_code, 0) << c.name << ": " << r.err;
    EXPECT_THAT(r.err, HasSubstr("warning: " + message)) << c.name;
    fs::remove(dir + "/out.exr");
    test::CommandResult strict = render_scene(dir, c.text, {"--strict"});
    EXPECT_EQ(strict.exit_code, 1) << c.name;
    EXPECT_THAT(strict.err, HasSubstr("error: " + message)) << c.name;
    EXPECT_THAT(strict.err, HasSubstr("(an error with --strict)")) << c.name;
    EXPECT_FALSE(fs::exists(dir + "/out.exr")) << c.name << ": --strict still rendered";
  }
  // Negative control: a lit scene with a shape gives none of them, with or without --strict.
  std::string dir = test::temp_dir("black-none");
  test::CommandResult r = render_scene(dir, kCamera + "WorldBegin\n" + kLight + "Shape \"sphere\"\n", {"--strict"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, Not(HasSubstr("warning")));
  // An environment light alone is something to render: the sky.
  r = render_scene(dir, kCamera + "WorldBegin\nLightSource \"infinite\" \"rgb L\" [ 0.5 0.5 0.5 ]\n", {"--strict"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, Not(HasSubstr("warning")));
}

// ---- numbers on the command line ---------------------------------------------------------------

TEST(BadInput, CommandLineNumbersAreValidatedWithRangesInWords) {
  struct Case {
    std::vector<std::string> args;
    std::string message;
  } cases[] = {
      {{"--spp", "0"}, "--spp: expected a positive whole number (at most 2^31 - 1), got '0', which is out of that range"},
      {{"--spp", "1.5"}, "--spp: expected a positive whole number (at most 2^31 - 1), got '1.5'"},
      {{"--spp", "99999999999"}, "--spp: expected a positive whole number (at most 2^31 - 1), got '99999999999', which is out of that range"},
      {{"--time", "nan"}, "--time: expected a positive number of seconds, got 'nan'"},
      {{"--time", "inf"}, "--time: expected a positive number of seconds, got 'inf', which is not finite"},
      {{"--time", "-2"}, "--time: expected a positive number of seconds, got '-2', which is not above zero"},
      {{"--time", "1e400"}, "--time: expected a positive number of seconds, got '1e400', which is not finite"},
      {{"--threads", "0"}, "--threads: expected a whole number of threads from 1 to 1024, got '0'"},
      {{"--nthreads", "5000"}, "--threads: expected a whole number of threads from 1 to 1024, got '5000'"},
      {{"--seed", "-1"}, "--seed: expected a whole number from 0 to 2^32 - 1, got '-1'"},
      {{"--firefly-threshold", "nan"}, "--firefly-threshold: expected a positive number, got 'nan'"},
      {{"--spp-total", "8", "--spp-offset", "-1"}, "--spp-offset: expected a whole number from 0 to 2^31 - 1, got '-1'"},
      {{"--res", "0x10"}, "--res: expected WIDTHxHEIGHT"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = {"render", kCornell, "-q"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    test::CommandResult r = test::run_penumbra(args);
    EXPECT_EQ(r.exit_code, 1) << c.message;
    EXPECT_THAT(r.err, HasSubstr(c.message));
    EXPECT_THAT(r.err, Not(HasSubstr("1797693134862315"))) << "a numeric bound of 309 digits";
    EXPECT_LT(r.err.size(), 300u) << r.err;
  }
  // Converge's numbers too.
  test::CommandResult r = test::run_penumbra({"converge", kCornell, "--configs", "path", "--time", "nan"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--time: expected a positive number of seconds, got 'nan'"));
}

// The programs beside penumbra read their numbers with the same validators and exit 2 on a bad one
// (they used atoi/atof: "64x" was 64, "abc" degrees were 0).
TEST(BadInput, ToolNumbersAreValidatedAsTheProgramsAre) {
  std::string dir = test::temp_dir("tool-numbers");
  std::string sky = dir + "/sky.exr";
  struct Case {
    std::vector<std::string> args;
    std::string message;
  } cases[] = {
      {{sky, "64x", "32"}, "width: expected a whole number from 8 to 65536, got '64x'"},
      {{sky, "4", "32"}, "width: expected a whole number from 8 to 65536, got '4', which is out of that range"},
      {{sky, "64", "32", "abc"}, "sun_elevation: expected a finite number of degrees, got 'abc'"},
      {{sky, "64", "32", "10", "nan"}, "sun_azimuth: expected a finite number of degrees, got 'nan'"},
      {{sky, "64", "32", "10", "20", "-5"}, "sun_radiance: expected a positive number, got '-5', which is not above zero"},
  };
  for (const Case& c : cases) {
    test::CommandResult r = test::run_tool("penumbra-make-sky", c.args);
    EXPECT_EQ(r.exit_code, 2) << c.message;
    EXPECT_THAT(r.err, HasSubstr(c.message));
    EXPECT_FALSE(fs::exists(sky)) << c.message;
  }
  // Control: good numbers (a negative elevation included) write the image.
  test::CommandResult r = test::run_tool("penumbra-make-sky", {sky, "16", "8", "-10", "20", "5"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(sky));
  // penumbra envmap --size is a whole number too (CLI11's PositiveNumber took 1e3 and 1.5).
  r = test::run_penumbra({"envmap", sky, dir + "/square.exr", "--to", "equalarea", "--size", "1.5"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--size: expected a positive whole number (at most 2^31 - 1), got '1.5'"));
  EXPECT_FALSE(fs::exists(dir + "/square.exr"));
}

// ---- pbrt's habits -----------------------------------------------------------------------------

TEST(BadInput, PbrtStyleCommandLineRendersTheScene) {
  std::string dir = test::temp_dir("pbrt-style");
  // pbrt --nthreads 2 --spp 4 --outfile x.exr scene.pbrt
  test::CommandResult r = test::run_penumbra({"--nthreads", "1", "--spp", "2", "--res", "8x8", "--outfile",
                                              dir + "/a.exr", "-q", kCornell});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(dir + "/a.exr"));
  r = test::run_penumbra({kCornell, "--spp", "1", "--res", "8x8", "-o", dir + "/b.exr", "-q"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(dir + "/b.exr"));
  // A scene that does not exist is still named as the render's scene.
  r = test::run_penumbra({dir + "/nope.pbrt"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr(dir + "/nope.pbrt"));
}

TEST(BadInput, ByteOrderMarkIsAccepted) {
  std::string dir = test::temp_dir("bom");
  test::CommandResult r = render_scene(dir, "\xEF\xBB\xBF" + kCamera + "WorldBegin\n" + kLight + "Shape \"sphere\"\n");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  // Columns count from after the mark.
  r = render_scene(dir, "\xEF\xBB\xBFLookAt 0 0 5 0 0 0 0 1 x\n");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("scene.pbrt:1:24: error:"));
}

// ---- quoting -----------------------------------------------------------------------------------

TEST(BadInput, LongLinesAreQuotedAroundTheColumnOnly) {
  std::string dir = test::temp_dir("long-line");
  std::string numbers;
  while (numbers.size() < 10'000'000) numbers += "0 0 0 ";
  // The error at the end of a 10 MB line: "..." before a window that ends the line, the caret under
  // the bad token.
  test::CommandResult r = render_scene(dir, kCamera + "WorldBegin\n" + kLight + "Shape \"trianglemesh\" \"point3 P\" [ " +
                                                numbers + "oops ]\n");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("scene.pbrt:6:"));
  EXPECT_LT(r.err.size(), 1000u) << "the quote of a 10 MB line is not bounded";
  size_t quote = r.err.find("\n    ");
  ASSERT_NE(quote, std::string::npos) << r.err;
  size_t quote_end = r.err.find('\n', quote + 1);
  std::string quoted = r.err.substr(quote + 5, quote_end - quote - 5);
  std::string caret_line = r.err.substr(quote_end + 5);
  EXPECT_EQ(quoted.substr(0, 3), "...");
  EXPECT_LE(quoted.size(), 210u);
  size_t caret = caret_line.find('^');
  ASSERT_NE(caret, std::string::npos);
  EXPECT_EQ(quoted.substr(caret, 4), "oops") << quoted;
  // The error near its start: the window starts the line and "..." ends it.
  r = render_scene(dir, kCamera + "WorldBegin\n" + kLight + "Shape \"trianglemesh\" \"float nope\" [ 1 ] \"point3 P\" [ " +
                            numbers + "]\n");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_LT(r.err.size(), 1000u);
  EXPECT_THAT(r.err, HasSubstr("scene.pbrt:6:22: error: unknown parameter 'nope'"));
  EXPECT_THAT(r.err, HasSubstr("    Shape \"trianglemesh\" \"float nope\" [ 1 ] \"point3 P\" [ 0 0 0"));
  EXPECT_THAT(r.err, HasSubstr("0...\n"));
}

TEST(BadInput, IncludedFilesThatAreNotScenesAreNotQuoted) {
  std::string dir = test::temp_dir("include-secret");
  test::write_file(dir, "secret.txt", "password=hunter2\n");
  test::write_file(dir, "key.txt", "\"hunter2\"\n");
  test::write_file(dir, "binary.dat", std::string("\x7f" "ELF\x02\x01\x01hunter2", 14));
  for (const char* file : {"secret.txt", "key.txt", "binary.dat"}) {
    test::CommandResult r = render_scene(dir, kCamera + "WorldBegin\nInclude \"" + std::string(file) + "\"\n");
    EXPECT_EQ(r.exit_code, 1) << file;
    EXPECT_THAT(r.err, HasSubstr(std::string(file) + ":1:1: error: '" + dir + "/" + file +
                                 "' does not look like a pbrt-v4 scene file"));
    EXPECT_THAT(r.err, Not(HasSubstr("hunter2"))) << file;
  }
  // A scene file with a typo in its first directive is a scene file: did-you-mean and the quote.
  test::write_file(dir, "typo.pbrt", "Shap \"sphere\"\n");
  test::CommandResult r = render_scene(dir, kCamera + "WorldBegin\nInclude \"typo.pbrt\"\n");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("typo.pbrt:1:1: error: unknown directive 'Shap'; did you mean 'Shape'?"));
  EXPECT_THAT(r.err, HasSubstr("    Shap \"sphere\""));
  // Lines that are not printable UTF-8 are not quoted, even in a scene file.
  test::write_file(dir, "control.pbrt", "Shape \"sphere\" \"float radius\" [ 1 ] \x1b[2J \"\n");
  r = render_scene(dir, kCamera + "WorldBegin\nInclude \"control.pbrt\"\n");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("control.pbrt:1:"));
  EXPECT_THAT(r.err, Not(HasSubstr("\x1b"))) << "a terminal escape sequence was quoted";
}

// ---- non-regular files -------------------------------------------------------------------------

TEST(BadInput, ReadersRefuseDevicesAndFifos) {
  std::string dir = test::temp_dir("non-regular");
  ASSERT_EQ(mkfifo((dir + "/fifo").c_str(), 0600), 0);
  fs::create_symlink("/dev/zero", dir + "/zero.ply");
  fs::create_symlink("/dev/zero", dir + "/zero.gltf");
  fs::create_symlink("/dev/zero", dir + "/zero.bin");
  fs::create_symlink(dir + "/fifo", dir + "/fifo.pbrt");
  fs::create_symlink(dir + "/fifo", dir + "/fifo.exr");
  test::write_file(dir, "buffer-zero.gltf", triangle_gltf("zero.bin", 48));
  struct Case {
    std::string world, message;
  } cases[] = {
      {"Shape \"plymesh\" \"string filename\" \"zero.ply\"\n",
       "scene.pbrt:6:17: error: PLY file '" + dir + "/zero.ply': cannot open the file: it is a character device, not a regular file"},
      {"Shape \"gltf\" \"string filename\" \"zero.gltf\"\n",
       "scene.pbrt:6:14: error: cannot read glTF file '" + dir + "/zero.gltf': it is a character device"},
      {"Shape \"gltf\" \"string filename\" \"buffer-zero.gltf\"\n", "it is a character device, not a regular file"},
      {"Include \"fifo.pbrt\"\n", "scene.pbrt:6:1: error: cannot read included file '" + dir + "/fifo.pbrt': it is a FIFO"},
      {"LightSource \"infinite\" \"string filename\" \"fifo.exr\"\n",
       "cannot read image '" + dir + "/fifo.exr': it is a FIFO (named pipe), not a regular file"},
  };
  for (const Case& c : cases) {
    test::CommandResult r = render_scene(dir, kCamera + "WorldBegin\n" + kLight + c.world);
    EXPECT_EQ(r.exit_code, 1) << c.world << r.err;  // 124: it hung
    EXPECT_THAT(r.err, HasSubstr(c.message));
  }
  test::CommandResult r = test::run_penumbra({"render", dir + "/fifo.pbrt"}, kTimeout);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("cannot read scene file '" + dir + "/fifo.pbrt': it is a FIFO"));
}

// ---- PLY and glTF ------------------------------------------------------------------------------

TEST(BadInput, PlyWithTheWrongEndiannessSaysSo) {
  std::string dir = test::temp_dir("ply-endian");
  for (const char* header_format : {"binary_big_endian", "binary_little_endian"}) {
    bool big = std::strcmp(header_format, "binary_big_endian") == 0;
    std::string body;
    auto put32 = [&](uint32_t v) {  // in the byte order the header does NOT say
      for (int k = 0; k < 4; ++k) body += static_cast<char>(big ? (v >> (8 * k)) & 0xff : (v >> (8 * (3 - k))) & 0xff);
    };
    for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) {
      uint32_t bits;
      std::memcpy(&bits, &f, 4);
      put32(bits);
    }
    body += '\3';
    for (uint32_t i : {0u, 1u, 2u}) put32(i);
    test::write_file(dir, "tri.ply",
                     fmt::format("ply\nformat {} 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                 "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n",
                                 header_format) + body);
    test::CommandResult r = render_scene(dir, kCamera + "WorldBegin\n" + kLight + "Shape \"plymesh\" \"string filename\" \"tri.ply\"\n");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_THAT(r.err, HasSubstr("scene.pbrt:6:17: error: PLY file '" + dir + "/tri.ply': vertex index"));
    EXPECT_THAT(r.err, HasSubstr(fmt::format("the header says {}, but the data look {}", header_format,
                                             big ? "little-endian" : "big-endian")));
  }
  // A plain out-of-range index in a correct file gets no such hint (negative control).
  std::string body;
  for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) append(body, f);
  body += '\3';
  for (int32_t i : {0, 1, 3}) append(body, i);
  test::write_file(dir, "tri.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                                   "property float y\nproperty float z\nelement face 1\n"
                                   "property list uchar int vertex_indices\nend_header\n" + body);
  test::CommandResult r = render_scene(dir, kCamera + "WorldBegin\n" + kLight + "Shape \"plymesh\" \"string filename\" \"tri.ply\"\n");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("vertex index 3 out of range (the mesh has 3 vertices)"));
  EXPECT_THAT(r.err, Not(HasSubstr("byte order")));
}

TEST(BadInput, PlyHeaderCountsAreBoundedByTheFile) {
  std::string dir = test::temp_dir("ply-count");
  test::write_file(dir, "huge.ply", "ply\nformat binary_little_endian 1.0\nelement junk 1000000000000000000\n"
                                    "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n");
  test::CommandResult r = render_scene(dir, kCamera + "WorldBegin\n" + kLight + "Shape \"plymesh\" \"string filename\" \"huge.ply\"\n");
  EXPECT_EQ(r.exit_code, 1) << r.err;  // 124: a loop of 10^18 empty items
  EXPECT_THAT(r.err, HasSubstr("the header declares 1000000000000000000 'junk' items, more than the 0 bytes after the header can hold"));
}

TEST(BadInput, GltfIndexErrorsAreUnsignedAndNameTheFile) {
  std::string dir = test::temp_dir("gltf-index");
  std::string buffer = triangle_buffer(0xFFFFFFFFu);
  test::write_file(dir, "tri.gltf", triangle_gltf("data:application/octet-stream;base64," + base64(buffer), buffer.size()));
  test::CommandResult r = render_scene(dir, kCamera + "WorldBegin\n" + kLight + "Shape \"gltf\" \"string filename\" \"tri.gltf\"\n");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("scene.pbrt:6:14: error: glTF file '" + dir + "/tri.gltf': mesh 'tri' primitive 0 "
                               "has index 4294967295, but only 3 vertices"));
  EXPECT_THAT(r.err, Not(HasSubstr("-2147483648")));
  // The same triangle with a good index renders (the check is not over-eager).
  buffer = triangle_buffer(2);
  test::write_file(dir, "tri.gltf", triangle_gltf("data:application/octet-stream;base64," + base64(buffer), buffer.size()));
  r = render_scene(dir, kCamera + "WorldBegin\n" + kLight + "Shape \"gltf\" \"string filename\" \"tri.gltf\"\n");
  EXPECT_EQ(r.exit_code, 0) << r.err;
}
