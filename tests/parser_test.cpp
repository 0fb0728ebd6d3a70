// The pbrt-v4 scene parser: tokens, directives, transforms and the real scenes in scenes/pbrt-v4.
// Error messages are checked in parser_errors_test.cpp.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>

#include "parser/scene_description.h"
#include "parser/tokenizer.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const std::string kScenes = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/pbrt-v4/";

// A fresh folder under the system temp directory, removed with the test.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("penumbra-parser-" + std::string(info->name()) + "-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~TempDir() { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) const {
    fs::path p = dir_ / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  const fs::path& path() const { return dir_; }

 private:
  fs::path dir_;
};

void expect_mat_near(const Mat4& a, const Mat4& b, float eps = 1e-5f) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      EXPECT_NEAR(a[c][r], b[c][r], eps) << "column " << c << " row " << r;
}

Vec3 apply_point(const Mat4& m, Vec3 p) { return Vec3(m * Vec4(p, 1.f)); }

// Parses `text` after WorldBegin and returns the single shape's to_world.
Mat4 shape_transform(const std::string& transforms) {
  auto d = parse_scene_string("WorldBegin\n" + transforms + "\nShape \"sphere\"\n");
  EXPECT_EQ(d.shapes.size(), 1u);
  return d.shapes.empty() ? Mat4(1.f) : d.shapes[0].to_world;
}

std::vector<Token> tokenize(const std::string& text) {
  Tokenizer tok(std::make_shared<const std::string>(text),
                std::make_shared<const std::string>("t"));
  std::vector<Token> out;
  for (Token t = tok.next(); t.kind != TokenKind::End; t = tok.next()) out.push_back(t);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Tokenizer

TEST(Tokenizer, GivesOneBasedLineAndColumnOfEachToken) {
  auto t = tokenize("Shape \"sphere\"\n\t\"float radius\" [ 2 ]");
  ASSERT_EQ(t.size(), 6u);
  EXPECT_EQ(t[0].kind, TokenKind::Word);
  EXPECT_EQ(t[1].kind, TokenKind::String);
  EXPECT_EQ(t[1].text, "sphere");
  EXPECT_EQ(t[1].loc.line, 1);
  EXPECT_EQ(t[1].loc.column, 7);
  EXPECT_EQ(t[2].loc.line, 2);
  EXPECT_EQ(t[2].loc.column, 2);  // a tab is one column
  EXPECT_EQ(t[3].kind, TokenKind::LBracket);
  EXPECT_EQ(t[4].kind, TokenKind::Number);
  EXPECT_EQ(t[4].text, "2");
  EXPECT_EQ(t[4].loc.column, 19);
  EXPECT_EQ(t[5].kind, TokenKind::RBracket);
}

TEST(Tokenizer, LocationsCarryFilenameAndSourceText) {
  auto t = tokenize("Identity");
  ASSERT_EQ(t.size(), 1u);
  ASSERT_TRUE(t[0].loc.filename && t[0].loc.source);
  EXPECT_EQ(*t[0].loc.filename, "t");
  EXPECT_EQ(*t[0].loc.source, "Identity");
}

TEST(Tokenizer, ResolvesStringEscapes) {
  auto t = tokenize(R"("a\"b\\c\nd\te")");
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(t[0].text, "a\"b\\c\nd\te");
}

TEST(Tokenizer, SkipsCommentsIncludingThoseAfterValues) {
  auto t = tokenize("# header\nSampler \"sobol\" # trailing\n  [ 1 ] # gonsolo 512\n");
  ASSERT_EQ(t.size(), 5u);
  EXPECT_EQ(t[0].text, "Sampler");
  EXPECT_EQ(t[0].loc.line, 2);
  EXPECT_EQ(t[4].kind, TokenKind::RBracket);
}

TEST(Tokenizer, KeepsAMalformedNumberAsOneToken) {
  auto t = tokenize("1.2.3 -4e+2 +.5");
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t[0].text, "1.2.3");
  EXPECT_THROW(parse_number(t[0]), Error);
  EXPECT_DOUBLE_EQ(parse_number(t[1]), -400.0);
  EXPECT_DOUBLE_EQ(parse_number(t[2]), 0.5);
}

TEST(Tokenizer, HandlesWindowsLineEndings) {
  auto t = tokenize("WorldBegin\r\nShape \"sphere\"\r\n");
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t[1].loc.line, 2);
  EXPECT_EQ(t[1].loc.column, 1);
}

TEST(Tokenizer, PeekDoesNotConsume) {
  Tokenizer tok(std::make_shared<const std::string>("a b"),
                std::make_shared<const std::string>("t"));
  EXPECT_EQ(tok.peek().text, "a");
  EXPECT_EQ(tok.next().text, "a");
  EXPECT_EQ(tok.next().text, "b");
  EXPECT_EQ(tok.next().kind, TokenKind::End);
}

// ---------------------------------------------------------------------------------------------
// Parameter lists

TEST(ParserParams, ReadsEveryAcceptedTypeWithItsValues) {
  auto d = parse_scene_string(R"(Integrator "path"
    "integer a" [ 1 2 ] "float b" 0.5 "point2 c" [ 1 2 ] "vector2 d" [ 1 2 ]
    "point3 e" [ 1 2 3 ] "vector3 f" [ 1 2 3 ] "normal g" [ 0 0 1 ] "normal3 h" [ 0 1 0 ]
    "point i" [ 1 2 3 ] "vector j" [ 1 2 3 ] "rgb k" [ .1 .2 .3 ] "bool l" true
    "bool m" [ "false" ] "string n" "text" "spectrum o" [ 1 2 3 ])");
  const ParamSet& p = d.integrator.params;
  EXPECT_EQ(p.params().size(), 15u);
  EXPECT_EQ(p.get_ints("a"), (std::vector<int>{1, 2}));
  EXPECT_FLOAT_EQ(p.get_float("b"), 0.5f);
  EXPECT_EQ(p.find("c")->numbers.size(), 2u);
  EXPECT_EQ(p.get_rgb("k"), Rgb(.1f, .2f, .3f));
  EXPECT_TRUE(p.get_bool("l"));
  EXPECT_FALSE(p.get_bool("m", true));
  EXPECT_EQ(p.get_string("n"), "text");
  EXPECT_EQ(p.find("o")->type, "spectrum");
  EXPECT_EQ(p.get_rgb("o"), Rgb(1, 2, 3));
}

TEST(ParserParams, EachParamIsLocatedAtItsDeclarationString) {
  auto d = parse_scene_string("Sampler \"sobol\"\n  \"integer pixelsamples\" [ 4 ]");
  const Param* p = d.sampler.params.find("pixelsamples");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->loc.line, 2);
  EXPECT_EQ(p->loc.column, 3);
  EXPECT_EQ(p->loc.str(), "<string>:2:3");
}

TEST(ParserParams, AcceptsIntegersWrittenWithExponent) {
  auto d = parse_scene_string("Sampler \"sobol\" \"integer pixelsamples\" 1e2");
  EXPECT_EQ(d.sampler.params.get_int("pixelsamples"), 100);
}

// ---------------------------------------------------------------------------------------------
// Options and camera

TEST(ParserOptions, StoresFilmFilterSamplerIntegratorTypeAndParams) {
  auto d = parse_scene_string(R"(Film "rgb" "integer xresolution" 32
PixelFilter "gaussian" "float xradius" 1.5
Sampler "sobol" "integer pixelsamples" 8
Integrator "path" "integer maxdepth" 5
WorldBegin)");
  EXPECT_EQ(d.film.type, "rgb");
  EXPECT_EQ(d.film.params.get_int("xresolution"), 32);
  EXPECT_EQ(d.filter.type, "gaussian");
  EXPECT_FLOAT_EQ(d.filter.params.get_float("xradius"), 1.5f);
  EXPECT_EQ(d.sampler.type, "sobol");
  EXPECT_EQ(d.integrator.type, "path");
  EXPECT_EQ(d.integrator.params.get_int("maxdepth"), 5);
  EXPECT_EQ(d.integrator.loc.line, 4);
  EXPECT_EQ(d.integrator.loc.column, 1);
}

TEST(ParserOptions, LastOptionDirectiveWins) {
  auto d = parse_scene_string("Integrator \"path\"\nIntegrator \"bdpt\" \"integer maxdepth\" 3");
  EXPECT_EQ(d.integrator.type, "bdpt");
  EXPECT_EQ(d.integrator.params.get_int("maxdepth"), 3);
}

TEST(ParserOptions, AbsentOptionsLeaveEmptyTypes) {
  auto d = parse_scene_string("WorldBegin");
  EXPECT_EQ(d.camera.type, "");
  EXPECT_EQ(d.film.type, "");
  EXPECT_TRUE(d.shapes.empty());
}

TEST(ParserCamera, CameraToWorldIsInverseOfCtm) {
  auto d =
      parse_scene_string("Translate 1 2 3\nCamera \"perspective\" \"float fov\" 45\nWorldBegin");
  EXPECT_EQ(d.camera.type, "perspective");
  EXPECT_FLOAT_EQ(d.camera.params.get_float("fov"), 45.f);
  expect_mat_near(d.camera.to_world, glm::translate(Mat4(1.f), Vec3(-1, -2, -3)));
}

TEST(ParserCamera, DefinesTheCameraCoordinateSystem) {
  auto d = parse_scene_string(R"(Translate 1 2 3
Camera "perspective"
WorldBegin
CoordSysTransform "camera"
Shape "sphere")");
  expect_mat_near(d.shapes[0].to_world, d.camera.to_world);
}

// ---------------------------------------------------------------------------------------------
// Transforms

TEST(ParserTransforms, TranslateScaleRotateMatchGlm) {
  expect_mat_near(shape_transform("Translate 1 2 3"), glm::translate(Mat4(1.f), Vec3(1, 2, 3)));
  expect_mat_near(shape_transform("Scale 2 3 4"), glm::scale(Mat4(1.f), Vec3(2, 3, 4)));
  Mat4 r = shape_transform("Rotate 90 0 0 1");
  Vec3 x = apply_point(r, Vec3(1, 0, 0));
  EXPECT_NEAR(x.x, 0.f, 1e-6f);
  EXPECT_NEAR(x.y, 1.f, 1e-6f);
  EXPECT_NEAR(x.z, 0.f, 1e-6f);
}

TEST(ParserTransforms, RotateNormalizesItsAxis) {
  expect_mat_near(shape_transform("Rotate 30 0 0 5"), shape_transform("Rotate 30 0 0 1"));
}

TEST(ParserTransforms, TransformsPostMultiplySoTheLastAppliesFirst) {
  Mat4 m = shape_transform("Translate 1 0 0\nScale 2 2 2");
  Vec3 p = apply_point(m, Vec3(1, 1, 1));
  EXPECT_NEAR(p.x, 3.f, 1e-6f);  // scaled to 2, then moved by 1
  EXPECT_NEAR(p.y, 2.f, 1e-6f);
}

TEST(ParserTransforms, IdentityResetsTheCtm) {
  expect_mat_near(shape_transform("Translate 1 2 3\nIdentity"), Mat4(1.f));
}

TEST(ParserTransforms, TransformReadsColumnsLikeGlmMakeMat4) {
  Mat4 m = shape_transform("Translate 9 9 9\nTransform [ 1 0 0 0  0 2 0 0  0 0 3 0  4 5 6 1 ]");
  expect_mat_near(m, Mat4(Vec4(1, 0, 0, 0), Vec4(0, 2, 0, 0), Vec4(0, 0, 3, 0), Vec4(4, 5, 6, 1)));
}

TEST(ParserTransforms, ConcatTransformPostMultiplies) {
  Mat4 m = shape_transform("Translate 1 0 0\nConcatTransform [ 2 0 0 0 0 2 0 0 0 0 2 0 0 0 0 1 ]");
  expect_mat_near(m, glm::scale(glm::translate(Mat4(1.f), Vec3(1, 0, 0)), Vec3(2.f)));
}

TEST(ParserTransforms, BracketsAreOptionalForNumberDirectives) {
  expect_mat_near(shape_transform("Translate [ 1 2 3 ]"), shape_transform("Translate 1 2 3"));
  expect_mat_near(shape_transform("Transform 1 0 0 0 0 1 0 0 0 0 1 0 4 5 6 1"),
                  glm::translate(Mat4(1.f), Vec3(4, 5, 6)));
}

TEST(ParserTransforms, LookAtBuildsCameraFromWorld) {
  auto d = parse_scene_string("LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin");
  const Mat4& w = d.camera.to_world;  // world-from-camera
  Vec3 eye = apply_point(w, Vec3(0.f));
  Vec3 forward = Vec3(w * Vec4(0, 0, 1, 0));
  Vec3 up = Vec3(w * Vec4(0, 1, 0, 0));
  Vec3 right = Vec3(w * Vec4(1, 0, 0, 0));
  EXPECT_NEAR(glm::distance(eye, Vec3(0, 0, 5)), 0.f, 1e-6f);
  EXPECT_NEAR(glm::distance(forward, Vec3(0, 0, -1)), 0.f, 1e-6f);
  EXPECT_NEAR(glm::distance(up, Vec3(0, 1, 0)), 0.f, 1e-6f);
  EXPECT_NEAR(glm::distance(right, Vec3(-1, 0, 0)), 0.f, 1e-6f);  // pbrt's left-handed camera
}

TEST(ParserTransforms, LookAtOrthonormalizesATiltedUpVector) {
  auto d = parse_scene_string("LookAt 1 2 3  4 6 3  0 1 1\nCamera \"perspective\"\nWorldBegin");
  const Mat4& w = d.camera.to_world;
  Vec3 forward = Vec3(w * Vec4(0, 0, 1, 0)), up = Vec3(w * Vec4(0, 1, 0, 0));
  EXPECT_NEAR(glm::distance(forward, Vec3(0.6f, 0.8f, 0)), 0.f, 1e-6f);
  EXPECT_NEAR(glm::dot(forward, up), 0.f, 1e-6f);
  EXPECT_NEAR(glm::length(up), 1.f, 1e-6f);
  EXPECT_GT(up.z, 0.f);
}

TEST(ParserTransforms, CoordSysTransformRestoresANamedCtm) {
  Mat4 m = shape_transform(
      "Translate 1 2 3\nCoordinateSystem \"mine\"\nScale 5 5 5\n"
      "CoordSysTransform \"mine\"");
  expect_mat_near(m, glm::translate(Mat4(1.f), Vec3(1, 2, 3)));
}

TEST(ParserTransforms, WorldBeginResetsCtmButKeepsNamedSystems) {
  auto d = parse_scene_string(R"(Translate 1 2 3
CoordinateSystem "before"
WorldBegin
Shape "sphere"
CoordSysTransform "before"
Shape "sphere"
Translate 5 0 0
CoordSysTransform "world"
Shape "sphere")");
  ASSERT_EQ(d.shapes.size(), 3u);
  expect_mat_near(d.shapes[0].to_world, Mat4(1.f));
  expect_mat_near(d.shapes[1].to_world, glm::translate(Mat4(1.f), Vec3(1, 2, 3)));
  expect_mat_near(d.shapes[2].to_world, Mat4(1.f));
}

TEST(ParserTransforms, AttributeEndRestoresTheCtm) {
  auto d = parse_scene_string(R"(WorldBegin
Translate 1 0 0
AttributeBegin
  Translate 0 1 0
  Shape "sphere"
AttributeEnd
Shape "sphere")");
  ASSERT_EQ(d.shapes.size(), 2u);
  expect_mat_near(d.shapes[0].to_world, glm::translate(Mat4(1.f), Vec3(1, 1, 0)));
  expect_mat_near(d.shapes[1].to_world, glm::translate(Mat4(1.f), Vec3(1, 0, 0)));
}

TEST(ParserTransforms, TransformBeginRestoresOnlyTheCtmAndWarns) {
  ::testing::internal::CaptureStderr();
  auto d = parse_scene_string(R"(WorldBegin
TransformBegin
  Translate 0 1 0
  Material "conductor"
TransformEnd
Shape "sphere")");
  std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_THAT(err, HasSubstr("<string>:2:1: warning: TransformBegin is deprecated"));
  ASSERT_EQ(d.shapes.size(), 1u);
  expect_mat_near(d.shapes[0].to_world, Mat4(1.f));
  EXPECT_EQ(d.shapes[0].material, 0);  // the material set inside the block stays
}

// ---------------------------------------------------------------------------------------------
// Materials, lights and shapes

TEST(ParserMaterials, MaterialBecomesCurrentAndClearsNamedMaterial) {
  auto d = parse_scene_string(R"(WorldBegin
MakeNamedMaterial "red" "string type" "diffuse"
NamedMaterial "red"
Material "conductor" "float roughness" 0.1
Shape "sphere")");
  ASSERT_EQ(d.materials.size(), 2u);
  EXPECT_EQ(d.materials[1].type, "conductor");
  EXPECT_EQ(d.shapes[0].material, 1);
  EXPECT_EQ(d.shapes[0].material_name, "");
}

TEST(ParserMaterials, MakeNamedMaterialMovesTypeOutOfParams) {
  auto d = parse_scene_string(R"(WorldBegin
MakeNamedMaterial "red" "string type" [ "diffuse" ] "rgb reflectance" [ 1 0 0 ])");
  ASSERT_EQ(d.materials.size(), 1u);
  EXPECT_EQ(d.materials[0].type, "diffuse");
  EXPECT_FALSE(d.materials[0].params.has("type"));
  EXPECT_EQ(d.materials[0].params.get_rgb("reflectance"), Rgb(1, 0, 0));
  EXPECT_EQ(d.named_materials.at("red"), 0);
}

TEST(ParserMaterials, MakeNamedMaterialDoesNotChangeCurrentMaterial) {
  auto d = parse_scene_string(R"(WorldBegin
Material "diffuse"
MakeNamedMaterial "red" "string type" "diffuse"
Shape "sphere")");
  EXPECT_EQ(d.shapes[0].material, 0);
}

TEST(ParserMaterials, NamedMaterialIsStoredOnFollowingShapesWithItsLocation) {
  auto d = parse_scene_string(R"(WorldBegin
Material "diffuse"
  NamedMaterial "later"
Shape "sphere"
Shape "disk")");
  ASSERT_EQ(d.shapes.size(), 2u);
  for (const auto& s : d.shapes) {
    EXPECT_EQ(s.material, -1);
    EXPECT_EQ(s.material_name, "later");
    EXPECT_EQ(s.material_loc.line, 3);
    EXPECT_EQ(s.material_loc.column, 3);
  }
}

TEST(ParserMaterials, ShapesHaveNoMaterialByDefault) {
  auto d = parse_scene_string("WorldBegin\nShape \"sphere\"");
  EXPECT_EQ(d.shapes[0].material, -1);
  EXPECT_EQ(d.shapes[0].material_name, "");
}

TEST(ParserMaterials, AttributeEndRestoresMaterial) {
  auto d = parse_scene_string(R"(WorldBegin
Material "diffuse"
AttributeBegin
  Material "conductor"
AttributeEnd
Shape "sphere")");
  EXPECT_EQ(d.shapes[0].material, 0);
}

TEST(ParserLights, AreaLightAppliesToShapesUntilAttributeEnd) {
  auto d = parse_scene_string(R"(WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 1 2 3 ]
  Shape "sphere"
  Shape "disk"
AttributeEnd
Shape "sphere")");
  ASSERT_EQ(d.area_lights.size(), 1u);
  EXPECT_EQ(d.area_lights[0].type, "diffuse");
  EXPECT_EQ(d.area_lights[0].params.get_rgb("L"), Rgb(1, 2, 3));
  EXPECT_EQ(d.shapes[0].area_light, 0);
  EXPECT_EQ(d.shapes[1].area_light, 0);
  EXPECT_EQ(d.shapes[2].area_light, -1);
}

TEST(ParserLights, LightSourceStoresTheCtm) {
  auto d =
      parse_scene_string("WorldBegin\nTranslate 0 5 0\nLightSource \"point\" \"rgb I\" [1 1 1]");
  ASSERT_EQ(d.lights.size(), 1u);
  EXPECT_EQ(d.lights[0].type, "point");
  expect_mat_near(d.lights[0].to_world, glm::translate(Mat4(1.f), Vec3(0, 5, 0)));
}

TEST(ParserShapes, ShapeStoresTypeParamsTransformAndLocation) {
  auto d = parse_scene_string("WorldBegin\nScale 2 2 2\n  Shape \"sphere\" \"float radius\" 3");
  ASSERT_EQ(d.shapes.size(), 1u);
  EXPECT_EQ(d.shapes[0].type, "sphere");
  EXPECT_FLOAT_EQ(d.shapes[0].params.get_float("radius"), 3.f);
  expect_mat_near(d.shapes[0].to_world, glm::scale(Mat4(1.f), Vec3(2.f)));
  EXPECT_EQ(d.shapes[0].loc.line, 3);
  EXPECT_EQ(d.shapes[0].loc.column, 3);
}

TEST(ParserShapes, ReverseOrientationTogglesAndAttributeEndRestoresIt) {
  auto d = parse_scene_string(R"(WorldBegin
AttributeBegin
  ReverseOrientation
  Shape "sphere"
  ReverseOrientation
  Shape "sphere"
  ReverseOrientation
AttributeEnd
Shape "sphere")");
  ASSERT_EQ(d.shapes.size(), 3u);
  EXPECT_TRUE(d.shapes[0].reverse_orientation);
  EXPECT_FALSE(d.shapes[1].reverse_orientation);
  EXPECT_FALSE(d.shapes[2].reverse_orientation);
}

// ---------------------------------------------------------------------------------------------
// Files and ignored directives

TEST(ParserFiles, IncludeParsesInlineRelativeToTheIncludingFile) {
  TempDir tmp;
  tmp.write("sub/inner.pbrt", "Include \"deeper/leaf.pbrt\"\nShape \"sphere\"\n");
  tmp.write("sub/deeper/leaf.pbrt", "Translate 1 0 0\n");
  std::string main =
      tmp.write("main.pbrt", "WorldBegin\nInclude \"sub/inner.pbrt\"\nShape \"disk\"\n");
  auto d = parse_scene_file(main);
  ASSERT_EQ(d.shapes.size(), 2u);
  EXPECT_EQ(d.filename, main);
  EXPECT_EQ(d.shapes[0].base_dir, (tmp.path() / "sub").string());
  EXPECT_EQ(d.shapes[1].base_dir, tmp.path().string());
  expect_mat_near(d.shapes[1].to_world, glm::translate(Mat4(1.f), Vec3(1, 0, 0)));
  EXPECT_THAT(*d.shapes[0].loc.filename, HasSubstr("inner.pbrt"));
  EXPECT_EQ(d.shapes[0].loc.line, 2);
}

TEST(ParserFiles, ImportIsReadLikeInclude) {
  TempDir tmp;
  tmp.write("geometry.pbrt", "Shape \"sphere\"\n");
  auto d = parse_scene_file(tmp.write("main.pbrt", "WorldBegin\nImport \"geometry.pbrt\"\n"));
  EXPECT_EQ(d.shapes.size(), 1u);
}

TEST(ParserFiles, IncludingTheSameFileTwiceIsNotACycle) {
  TempDir tmp;
  tmp.write("s.pbrt", "Shape \"sphere\"\n");
  auto d = parse_scene_file(
      tmp.write("main.pbrt", "WorldBegin\nInclude \"s.pbrt\"\nInclude \"s.pbrt\"\n"));
  EXPECT_EQ(d.shapes.size(), 2u);
}

TEST(ParserFiles, StringScenesResolveIncludesAgainstTheCurrentDirectory) {
  auto d = parse_scene_string("WorldBegin\nShape \"plymesh\"");
  EXPECT_EQ(d.shapes[0].base_dir, "");
}

TEST(ParserIgnored, AcceleratorColorSpaceOptionWorldEndWarnOnceAndSkipArguments) {
  ::testing::internal::CaptureStderr();
  auto d = parse_scene_string(R"(Accelerator "bvh" "integer maxnodeprims" 4
Accelerator "kdtree"
ColorSpace "aces2065-1"
Option "bool disablepixeljitter" true
Option "string rendercoordsys" [ "world" ]
Integrator "path"
WorldBegin
Shape "sphere"
WorldEnd)");
  std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_THAT(err, HasSubstr("<string>:1:1: warning: Accelerator is ignored"));
  EXPECT_THAT(err, HasSubstr("<string>:3:1: warning: ColorSpace is ignored"));
  EXPECT_THAT(err, HasSubstr("<string>:4:1: warning: Option is ignored"));
  EXPECT_THAT(err, HasSubstr("<string>:9:1: warning: WorldEnd"));
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 4);
  EXPECT_EQ(d.integrator.type, "path");
  EXPECT_EQ(d.shapes.size(), 1u);
}

TEST(ParserIgnored, MissingAttributeEndWarnsAtTheBegin) {
  ::testing::internal::CaptureStderr();
  auto d = parse_scene_string("WorldBegin\n  AttributeBegin\nShape \"sphere\"\n");
  std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_THAT(err, HasSubstr("<string>:2:3: warning: AttributeBegin has no matching AttributeEnd"));
  EXPECT_EQ(d.shapes.size(), 1u);
}

// ---------------------------------------------------------------------------------------------
// The real scenes, unchanged from their pbrt-v4 versions

TEST(ParserRealScenes, AllFourScenesParse) {
  for (const char* name : {"cornell-box", "veach-mis", "veach-bidir", "water-caustic"}) {
    SCOPED_TRACE(name);
    ::testing::internal::CaptureStderr();  // the Accelerator warning
    EXPECT_NO_THROW(parse_scene_file(kScenes + name + "/scene-v4.pbrt"));
    ::testing::internal::GetCapturedStderr();
  }
}

TEST(ParserRealScenes, CornellBoxHasItsMaterialsShapesLightAndCamera) {
  ::testing::internal::CaptureStderr();
  auto d = parse_scene_file(kScenes + "cornell-box/scene-v4.pbrt");
  ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(d.named_materials.size(), 8u);
  EXPECT_EQ(d.materials.size(), 8u);
  EXPECT_EQ(d.shapes.size(), 8u);
  ASSERT_EQ(d.area_lights.size(), 1u);
  EXPECT_EQ(d.area_lights[0].params.get_rgb("L"), Rgb(17, 12, 4));
  EXPECT_EQ(d.shapes[7].area_light, 0);
  EXPECT_EQ(d.shapes[7].material_name, "Light");
  EXPECT_EQ(d.shapes[0].material_name, "Floor");
  EXPECT_EQ(d.shapes[0].area_light, -1);
  EXPECT_EQ(d.camera.type, "perspective");
  EXPECT_FLOAT_EQ(d.camera.params.get_float("fov"), 19.5f);
  Vec3 position(d.camera.to_world[3]);
  EXPECT_NEAR(glm::distance(position, Vec3(0, 1, 6.8f)), 0.f, 1e-5f);
  EXPECT_EQ(d.integrator.params.get_int("maxdepth"), 4);
  EXPECT_EQ(d.film.params.get_int("xresolution"), 64);
  EXPECT_EQ(d.filter.type, "gaussian");
  EXPECT_EQ(d.sampler.type, "sobol");
  EXPECT_EQ(d.shapes[0].base_dir, kScenes + "cornell-box");
}

TEST(ParserRealScenes, VeachMisHasThreeSphereLightsInNestedBlocks) {
  auto d = parse_scene_file(kScenes + "veach-mis/scene-v4.pbrt");
  EXPECT_EQ(d.area_lights.size(), 3u);
  int spheres = 0;
  for (const auto& s : d.shapes)
    if (s.type == "sphere") {
      ++spheres;
      EXPECT_GE(s.area_light, 0);
      EXPECT_EQ(s.material_name, "Null");
      EXPECT_NEAR(s.to_world[3][1], 6.5f, 1e-6f);
    }
  EXPECT_EQ(spheres, 3);
  EXPECT_EQ(d.shapes.back().material_name, "SuperRough");
  EXPECT_EQ(d.shapes.back().area_light, -1);
}

TEST(ParserRealScenes, WaterCausticKeepsTheWaterScaleOnItsPlyMeshes) {
  auto d = parse_scene_file(kScenes + "water-caustic/scene-v4.pbrt");
  EXPECT_EQ(d.integrator.type, "sppm");
  const auto& water = d.shapes.back();
  EXPECT_EQ(water.type, "plymesh");
  EXPECT_EQ(water.params.get_string("filename"), "models/Mesh000.ply");
  EXPECT_EQ(water.material_name, "Water");
  EXPECT_FLOAT_EQ(water.to_world[1][1], 1.5f);
}

}  // namespace
}  // namespace penumbra
