// Every class of scene-file error the parser reports: the message, the exact line:column in
// Error::formatted(), and the quoted source line with a caret under that column.
#include <fmt/core.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "parser/scene_description.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

std::string formatted_error(const std::function<void()>& parse) {
  try {
    parse();
  } catch (const Error& e) { return e.formatted(); }
  return "(no error)";
}

std::string source_line(const std::string& text, int line) {
  std::istringstream in(text);
  std::string l;
  for (int i = 0; i < line; ++i) std::getline(in, l);
  return l;
}

// The caret line Error::formatted() prints under the quoted source line.
std::string caret(const std::string& text, int line, int column) {
  return fmt::format("\n    {}\n    {}^", source_line(text, line), std::string(column - 1, ' '));
}

// Parses `text` as "scene.pbrt" and checks "scene.pbrt:line:column: error: message" and the caret.
void expect_error(const std::string& text, int line, int column, const std::string& message) {
  std::string f = formatted_error([&] { parse_scene_string(text, "scene.pbrt"); });
  EXPECT_THAT(f, HasSubstr(fmt::format("scene.pbrt:{}:{}: error: {}", line, column, message)));
  EXPECT_THAT(f, HasSubstr(caret(text, line, column)));
}

class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("penumbra-parser-errors-" + std::string(info->name()) +
                                        "-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~TempDir() { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream((dir_ / name).string(), std::ios::binary) << text;
    return (dir_ / name).string();
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

 private:
  fs::path dir_;
};

// ---------------------------------------------------------------------------------------------
// Tokens

TEST(ParserErrors, UnterminatedStringIsReportedAtItsOpeningQuote) {
  expect_error("WorldBegin\nShape \"sphere\"\n  Shape \"disk\n", 3, 9, "unterminated string");
}

TEST(ParserErrors, UnterminatedStringAtEndOfFile) {
  expect_error("WorldBegin\nShape \"disk", 2, 7, "unterminated string");
}

TEST(ParserErrors, UnknownEscapeInString) {
  expect_error("WorldBegin\nShape \"a\\qb\"", 2, 9, "unknown escape sequence '\\q' in string");
}

TEST(ParserErrors, UnexpectedCharacter) {
  expect_error("WorldBegin\nShape @", 2, 7, "unexpected character '@'");
}

// ---------------------------------------------------------------------------------------------
// Directives

TEST(ParserErrors, UnknownDirective) {
  expect_error("WorldBegin\n\n  Foo \"x\"", 3, 3, "unknown directive 'Foo'");
}

TEST(ParserErrors, UnknownDirectiveSuggestsTheClosestOne) {
  expect_error("WorldBegin\nShap \"sphere\"", 2, 1,
               "unknown directive 'Shap'; did you mean 'Shape'?");
}

TEST(ParserErrors, UnsupportedDirectiveNamesTheDocs) {
  expect_error("WorldBegin\nTransformTimes 0 1", 2, 1,
               "unsupported directive 'TransformTimes' (Penumbra supports a subset of pbrt-v4: see "
               "docs/scene-format.md)");
}

TEST(ParserErrors, EveryUnsupportedPbrtDirectiveIsNamedAsSuch) {
  for (const char* d :
       {"ActiveTransform", "TransformTimes"}) {
    SCOPED_TRACE(d);
    expect_error(fmt::format("WorldBegin\n {}", d), 2, 2,
                 fmt::format("unsupported directive '{}'", d));
  }
}

TEST(ParserErrors, ValueWhereADirectiveIsExpected) {
  expect_error("WorldBegin 5", 1, 12, "expected a directive, got '5'");
}

TEST(ParserErrors, DirectiveWithoutItsQuotedType) {
  expect_error("WorldBegin\nShape sphere", 2, 7, "Shape needs a quoted shape type, got 'sphere'");
}

TEST(ParserErrors, FilmAfterWorldBegin) {
  expect_error("WorldBegin\nFilm \"rgb\"", 2, 1,
               "Film must come before WorldBegin (WorldBegin is at scene.pbrt:1:1)");
}

TEST(ParserErrors, CameraAfterWorldBegin) {
  expect_error("WorldBegin\n\nCamera \"perspective\"", 3, 1, "Camera must come before WorldBegin");
}

TEST(ParserErrors, ShapeBeforeWorldBegin) {
  expect_error("Film \"rgb\"\nShape \"sphere\"", 2, 1, "Shape must come after WorldBegin");
}

TEST(ParserErrors, WorldBeginTwice) {
  expect_error("WorldBegin\nWorldBegin", 2, 1, "WorldBegin given twice (first at scene.pbrt:1:1)");
}

TEST(ParserErrors, UnmatchedAttributeEnd) {
  expect_error("WorldBegin\nAttributeBegin\nAttributeEnd\n AttributeEnd", 4, 2,
               "AttributeEnd without a matching AttributeBegin");
}

TEST(ParserErrors, TransformEndCannotCloseAnAttributeBlock) {
  ::testing::internal::CaptureStderr();  // the deprecation warning
  expect_error("WorldBegin\nAttributeBegin\nTransformEnd", 3, 1,
               "TransformEnd closes the AttributeBegin at scene.pbrt:2:1");
  ::testing::internal::GetCapturedStderr();
}

TEST(ParserErrors, MakeNamedMaterialWithoutType) {
  expect_error("WorldBegin\nMakeNamedMaterial \"red\" \"rgb reflectance\" [ 1 0 0 ]", 2, 1,
               "MakeNamedMaterial 'red' needs a \"string type\" parameter");
}

TEST(ParserErrors, MakeNamedMaterialRedefined) {
  expect_error(
      "WorldBegin\nMakeNamedMaterial \"m\" \"string type\" \"diffuse\"\n"
      "MakeNamedMaterial \"m\" \"string type\" \"diffuse\"",
      3, 19, "named material 'm' redefined (first defined at scene.pbrt:2:1)");
}

TEST(ParserErrors, UnknownCoordinateSystem) {
  expect_error("WorldBegin\nCoordSysTransform \"nope\"", 2, 19,
               "unknown coordinate system 'nope' (defined: world)");
}

TEST(ParserErrors, LookAtWithUpParallelToTheViewDirection) {
  expect_error("LookAt 0 0 0  0 2 0  0 1 0", 1, 1,
               "LookAt up vector is parallel to the viewing direction");
}

TEST(ParserErrors, RotateAboutAZeroAxis) {
  expect_error("Rotate 30 0 0 0", 1, 1, "Rotate needs a non-zero axis");
}

TEST(ParserErrors, TransformWithTooFewNumbers) {
  expect_error("Transform [ 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 ]", 1, 11,
               "Transform needs 16 numbers, got 15");
}

TEST(ParserErrors, TranslateWithAWordInsteadOfANumber) {
  expect_error("Translate 1 2 x", 1, 15, "Translate needs 3 numbers; expected a number, got 'x'");
}

// ---------------------------------------------------------------------------------------------
// Parameters

TEST(ParserErrors, UnknownParameterType) {
  expect_error("WorldBegin\nShape \"sphere\" \"flot radius\" 1", 2, 16,
               "unknown parameter type 'flot'; did you mean 'float'?");
}

// Texture directives: the value type, redefinition and placement are checked by the parser; names
// are resolved when the scene is built (tests/texture_scene_test.cpp).
TEST(ParserErrors, TextureTypeMustBeFloatOrSpectrum) {
  expect_error("WorldBegin\nTexture \"checks\" \"color\" \"checkerboard\"", 2, 18,
               "texture type must be \"float\" or \"spectrum\", got \"color\"");
}

TEST(ParserErrors, TextureRedefinedIsAnError) {
  expect_error("WorldBegin\nTexture \"t\" \"float\" \"constant\"\nTexture \"t\" \"float\" \"constant\"", 3, 9,
               "float texture 't' redefined (first defined at scene.pbrt:2:1)");
}

TEST(ParserErrors, TextureBeforeWorldBegin) {
  expect_error("Texture \"t\" \"float\" \"constant\"", 1, 1, "Texture must come after WorldBegin");
}

TEST(ParserErrors, TextureParameterTakesAName) {
  expect_error("WorldBegin\nMaterial \"diffuse\" \"texture reflectance\" 0.5", 2, 42,
               "parameter 'reflectance' of type 'texture' needs quoted strings");
}

TEST(ParserErrors, BadParameterDeclaration) {
  expect_error("WorldBegin\nShape \"sphere\" \"radius\" 1", 2, 16,
               "bad parameter declaration \"radius\": expected \"type name\"");
}

TEST(ParserErrors, StringGivenForAFloat) {
  expect_error("WorldBegin\nShape \"sphere\" \"float radius\" \"big\"", 2, 31,
               "parameter 'radius' of type 'float' needs numbers, got string \"big\"");
}

TEST(ParserErrors, NumberGivenForAString) {
  expect_error("WorldBegin\nShape \"plymesh\" \"string filename\" 5", 2, 35,
               "parameter 'filename' of type 'string' needs quoted strings, got '5'");
}

TEST(ParserErrors, BoolThatIsNotTrueOrFalse) {
  expect_error("WorldBegin\nMaterial \"conductor\" \"bool remaproughness\" 1", 2, 44,
               "bool parameter 'remaproughness' must be true or false, got '1'");
  expect_error("WorldBegin\nMaterial \"conductor\" \"bool remaproughness\" [ \"yes\" ]", 2, 46,
               "bool parameter 'remaproughness' must be true or false, got string \"yes\"");
}

TEST(ParserErrors, BadNumber) {
  expect_error("WorldBegin\nShape \"sphere\" \"float radius\" [ 1.2.3 ]", 2, 33,
               "bad number '1.2.3'");
  expect_error("Translate 1 2 1e", 1, 15, "bad number '1e'");
  expect_error("Scale -nan 1 1", 1, 7, "bad number '-nan'");
  expect_error("Scale 1 1 1e999", 1, 11, "bad number '1e999'");
}

TEST(ParserErrors, NonIntegerForAnIntegerParameter) {
  expect_error("Integrator \"path\" \"integer maxdepth\" [ 1.5 ]", 1, 40,
               "parameter 'maxdepth' of type 'integer' needs an integer, got '1.5'");
}

TEST(ParserErrors, DuplicateParameter) {
  expect_error("WorldBegin\nShape \"sphere\" \"float radius\" 1 \"float radius\" 2", 2, 33,
               "parameter 'radius' given twice (first at scene.pbrt:2:16)");
}

TEST(ParserErrors, UnknownSpectrumNameListsTheClosestNames) {
  expect_error("WorldBegin\nMaterial \"conductor\" \"spectrum eta\" \"metal-Ag-et\"", 2, 22,
               "unknown spectrum 'metal-Ag-et' for parameter 'eta': not one of pbrt-v4's named spectra");
  std::string f = formatted_error(
      [] { parse_scene_string("WorldBegin\nMaterial \"conductor\" \"spectrum eta\" \"metal-Ag-et\"", "scene.pbrt"); });
  EXPECT_THAT(f, HasSubstr("closest names: 'metal-Ag-eta', 'metal-Ag-k', "));
}

TEST(ParserErrors, SpectrumPairsNeedAnEvenCount) {
  expect_error("WorldBegin\nLightSource \"point\" \"spectrum I\" [ 300 1 800 1 900 ]", 2, 21,
               "spectrum 'I' takes 3 RGB values or at least two (wavelength, value) pairs, got 5 values");
}

TEST(ParserErrors, SpectrumWavelengthsMustIncrease) {
  expect_error("WorldBegin\nLightSource \"point\" \"spectrum I\" [ 500 1 400 1 ]", 2, 21,
               "spectrum 'I': wavelengths must increase, but 400 follows 500");
}

TEST(ParserErrors, BlackbodyTakesOneTemperature) {
  expect_error("WorldBegin\nLightSource \"point\" \"blackbody I\" [ 3000 2 ]", 2, 21,
               "blackbody 'I' takes one temperature in kelvin, got 2 values");
  expect_error("WorldBegin\nLightSource \"point\" \"blackbody I\" [ -5 ]", 2, 21,
               "blackbody 'I' needs a temperature > 0 K, got -5");
}

TEST(ParserErrors, ParameterWithoutValue) {
  expect_error("WorldBegin\nShape \"sphere\" \"float radius\"\nShape \"disk\"", 2, 16,
               "parameter 'radius' has no value");
}

TEST(ParserErrors, ValueListWithoutClosingBracket) {
  expect_error("WorldBegin\nShape \"sphere\" \"float radius\" [ 1", 2, 31,
               "value list of parameter 'radius' has no closing ']'");
}

TEST(ParserErrors, EmptyValueList) {
  expect_error("WorldBegin\nShape \"sphere\" \"float radius\" [ ]", 2, 31,
               "parameter 'radius' has no values");
}

// ---------------------------------------------------------------------------------------------
// Files

TEST(ParserErrors, MissingIncludeFileIsReportedAtTheInclude) {
  TempDir tmp;
  std::string text = "WorldBegin\n  Include \"nothere.pbrt\"\n";
  std::string main = tmp.write("main.pbrt", text);
  std::string f = formatted_error([&] { parse_scene_file(main); });
  EXPECT_THAT(f, HasSubstr(fmt::format("main.pbrt:2:3: error: cannot open included file '{}'",
                                       tmp.path("nothere.pbrt"))));
  EXPECT_THAT(f, HasSubstr(caret(text, 2, 3)));
}

TEST(ParserErrors, IncludeCycleIsAnErrorNotAHang) {
  TempDir tmp;
  std::string a = tmp.write("a.pbrt", "WorldBegin\nInclude \"b.pbrt\"\n");
  tmp.write("b.pbrt", "Shape \"sphere\"\n Include \"a.pbrt\"\n");
  std::string f = formatted_error([&] { parse_scene_file(a); });
  EXPECT_THAT(f, HasSubstr(fmt::format("b.pbrt:2:2: error: include cycle: '{}' is already being "
                                       "read (a.pbrt -> b.pbrt -> a.pbrt)",
                                       tmp.path("a.pbrt"))));
  EXPECT_THAT(f, HasSubstr(caret("Shape \"sphere\"\n Include \"a.pbrt\"\n", 2, 2)));
}

TEST(ParserErrors, FileIncludingItselfIsACycle) {
  TempDir tmp;
  std::string a = tmp.write("self.pbrt", "Include \"self.pbrt\"\n");
  std::string f = formatted_error([&] { parse_scene_file(a); });
  EXPECT_THAT(f, HasSubstr("self.pbrt:1:1: error: include cycle"));
}

TEST(ParserErrors, ErrorsInsideAnIncludedFileNameThatFile) {
  TempDir tmp;
  tmp.write("inc.pbrt", "\n\nShape \"sphere\" \"float radius\" \"x\"\n");
  std::string main = tmp.write("main.pbrt", "WorldBegin\nInclude \"inc.pbrt\"\n");
  std::string f = formatted_error([&] { parse_scene_file(main); });
  EXPECT_THAT(f, HasSubstr("inc.pbrt:3:31: error: parameter 'radius'"));
  EXPECT_THAT(f, HasSubstr(caret("\n\nShape \"sphere\" \"float radius\" \"x\"", 3, 31)));
}

TEST(ParserErrors, MissingSceneFileHasNoLocation) {
  std::string f = formatted_error([] { parse_scene_file("/nonexistent/scene.pbrt"); });
  EXPECT_EQ(f, "error: cannot open scene file '/nonexistent/scene.pbrt'");
}

TEST(ParserErrors, MessagesQuoteTabIndentedLinesWithAlignedCaret) {
  std::string f =
      formatted_error([] { parse_scene_string("WorldBegin\n\tShape \"s", "scene.pbrt"); });
  EXPECT_THAT(
      f, HasSubstr("scene.pbrt:2:8: error: unterminated string\n    \tShape \"s\n    \t      ^"));
  EXPECT_THAT(f, Not(HasSubstr("(no error)")));
}

}  // namespace
}  // namespace penumbra
