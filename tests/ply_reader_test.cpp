// The PLY reader: ascii and binary encodings, the property spellings pbrt scenes use, polygon
// splitting, skipping what it does not need, errors, and the real meshes of the pbrt-v4 scenes.
#include "parser/ply_reader.h"

#include <fmt/core.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;

const std::string kScenes = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/pbrt-v4/";

FileLoc test_loc() {
  return FileLoc{std::make_shared<const std::string>("scene.pbrt"), nullptr, 7, 5};
}

class PlyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("penumbra-ply-" + std::string(info->name()) + "-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& bytes, const std::string& name = "mesh.ply") {
    std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }
  TriangleMeshData read(const std::string& bytes) { return read_ply(write(bytes), test_loc()); }
  // The formatted error, checked to be located at the scene parameter and to name the file.
  std::string error(const std::string& bytes) {
    std::string path = write(bytes);
    try {
      read_ply(path, test_loc());
    } catch (const Error& e) {
      EXPECT_THAT(e.formatted(),
                  HasSubstr(fmt::format("scene.pbrt:7:5: error: PLY file '{}': ", path)));
      return e.formatted();
    }
    return "(no error)";
  }

  fs::path dir_;
};

// Appends the bytes of `v` in the requested byte order.
template <typename T>
void put(std::string& out, T v, bool little_endian) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (little_endian != (std::endian::native == std::endian::little)) std::reverse(b, b + sizeof(T));
  out.append(b, sizeof(T));
}

const char* kAsciiQuad = R"(ply
format ascii 1.0
comment a unit quad
element vertex 4
property float x
property float y
property float z
element face 1
property list uchar int vertex_indices
end_header
0 0 0
1 0 0
1 1 0
0 1 0
4 0 1 2 3
)";

// ---------------------------------------------------------------------------------------------

TEST_F(PlyTest, AsciiQuadIsSplitAlongItsFirstDiagonal) {
  auto m = read(kAsciiQuad);
  ASSERT_EQ(m.P.size(), 4u);
  EXPECT_EQ(m.P[2], Vec3(1, 1, 0));
  EXPECT_THAT(m.indices, ElementsAre(0, 1, 2, 0, 2, 3));
  EXPECT_TRUE(m.N.empty());
  EXPECT_TRUE(m.uv.empty());
}

TEST_F(PlyTest, PolygonsAreFanTriangulatedAndTrianglesKept) {
  auto m = read(R"(ply
format ascii 1.0
element vertex 5
property float x
property float y
property float z
element face 2
property list uchar int vertex_index
end_header
0 0 0  1 0 0  2 1 0  1 2 0  0 1 0
5 0 1 2 3 4
3 4 3 2
)");
  EXPECT_THAT(m.indices, ElementsAre(0, 1, 2, 0, 2, 3, 0, 3, 4, 4, 3, 2));
}

TEST_F(PlyTest, ReadsNormalsAndUvs) {
  auto m = read(R"(ply
format ascii 1.0
element vertex 3
property float x
property float y
property float z
property float nx
property float ny
property float nz
property float u
property float v
element face 1
property list uchar int vertex_indices
end_header
0 0 0 0 0 1 0 0
1 0 0 0 0 1 1 0
0 1 0 0 0 1 0.25 0.75
3 0 1 2
)");
  ASSERT_EQ(m.N.size(), 3u);
  ASSERT_EQ(m.uv.size(), 3u);
  EXPECT_EQ(m.N[1], Vec3(0, 0, 1));
  EXPECT_EQ(m.uv[2], Vec2(0.25f, 0.75f));
}

TEST_F(PlyTest, AcceptsStAndTextureUvSpellingsOfTextureCoordinates) {
  for (auto [u, v] : {std::pair{"s", "t"}, std::pair{"texture_u", "texture_v"}}) {
    SCOPED_TRACE(u);
    auto m = read(fmt::format(R"(ply
format ascii 1.0
element vertex 3
property double x
property double y
property double z
property float {}
property float {}
element face 1
property list uchar int vertex_indices
end_header
0 0 0 0.5 0.5
1 0 0 1 0
0 1 0 0 1
3 0 1 2
)",
                              u, v));
    ASSERT_EQ(m.uv.size(), 3u);
    EXPECT_EQ(m.uv[0], Vec2(0.5f, 0.5f));
  }
}

TEST_F(PlyTest, SkipsUnknownPropertiesListsAndElements) {
  auto m = read(R"(ply
format ascii 1.0
element material 1
property list uchar float coefficients
property int id
element vertex 3
property float confidence
property float x
property list uchar uchar tags
property float y
property float z
property uchar red
element face 1
property int flags
property list uchar int vertex_indices
property list uint uint extra
end_header
3 0.1 0.2 0.3 7
9 0 2 1 1 0 0 255
9 1 0 0 0 255
9 0 1 5 1 0 255
42 3 0 1 2 2 8 9
)");
  ASSERT_EQ(m.P.size(), 3u);
  EXPECT_EQ(m.P[0], Vec3(0, 0, 0));
  EXPECT_EQ(m.P[1], Vec3(1, 0, 0));
  EXPECT_EQ(m.P[2], Vec3(0, 1, 0));
  EXPECT_THAT(m.indices, ElementsAre(0, 1, 2));
}

TEST_F(PlyTest, HeaderLinesMayEndInCarriageReturns) {
  std::string text = kAsciiQuad;
  std::string crlf;
  for (char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  EXPECT_EQ(read(crlf).indices.size(), 6u);
}

// Builds a binary file with float positions, uvs, a per-face scalar and the given list types.
std::string binary_triangle_pair(bool little, const char* count_type, const char* index_type) {
  std::string s = fmt::format(
      "ply\nformat {} 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float "
      "z\nproperty float u\nproperty float v\nelement face 2\nproperty list {} {} "
      "vertex_indices\nend_header\n",
      little ? "binary_little_endian" : "binary_big_endian", count_type, index_type);
  float verts[4][5] = {{0, 0, 0, 0, 0}, {1, 0, 0, 1, 0}, {1, 1, 0, 1, 1}, {0, 1, 0, 0, 1}};
  for (auto& v : verts)
    for (float f : v) put(s, f, little);
  auto put_int = [&](const char* type, int v) {
    std::string t = type;
    if (t == "uchar" || t == "uint8" || t == "char" || t == "int8")
      put(s, static_cast<int8_t>(v), little);
    else if (t == "ushort" || t == "short")
      put(s, static_cast<int16_t>(v), little);
    else
      put(s, static_cast<int32_t>(v), little);
  };
  for (auto face : {std::array{0, 1, 2}, std::array{0, 2, 3}}) {
    put_int(count_type, 3);
    for (int i : face) put_int(index_type, i);
  }
  return s;
}

TEST_F(PlyTest, ReadsBinaryInBothByteOrdersWithEveryIntegerListType) {
  const char* types[] = {"uchar", "uint8", "char", "int8",   "ushort",
                         "short", "uint",  "int",  "uint32", "int32"};
  for (bool little : {true, false})
    for (const char* count : types)
      for (const char* index : types) {
        SCOPED_TRACE(fmt::format("{} {} {}", little ? "little" : "big", count, index));
        auto m = read(binary_triangle_pair(little, count, index));
        ASSERT_EQ(m.P.size(), 4u);
        EXPECT_EQ(m.P[2], Vec3(1, 1, 0));
        EXPECT_EQ(m.uv[3], Vec2(0, 1));
        EXPECT_THAT(m.indices, ElementsAre(0, 1, 2, 0, 2, 3));
      }
}

TEST_F(PlyTest, ReadsDoublePositionsInBigEndian) {
  std::string s =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\nproperty double "
      "y\nproperty double z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n";
  for (double d : {0.0, 0.0, 0.0, 1.5, 0.0, 0.0, 0.0, -2.5, 0.0}) put(s, d, false);
  put(s, uint8_t{3}, false);
  for (uint32_t i : {0u, 1u, 2u}) put(s, i, false);
  auto m = read(s);
  EXPECT_EQ(m.P[1], Vec3(1.5f, 0, 0));
  EXPECT_EQ(m.P[2], Vec3(0, -2.5f, 0));
}

// ---------------------------------------------------------------------------------------------
// Errors: each names the file and is located at the scene parameter

TEST_F(PlyTest, MissingFile) {
  std::string path = (dir_ / "absent.ply").string();
  try {
    read_ply(path, test_loc());
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.formatted(),
              fmt::format("scene.pbrt:7:5: error: PLY file '{}': cannot open the file", path));
  }
}

TEST_F(PlyTest, NotAPlyFile) {
  EXPECT_THAT(error("OFF\n3 1 0\n"), HasSubstr("mesh.ply': not a PLY file"));
  EXPECT_THAT(error(""), HasSubstr("not a PLY file"));
}

TEST_F(PlyTest, HeaderWithoutEndHeader) {
  EXPECT_THAT(error("ply\nformat ascii 1.0\nelement vertex 3\n"),
              HasSubstr("the header has no end_header line"));
}

TEST_F(PlyTest, UnknownFormatAndPropertyType) {
  EXPECT_THAT(error("ply\nformat binary_middle_endian 1.0\nend_header\n"),
              HasSubstr("unknown format 'binary_middle_endian'"));
  EXPECT_THAT(error("ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\nend_header\n"),
              HasSubstr("unknown property type 'half'"));
}

TEST_F(PlyTest, TruncatedBinaryData) {
  std::string s = binary_triangle_pair(true, "uchar", "int");
  s.resize(s.size() - 3);
  EXPECT_THAT(error(s), HasSubstr("mesh.ply': truncated data (the file ends early)"));
}

// CI's fuzzer found a face whose uint count (3,742,777,171) made the reader allocate 15 GB for
// one polygon. A count is refused when its items cannot fit in the bytes left, before any
// allocation; a count that fits but whose items are missing is still the truncation error.
TEST_F(PlyTest, ListCountBeyondTheFileIsRefusedBeforeAllocating) {
  for (bool little : {true, false}) {
    // The header and four vertices of binary_triangle_pair(), then one face: `count`, indices 0 1 2.
    std::string pair = binary_triangle_pair(little, "uint", "int");
    std::string start = pair.substr(0, pair.find("end_header\n") + 11 + 4 * 5 * 4);
    auto one_face = [&](uint32_t count) {
      std::string s = start;
      put(s, count, little);
      for (int i : {0, 1, 2}) put(s, int32_t{i}, little);
      return s;
    };
    EXPECT_THAT(error(one_face(3742777171u)),
                HasSubstr("truncated data (the file ends early): list property 'vertex_indices' claims "
                          "3742777171 items, more than the 12 bytes left can hold"));
    // Control: 3 items need 12 bytes and pass the count check (then face 2 is missing); 4 do not.
    EXPECT_THAT(error(one_face(3)), AllOf(HasSubstr("truncated data"), Not(HasSubstr("claims"))));
    EXPECT_THAT(error(one_face(4)), HasSubstr("claims 4 items, more than the 12 bytes left"));
  }
  std::string ascii = kAsciiQuad;
  ascii.replace(ascii.find("4 0 1 2 3"), 1, "4000000000");
  EXPECT_THAT(error(ascii), HasSubstr("claims 4000000000 items"));
  // Ascii items take a character and a separator, but the last: "0 1 2" holds 3 and not 4.
  std::string header = kAsciiQuad;
  header.resize(header.find("4 0 1 2 3"));
  EXPECT_EQ(read(header + "3 0 1 2").indices.size(), 3u);
  EXPECT_THAT(error(header + "4 0 1 2"), HasSubstr("claims 4 items, more than the 6 bytes left"));
}

TEST_F(PlyTest, TruncatedAsciiData) {
  std::string s = kAsciiQuad;
  s.resize(s.find("4 0 1 2 3") + 7);
  EXPECT_THAT(error(s), HasSubstr("truncated data"));
}

TEST_F(PlyTest, BadAsciiNumber) {
  std::string s = kAsciiQuad;
  s.replace(s.find("1 1 0"), 1, "x");
  EXPECT_THAT(error(s), HasSubstr("bad number 'x' in the data"));
}

TEST_F(PlyTest, IndexOutOfRange) {
  std::string s = kAsciiQuad;
  s.replace(s.find("4 0 1 2 3"), 9, "4 0 1 2 4");
  EXPECT_THAT(error(s),
              HasSubstr("mesh.ply': vertex index 4 out of range (the mesh has 4 vertices)"));
  s.replace(s.find("4 0 1 2 4"), 9, "3 0 -1 2");
  EXPECT_THAT(error(s), HasSubstr("vertex index -1 out of range in face 0"));
}

// CI's fuzzer found a NaN vertex index (a float index type) cast to an integer, which is undefined
// behaviour. NaN and infinite indices and list lengths (an ascii count may read "nan") are now
// errors, found by comparison alone.
TEST_F(PlyTest, NonFiniteIndicesAndListLengthsAreErrors) {
  std::string s = kAsciiQuad;
  s.replace(s.find("list uchar int"), 14, "list uchar float");
  ASSERT_EQ(read(s).indices.size(), 6u);  // control: float indices holding whole numbers read
  for (const char* index : {"nan", "inf", "-inf"}) {
    std::string bad = s;
    bad.replace(bad.find("4 0 1 2 3"), 9, fmt::format("4 0 {} 2 3", index));
    EXPECT_THAT(error(bad), HasSubstr(fmt::format("vertex index {} out of range in face 0", index)));
  }
  std::string half = s;
  half.replace(half.find("4 0 1 2 3"), 9, "4 0 1.5 2 3");
  EXPECT_THAT(error(half), HasSubstr("vertex index 1.5 in face 0 is not an integer"));
  for (const char* count : {"nan", "2.5", "-1"}) {
    std::string bad = s;
    bad.replace(bad.find("4 0 1 2 3"), 1, count);
    EXPECT_THAT(error(bad), HasSubstr(fmt::format("bad list length {} in property 'vertex_indices'", count)));
  }
  std::string endless = s;
  endless.replace(endless.find("4 0 1 2 3"), 1, "inf");
  EXPECT_THAT(error(endless), HasSubstr("claims inf items"));
}

TEST_F(PlyTest, NoFaces) {
  std::string s = kAsciiQuad;
  s.replace(s.find("element face 1"), 14, "element face 0");
  s.resize(s.find("4 0 1 2 3"));
  EXPECT_THAT(error(s), HasSubstr("mesh.ply': the mesh has no faces"));
}

TEST_F(PlyTest, NoVertices) {
  EXPECT_THAT(error("ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int "
                    "vertex_indices\nend_header\n"),
              HasSubstr("no vertex element with x, y and z properties"));
}

TEST_F(PlyTest, FaceElementWithoutVertexIndices) {
  std::string s = kAsciiQuad;
  s.replace(s.find("vertex_indices"), 14, "corners");
  EXPECT_THAT(error(s), HasSubstr("the face element has no vertex_indices list"));
}

// ---------------------------------------------------------------------------------------------
// The real meshes

TEST(PlyRealFiles, WaterCausticSurfaceHasItsVerticesNormalsUvsAndFaces) {
  auto m = read_ply(kScenes + "water-caustic/models/Mesh001.ply", test_loc());
  EXPECT_EQ(m.P.size(), 63768u);
  EXPECT_EQ(m.N.size(), 63768u);
  EXPECT_EQ(m.uv.size(), 63768u);
  EXPECT_EQ(m.indices.size(), 102938u * 3);  // all faces are triangles
  EXPECT_NEAR(m.P[0].x, -0.329465f, 1e-6f);
  EXPECT_NEAR(m.N[0].z, 0.567214f, 1e-6f);
  EXPECT_NEAR(m.uv[0].y, 0.011211f, 1e-6f);
  EXPECT_THAT(std::vector<int>(m.indices.begin(), m.indices.begin() + 3), ElementsAre(0, 1, 2));
}

TEST(PlyRealFiles, EveryMeshOfTheRealScenesReads) {
  size_t files = 0;
  for (const char* scene : {"veach-bidir", "water-caustic"})
    for (const auto& entry : fs::directory_iterator(kScenes + scene + "/models")) {
      SCOPED_TRACE(entry.path().string());
      auto m = read_ply(entry.path().string(), test_loc());
      EXPECT_FALSE(m.P.empty());
      EXPECT_EQ(m.uv.size(), m.P.size());
      EXPECT_EQ(m.indices.size() % 3, 0u);
      ++files;
    }
  EXPECT_EQ(files, 14u);
}

TEST(PlyRealFiles, VeachBidirWoodMeshHasUvsButNoNormals) {
  auto m = read_ply(kScenes + "veach-bidir/models/Mesh000.ply", test_loc());
  EXPECT_EQ(m.P.size(), 24u);
  EXPECT_TRUE(m.N.empty());
  EXPECT_EQ(m.uv.size(), 24u);
  EXPECT_EQ(m.indices.size(), 36u);
}

}  // namespace
}  // namespace penumbra
