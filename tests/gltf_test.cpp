// glTF meshes: the same triangles given as glTF and as a trianglemesh render the same image bit for
// bit; node transforms compose; broken files are located errors naming the file.
#include "image/image_io.h"
#include "render/render_session.h"
#include "scene/gltf_loader.h"
#include "support/command.h"

#include <fmt/core.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <optional>

#include <cstring>

using namespace penumbra;
using namespace penumbra::test;
using ::testing::HasSubstr;

namespace {

std::string base64(const std::vector<unsigned char>& data) {
  static const char* chars = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < data.size(); i += 3) {
    uint32_t v = data[i] << 16 | (i + 1 < data.size() ? data[i + 1] << 8 : 0) | (i + 2 < data.size() ? data[i + 2] : 0);
    out += chars[v >> 18 & 63];
    out += chars[v >> 12 & 63];
    out += i + 1 < data.size() ? chars[v >> 6 & 63] : '=';
    out += i + 2 < data.size() ? chars[v & 63] : '=';
  }
  return out;
}

// The unit cube of scenes/cornell-box/unit-cube.pbrt.
const std::vector<float> kCubeP = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1};
const std::vector<uint32_t> kCubeIndices = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                            3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5};

// A glTF with one mesh (positions + uint32 indices) in a data-URI buffer. `nodes` is the JSON of
// the node list; `mode` the primitive mode; `byte_length` lets a test truncate the buffer;
// `first_index` replaces the first vertex index.
std::string cube_gltf(const std::string& nodes, int mode = 4, int truncate_bytes = 0,
                      std::optional<uint32_t> first_index = std::nullopt) {
  std::vector<unsigned char> buf(kCubeP.size() * 4 + kCubeIndices.size() * 4);
  std::memcpy(buf.data(), kCubeP.data(), kCubeP.size() * 4);
  std::memcpy(buf.data() + kCubeP.size() * 4, kCubeIndices.data(), kCubeIndices.size() * 4);
  if (first_index) std::memcpy(buf.data() + kCubeP.size() * 4, &*first_index, 4);
  size_t pbytes = kCubeP.size() * 4, ibytes = kCubeIndices.size() * 4;
  return fmt::format(R"({{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0]}}],
  "nodes": {},
  "meshes": [{{"name": "cube", "primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "mode": {}}}]}}],
  "buffers": [{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": {}}}, {{"buffer": 0, "byteOffset": {}, "byteLength": {}}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [-1,-1,-1], "max": [1,1,1]}},
    {{"bufferView": 1, "componentType": 5125, "count": 36, "type": "SCALAR"}}]
}})",
                     nodes, mode, buf.size(), base64(buf), pbytes, pbytes, ibytes - truncate_bytes);
}

std::string scene_around(const std::string& shape) {
  return R"(
Scale -1 1 1
LookAt 3 4 5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 48 ] "integer yresolution" [ 32 ]
Sampler "independent" "integer pixelsamples" [ 8 ]
Integrator "path" "integer maxdepth" [ 3 ]
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 4 4 4 ]
  Translate 0 5 0
  Shape "sphere" "float radius" [ 0.5 ]
AttributeEnd
Material "diffuse" "rgb reflectance" [ 0.6 0.5 0.4 ]
Translate 0.2 0 -0.1
Rotate 20 0 1 0
)" + shape;
}

RenderResult render_file(const std::string& path) {
  RenderSettings s;
  s.scene_file = path;
  s.quiet = true;
  return render(s);
}

}  // namespace

TEST(Gltf, SameTrianglesAsTrianglemeshRenderBitIdentical) {
  std::string dir = temp_dir("gltf-equal");
  write_file(dir, "cube.gltf", cube_gltf(R"([{"mesh": 0}])"));
  std::string indices;
  for (uint32_t i : kCubeIndices) indices += std::to_string(i) + " ";
  std::string points;
  for (float p : kCubeP) points += fmt::format("{} ", p);
  std::string mesh = "Shape \"trianglemesh\" \"point3 P\" [ " + points + "] \"integer indices\" [ " + indices + "]\n";
  RenderResult a = render_file(write_file(dir, "mesh.pbrt", scene_around(mesh)));
  RenderResult b = render_file(write_file(dir, "shape.pbrt", scene_around("Shape \"gltf\" \"string filename\" [ \"cube.gltf\" ]\n")));
  RenderResult c = render_file(write_file(dir, "import.pbrt", scene_around("Import \"cube.gltf\"\n")));
  ASSERT_EQ(a.image.pixels.size(), b.image.pixels.size());
  EXPECT_EQ(a.image.pixels, b.image.pixels);
  EXPECT_EQ(a.image.pixels, c.image.pixels);
  EXPECT_EQ(b.stats.triangles, 12u + 0u);
}

TEST(Gltf, NodeTransformsCompose) {
  std::string dir = temp_dir("gltf-nodes");
  // Parent: translate (10, 0, 0); child: scale 2 then rotate 90 degrees about z.
  std::string nodes = R"([{"translation": [10, 0, 0], "children": [1]},
                          {"mesh": 0, "rotation": [0, 0, 0.7071067811865476, 0.7071067811865476], "scale": [2, 2, 2]}])";
  std::string path = write_file(dir, "nodes.gltf", cube_gltf(nodes));
  auto prims = load_gltf(path, {});
  ASSERT_EQ(prims.size(), 1u);
  // Vertex 1 = (1, -1, -1): scaled (2, -2, -2), rotated 90 deg about z -> (2, 2, -2), translated -> (12, 2, -2).
  EXPECT_NEAR(prims[0].P[1].x, 12.f, 1e-5f);
  EXPECT_NEAR(prims[0].P[1].y, 2.f, 1e-5f);
  EXPECT_NEAR(prims[0].P[1].z, -2.f, 1e-5f);
  EXPECT_EQ(prims[0].indices.size(), 36u);
  EXPECT_FALSE(prims[0].material);
}

TEST(Gltf, BrokenFilesAreLocatedErrorsNamingTheFile) {
  std::string dir = temp_dir("gltf-errors");
  auto expect_error = [&](const std::string& name, const std::string& gltf, const std::string& message) {
    if (!gltf.empty()) write_file(dir, name, gltf);
    std::string scene = "Camera \"perspective\"\nWorldBegin\nShape \"gltf\" \"string filename\" [ \"" + name + "\" ]\n";
    auto r = run_penumbra({"render", write_file(dir, name + ".pbrt", scene), "-o", dir + "/o.exr", "-q"});
    EXPECT_EQ(r.exit_code, 1) << name;
    EXPECT_THAT(r.err, HasSubstr(".pbrt:3:14: error: glTF file '"));
    EXPECT_THAT(r.err, HasSubstr(name));
    EXPECT_THAT(r.err, HasSubstr(message));
  };
  expect_error("missing.gltf", "", "does not exist");
  expect_error("lines.gltf", cube_gltf(R"([{"mesh": 0}])", 1), "has mode 1; only triangles (4) are supported");
  expect_error("short.gltf", cube_gltf(R"([{"mesh": 0}])", 4, 8), "reads past the end of its buffer");
  expect_error("garbage.gltf", "{ not json", "cannot be read");
  // Unsigned indices are reported as such (not as a negative int) and against the vertex count.
  expect_error("index.gltf", cube_gltf(R"([{"mesh": 0}])", 4, 0, 0xFFFFFFFFu),
               "mesh 'cube' primitive 0 has index 4294967295, but only 8 vertices");
  expect_error("index8.gltf", cube_gltf(R"([{"mesh": 0}])", 4, 0, 8u), "has index 8, but only 8 vertices");
  // A NORMAL accessor with fewer elements than POSITION (found by the fuzzer: the mesh would have
  // been read past its normals).
  auto replace = [](std::string s, const std::string& from, const std::string& to) {
    size_t at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return at == std::string::npos ? s : s.replace(at, from.size(), to);
  };
  std::string cube = cube_gltf(R"([{"mesh": 0}])");
  std::string normals = replace(replace(cube, R"("POSITION": 0})", R"("POSITION": 0, "NORMAL": 2})"),
                                R"("type": "SCALAR"}])",
                                R"("type": "SCALAR"}, {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"}])");
  expect_error("normals.gltf", normals, "mesh 'cube' primitive 0 has 4 NORMAL values but 8 positions");
  // Index and vertex counts that are not whole triangles (found by the fuzzer).
  expect_error("count35.gltf", replace(cube, R"("count": 36,)", R"("count": 35,)"),
               "mesh 'cube' primitive 0 has 35 indices, not a multiple of 3 for triangles");
  expect_error("noindices.gltf", replace(cube, R"("indices": 1, )", ""),
               "mesh 'cube' primitive 0 has 8 vertices (and no indices), not a multiple of 3 for triangles");
  // A count so large that count x stride wraps around 64 bits is still past the end.
  expect_error("count.gltf", replace(cube, R"("count": 8,)", R"("count": 1537228672809129302,)"),
               "reads past the end of its buffer");
  // 40 nodes that each name the next one twice: 2^40 node instances (the last node has no mesh, so
  // that the test does not copy one a million times before the limit).
  std::string chain = "[{\"mesh\": 0, \"children\": [1]}, ";
  for (int i = 1; i < 40; ++i) chain += fmt::format(R"({{"children": [{}, {}]}}, )", i + 1, i + 1);
  chain += "{}]";
  expect_error("chain.gltf", cube_gltf(chain), "the node tree expands to more than 1000000 node instances");
}
