// Outputs are checked before any sample is taken, and written so that a failure never destroys the
// previous file: every bad output path of `penumbra render`, `merge` and `converge` ends with a
// message naming the option (or the scene's file:line:col) and exit status 1 long before a render
// of 10^9 samples per pixel could have ended; images are renamed into place from a temporary file.
#include "image/image_io.h"
#include "support/command.h"
#include "util/output_file.h"

#include <penumbra/error.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <stdexcept>

using namespace penumbra;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

namespace {

const std::string kCornell = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt";

// A render that would take weeks (256x256 pixels at 10^9 samples each: 6.6e13 samples at about 10^7
// a second) must fail at once. Without the checks it fails only after the whole render, so any
// bound far below that proves the check came first; 10 s leaves room for a loaded machine (unloaded,
// each of these runs takes about 0.3 s, mostly process start and plugin loading).
constexpr double kMaxSeconds = 10.0;

struct Timed {
  test::CommandResult r;
  double seconds;
};

Timed run_timed(const std::vector<std::string>& args) {
  auto t0 = std::chrono::steady_clock::now();
  test::CommandResult r = test::run_penumbra(args);
  return {r, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()};
}

std::vector<std::string> huge_render(std::vector<std::string> extra) {
  std::vector<std::string> args = {"render", kCornell, "--spp", "1000000000", "-q"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

size_t files_in(const std::string& dir) {
  size_t n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}

}  // namespace

TEST(OutputChecks, BadCommandLineOutputsFailBeforeRendering) {
  std::string dir = test::temp_dir("bad-outputs");
  test::write_file(dir, "a-file", "x");
  fs::create_directories(dir + "/folder.exr");
  struct Case {
    std::vector<std::string> args;
    std::string message;
  } cases[] = {
      {{"-o", dir + "/missing/out.exr"}, "-o: cannot write image '" + dir + "/missing/out.exr': the folder '" + dir +
                                             "/missing' does not exist"},
      {{"-o", dir + "/a-file/out.exr"}, "-o: cannot write image '" + dir + "/a-file/out.exr': '" + dir +
                                            "/a-file' is not a folder"},
      {{"-o", "/proc/out.exr"}, "-o: cannot write image '/proc/out.exr': cannot create files in the folder '/proc'"},
      {{"-o", dir + "/folder.exr"}, "-o: cannot write image '" + dir + "/folder.exr': '" + dir + "/folder.exr' is a folder"},
      {{"-o", dir + "/out.bmpx"}, "-o: cannot write image '" + dir + "/out.bmpx': unknown extension '.bmpx'"},
      {{"-o", dir + "/out"}, "-o: cannot write image '" + dir + "/out': it has no extension"},
      {{"-o", dir + "/out.png", "--aov", "depth"}, "-o: AOVs (depth) are written as EXR layers"},
      {{"-o", dir + "/out.exr", "--stats", dir + "/missing/s.json"},
       "--stats: cannot write '" + dir + "/missing/s.json': the folder '" + dir + "/missing' does not exist"},
      {{"-o", dir + "/out.exr", "--stats", "/proc/s.json"}, "--stats: cannot write '/proc/s.json': cannot create files"},
  };
  for (const Case& c : cases) {
    Timed t = run_timed(huge_render(c.args));
    EXPECT_EQ(t.r.exit_code, 1) << c.message;
    EXPECT_THAT(t.r.err, HasSubstr(c.message));
    EXPECT_LT(t.seconds, kMaxSeconds) << c.message << ": the render ran before the output was checked";
  }
  EXPECT_EQ(files_in(dir), 2u) << "a failed check left files behind";
}

TEST(OutputChecks, BadFilmFilenameIsLocatedInTheScene) {
  std::string dir = test::temp_dir("bad-film-filename");
  auto scene_with_filename = [&](const std::string& name, const std::string& extra) {
    return test::write_file(dir, "scene.pbrt",
                            "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\n"
                            "Film \"rgb\" \"integer xresolution\" [ 64 ] \"integer yresolution\" [ 64 ]\n"
                            "    \"string filename\" \"" + name + "\"" + extra + "\n"
                            "WorldBegin\nLightSource \"point\" \"rgb I\" [ 1 1 1 ]\nShape \"sphere\"\n");
  };
  struct Case {
    std::string filename, extra, message;
  } cases[] = {
      {dir + "/missing/x.exr", "", "scene.pbrt:4:5: error: cannot write image '" + dir + "/missing/x.exr': the folder"},
      {dir + "/x.gif2", "", "scene.pbrt:4:5: error: cannot write image '" + dir + "/x.gif2': unknown extension '.gif2'"},
      {dir + "/x.png", " \"string aovs\" \"albedo\"", "scene.pbrt:4:5: error: AOVs (albedo) are written as EXR layers"},
  };
  for (const Case& c : cases) {
    std::string scene = scene_with_filename(c.filename, c.extra);
    Timed t = run_timed({"render", scene, "--spp", "1000000000", "-q"});
    EXPECT_EQ(t.r.exit_code, 1) << c.message;
    EXPECT_THAT(t.r.err, HasSubstr(c.message));
    EXPECT_LT(t.seconds, kMaxSeconds) << c.message;
  }
  // The same scene with a good filename renders (the check is not over-eager).
  std::string scene = scene_with_filename(dir + "/good.exr", "");
  test::CommandResult ok = test::run_penumbra({"render", scene, "--spp", "1", "--res", "8x8", "-q"});
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_TRUE(fs::is_regular_file(dir + "/good.exr"));
}

TEST(OutputChecks, MergeAndConvergeCheckTheirOutputsFirst) {
  std::string dir = test::temp_dir("merge-converge-outputs");
  // The "part" is not even an EXR: the output is refused before any part is read.
  auto merge = test::run_penumbra({"merge", kCornell, "-o", dir + "/missing/m.exr"});
  EXPECT_EQ(merge.exit_code, 1);
  EXPECT_THAT(merge.err, HasSubstr("-o: cannot write image '" + dir + "/missing/m.exr': the folder"));
  Timed conv = run_timed({"converge", kCornell, "--configs", "path", "--time", "1000", "-o", "/proc/study"});
  EXPECT_EQ(conv.r.exit_code, 1);
  EXPECT_THAT(conv.r.err, HasSubstr("-o: cannot create the folder '/proc/study'"));
  EXPECT_LT(conv.seconds, kMaxSeconds);
}

TEST(OutputChecks, FailedWriteKeepsTheOldFileAndLeavesNoTemporary) {
  std::string dir = test::temp_dir("atomic-failure");
  std::string path = test::write_file(dir, "image.exr", "the previous image");
  EXPECT_THROW(write_atomically(path,
                                [](const std::string& temporary) {
                                  test::write_file(fs::path(temporary).parent_path().string(),
                                                   fs::path(temporary).filename().string(), "half an ima");
                                  throw Error("disk full");
                                }),
               Error);
  EXPECT_EQ(test::read_file(path), "the previous image");
  EXPECT_EQ(files_in(dir), 1u) << "the temporary file was left behind";
  // A malformed image (no pixels) is refused without touching the old file either.
  ImageRgb empty;
  EXPECT_THROW(write_image(path, empty), Error);
  EXPECT_EQ(test::read_file(path), "the previous image");
  EXPECT_EQ(files_in(dir), 1u);
}

TEST(OutputChecks, ImagesAreRenamedIntoPlaceReplacingSymlinksWithNormalPermissions) {
  std::string dir = test::temp_dir("atomic-symlink");
  std::string target = test::write_file(dir, "elsewhere.exr", "must not be overwritten");
  std::string link = dir + "/out.exr";
  fs::create_symlink(target, link);
  mode_t old_mask = umask(022);
  test::CommandResult r = test::run_penumbra({"render", kCornell, "-o", link, "--spp", "1", "--res", "8x8", "-q"});
  umask(old_mask);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(fs::is_symlink(link)) << "the symlink was followed instead of replaced";
  EXPECT_EQ(test::read_file(target), "must not be overwritten");
  ImageRgb img = read_image(link);
  EXPECT_EQ(img.width, 8);
  struct stat st{};
  ASSERT_EQ(stat(link.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0644u) << "the image kept the temporary file's 0600";
  EXPECT_EQ(files_in(dir), 2u) << "a temporary file was left behind";
}

TEST(OutputChecks, OutputPathProblemAcceptsWritableFolders) {
  std::string dir = test::temp_dir("writable");
  EXPECT_EQ(output_path_problem(dir + "/x.exr"), "");
  EXPECT_EQ(files_in(dir), 0u) << "the probe file was not removed";
  EXPECT_THAT(output_path_problem(""), HasSubstr("empty"));
  EXPECT_EQ(image_output_problem(dir + "/x.tif"), "");
  EXPECT_EQ(image_output_problem(dir + "/x.png"), "");  // the shipped OpenColorIO config is found
}
