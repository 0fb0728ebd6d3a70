// Loading code that cannot be tricked: no binary or plugin, built or installed, has an empty or
// relative RUNPATH entry (which makes the loader search the current folder: a libm.so.6 planted in a
// scene folder would run); plugins come only from the documented absolute folders; a truncated or
// corrupt plugin is refused by its ELF headers before dlopen, and `penumbra plugins` lists the rest.
#include "support/command.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <regex>

using namespace penumbra;
using ::testing::HasSubstr;
using ::testing::Not;
namespace fs = std::filesystem;

namespace {

const std::string kBuild = PENUMBRA_BINARY_DIR;
const std::string kPlugins = kBuild + "/lib/penumbra/plugins";

std::string run(const std::string& cmd) {
  std::string out;
  std::unique_ptr<FILE, int (*)(FILE*)> p(popen(cmd.c_str(), "r"), pclose);
  if (!p) return out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p.get())) > 0) out.append(buf, n);
  return out;
}

bool is_elf(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  char magic[4] = {};
  in.read(magic, 4);
  return in.gcount() == 4 && magic[0] == 0x7f && magic[1] == 'E' && magic[2] == 'L' && magic[3] == 'F';
}

// The entries of a RUNPATH or RPATH that make the loader search somewhere that depends on the
// current folder: empty ones and relative ones ($ORIGIN entries are relative to the binary, fine).
std::vector<std::string> unsafe_entries(const std::string& path_list) {
  std::vector<std::string> bad;
  size_t start = 0;
  while (true) {
    size_t end = path_list.find(':', start);
    std::string entry = path_list.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (entry.empty() || (entry[0] != '/' && entry.rfind("$ORIGIN", 0) != 0 && entry.rfind("${ORIGIN}", 0) != 0))
      bad.push_back(entry.empty() ? "(empty)" : entry);
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return bad;
}

// Every ELF file under `root` with its RUNPATH/RPATH problems, as read by binutils' readelf.
struct Checked {
  size_t files = 0, with_paths = 0;
  std::vector<std::string> problems;
};

Checked check_tree(const fs::path& root) {
  Checked c;
  static const std::regex re(R"(\((RUNPATH|RPATH)\)\s+Library (?:runpath|rpath): \[([^\]]*)\])");
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (!e.is_regular_file() || fs::is_symlink(e.path()) || !is_elf(e.path())) continue;
    ++c.files;
    std::string dyn = run("readelf -d '" + e.path().string() + "' 2>&1");
    for (std::sregex_iterator it(dyn.begin(), dyn.end(), re), end; it != end; ++it) {
      ++c.with_paths;
      for (const std::string& bad : unsafe_entries((*it)[2]))
        c.problems.push_back(e.path().string() + ": " + (*it)[1].str() + " [" + (*it)[2].str() + "] has entry " + bad);
    }
  }
  return c;
}

}  // namespace

TEST(Loading, UnsafeEntryCheckFindsTheOldEmptyEntry) {
  // The RUNPATH the program had: CMake's install padding left an empty last entry.
  EXPECT_EQ(unsafe_entries("$ORIGIN/../lib:/work/main/build/lib:"), std::vector<std::string>{"(empty)"});
  EXPECT_EQ(unsafe_entries(":/usr/lib"), std::vector<std::string>{"(empty)"});
  EXPECT_EQ(unsafe_entries("lib:$ORIGIN/x"), std::vector<std::string>{"lib"});
  EXPECT_TRUE(unsafe_entries("$ORIGIN/../lib").empty());
  EXPECT_TRUE(unsafe_entries("$ORIGIN/../..:/opt/penumbra/lib").empty());
}

TEST(Loading, NoBuiltBinaryOrPluginHasAnEmptyOrRelativeRunpathEntry) {
  ASSERT_NE(run("readelf --version"), "") << "readelf (binutils) is needed";
  Checked c;
  for (const char* sub : {"bin", "lib", "test-plugins"}) {
    Checked t = check_tree(kBuild + "/" + sub);
    c.files += t.files;
    c.with_paths += t.with_paths;
    c.problems.insert(c.problems.end(), t.problems.begin(), t.problems.end());
  }
  EXPECT_GT(c.files, 40u) << "the build tree's binaries were not found";
  EXPECT_GT(c.with_paths, 20u) << "readelf's RUNPATH lines were not recognised";
  EXPECT_TRUE(c.problems.empty()) << ::testing::PrintToString(c.problems);
}

TEST(Loading, NoInstalledBinaryOrPluginHasAnEmptyOrRelativeRunpathEntry) {
  std::string prefix = test::temp_dir("install-prefix");
  std::string log = run("cmake --install '" + kBuild + "' --prefix '" + prefix + "' 2>&1");
  ASSERT_TRUE(fs::exists(prefix + "/bin/penumbra")) << log;
  Checked c = check_tree(prefix);
  EXPECT_GT(c.files, 15u);
  EXPECT_GT(c.with_paths, 15u);
  EXPECT_TRUE(c.problems.empty()) << ::testing::PrintToString(c.problems);
  // The installed program finds its core and plugins through $ORIGIN alone.
  std::string out = run("'" + prefix + "/bin/penumbra' plugins 2>&1");
  EXPECT_THAT(out, HasSubstr("integrator 'path'"));
  EXPECT_THAT(out, HasSubstr(prefix + "/lib/penumbra/plugins"));
  // ... and the core its image library beside itself: an EXR and a PNG are written.
  std::string scene = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt";
  std::string render = "'" + prefix + "/bin/penumbra' render '" + scene + "' --spp 1 --res 8x8 -q -o '" + prefix;
  for (const char* name : {"/o.exr", "/o.png"}) {
    out = run(render + name + "' 2>&1; echo rc=$?");
    EXPECT_THAT(out, HasSubstr("rc=0")) << out;
    EXPECT_TRUE(fs::is_regular_file(prefix + name)) << name;
  }
  // Without the image library the render is refused before it starts, naming what is missing.
  fs::remove(prefix + "/lib/penumbra/libpenumbra-oiio.so");
  out = run(render + "/p.exr' 2>&1; echo rc=$?");
  EXPECT_THAT(out, HasSubstr("-o: cannot write image '" + prefix + "/p.exr': Penumbra's image library '" + prefix +
                             "/lib/penumbra/libpenumbra-oiio.so' is missing: reinstall Penumbra"));
  EXPECT_THAT(out, HasSubstr("rc=1"));
  EXPECT_THAT(out, Not(HasSubstr("rendered in")));
}

// Image files go through OpenImageIO in a library the core opens on first use
// (core/src/image/image_codecs.h): a process that reads and writes no image file does not load
// OpenImageIO and the ~260 shared libraries it links; one that writes its render does.
TEST(Loading, OnlyAProcessThatTouchesAnImageFileLoadsOpenImageIO) {
  std::string dir = test::temp_dir("lazy-image-library");
  std::string bin = "'" + std::string(PENUMBRA_BINARY) + "'";
  std::string listed = run("LD_DEBUG=files " + bin + " plugins 2>&1 >/dev/null");
  ASSERT_THAT(listed, HasSubstr("libpenumbra-core.so")) << "LD_DEBUG traced nothing";
  EXPECT_THAT(listed, HasSubstr("penumbra-texture-imagemap.so"));
  EXPECT_THAT(listed, Not(HasSubstr("libOpenImageIO")));
  std::string scene = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt";
  std::string rendered = run("LD_DEBUG=files " + bin + " render '" + scene + "' --spp 1 --res 8x8 -q -o '" + dir +
                             "/o.exr' 2>&1 >/dev/null");
  EXPECT_THAT(rendered, HasSubstr("lib/penumbra/libpenumbra-oiio.so"));
  EXPECT_THAT(rendered, HasSubstr("libOpenImageIO"));
  EXPECT_TRUE(fs::is_regular_file(dir + "/o.exr"));
}

TEST(Loading, ALibraryPlantedInTheCurrentFolderIsNotLoaded) {
  // A scene folder with a fake libm.so.6: a loader that searched the current folder would fail on it
  // ("file too short") before main; a complete fake would run its own code.
  std::string dir = test::temp_dir("planted-libm");
  test::write_file(dir, "libm.so.6", "not a library");
  test::write_file(dir, "libpenumbra-core.so", "not a library");
  std::string out = run("cd '" + dir + "' && '" + std::string(PENUMBRA_BINARY) + "' --version 2>&1; echo rc=$?");
  EXPECT_THAT(out, HasSubstr("rc=0")) << out;
  EXPECT_THAT(out, Not(HasSubstr("libm.so.6"))) << out;
}

TEST(Loading, TruncatedAndCorruptPluginsAreRefusedAndTheRestListed) {
  std::string dir = test::temp_dir("broken-plugins");
  {
    std::ifstream in(kPlugins + "/penumbra-integrator-path.so", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_GT(bytes.size(), 5000u);
    test::write_file(dir, "penumbra-integrator-cut.so", bytes.substr(0, 5000));
    // Headers intact, but the section header table points past the end: cut at 95 %.
    test::write_file(dir, "penumbra-integrator-almost.so", bytes.substr(0, bytes.size() * 95 / 100));
  }
  test::write_file(dir, "penumbra-sampler-text.so", "this is not a shared object at all\n");
  test::write_file(dir, "penumbra-light-tiny.so", "\x7f" "ELF");
  fs::copy_file(kPlugins + "/penumbra-light-point.so", dir + "/penumbra-light-pointcopy.so");
  std::string env = "PENUMBRA_PLUGIN_PATH='" + dir + "'";
  test::CommandResult r = test::run_penumbra({"plugins"}, env);
  EXPECT_EQ(r.exit_code, 1) << "a crash shows as -1 (SIGBUS)";
  for (const char* name : {"cut", "almost"})
    EXPECT_THAT(r.err, HasSubstr("error: plugin " + dir + "/penumbra-integrator-" + name +
                                 ".so cannot be loaded: the file is "));
  EXPECT_THAT(r.err, HasSubstr("penumbra-integrator-cut.so cannot be loaded: the file is 5000 bytes, but its "));
  EXPECT_THAT(r.err, HasSubstr("it is truncated or corrupt; rebuild or reinstall it"));
  EXPECT_THAT(r.err, HasSubstr("penumbra-sampler-text.so cannot be loaded: it is not an ELF file"));
  EXPECT_THAT(r.err, HasSubstr("penumbra-light-tiny.so cannot be loaded: the file is 4 bytes, too short for an ELF header"));
  // The rest are listed: every plugin of the build and the intact copy.
  for (const char* listed : {"integrator 'path'", "integrator 'bdpt'", "integrator 'sppm'", "sampler 'sobol'",
                             "bsdf 'diffuse'", "light 'infinite'"})
    EXPECT_THAT(r.out, HasSubstr(listed));
  EXPECT_THAT(r.out, HasSubstr(dir + "/penumbra-light-pointcopy.so"));
  // A render that names the truncated plugin gets the same refusal, located.
  std::string scene = test::write_file(dir, "scene.pbrt", "Integrator \"cut\"\nWorldBegin\n");
  r = test::run_penumbra({"render", scene, "-o", dir + "/o.exr", "-q"}, env);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("scene.pbrt:1:1: error: plugin " + dir + "/penumbra-integrator-cut.so cannot be loaded"));
  // ... and one that does not name it renders.
  r = test::run_penumbra({"render", std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt", "-o",
                          dir + "/o.exr", "--spp", "1", "--res", "8x8", "-q"}, env);
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST(Loading, PluginsComeOnlyFromAbsoluteFolders) {
  // A plugin in the current folder must not be found through an empty or relative entry.
  std::string dir = test::temp_dir("relative-plugin-path");
  fs::create_directories(dir + "/plugins");
  fs::copy_file(kPlugins + "/penumbra-integrator-path.so", dir + "/penumbra-integrator-here.so");
  fs::copy_file(kPlugins + "/penumbra-integrator-path.so", dir + "/plugins/penumbra-integrator-there.so");
  std::string cmd = "cd '" + dir + "' && PENUMBRA_PLUGIN_PATH=':plugins::' '" + std::string(PENUMBRA_BINARY) +
                    "' plugins 2>&1";
  std::string out = run(cmd);
  EXPECT_THAT(out, HasSubstr("integrator 'path'"));
  EXPECT_THAT(out, Not(HasSubstr("penumbra-integrator-here.so")));
  EXPECT_THAT(out, Not(HasSubstr("penumbra-integrator-there.so")));
  EXPECT_THAT(out, HasSubstr("warning: $PENUMBRA_PLUGIN_PATH entry 'plugins' is not an absolute path and is ignored"));
  // The same folder given absolutely is searched (the check is not over-eager).
  out = run("PENUMBRA_PLUGIN_PATH='" + dir + "/plugins' '" + std::string(PENUMBRA_BINARY) + "' plugins 2>&1");
  EXPECT_THAT(out, HasSubstr(dir + "/plugins/penumbra-integrator-there.so"));
}
