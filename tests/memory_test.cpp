// Memory that is announced: the film, the splat buffers, bdpt's light-vertex cache and SPPM's
// per-pixel statistics are estimated before they are allocated, and a render that cannot fit fails
// at once with the estimate instead of std::bad_alloc or the out-of-memory killer. The film's
// estimate is checked against the memory a film really takes.
#include "image/film_rgb.h"
#include "support/command.h"

#include <penumbra/error.h>
#include <penumbra/memory.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>

using namespace penumbra;
using ::testing::HasSubstr;
using ::testing::MatchesRegex;

namespace {

const std::string kCornell = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt";

// Resident bytes of this process (/proc/self/statm, second field in pages).
uint64_t resident_bytes() {
  std::ifstream in("/proc/self/statm");
  uint64_t size = 0, resident = 0;
  in >> size >> resident;
  return resident * static_cast<uint64_t>(sysconf(_SC_PAGESIZE));
}

PixelFilter box_filter() {
  ParamSet p;
  p.validate(pixel_filter_params("box"), "filter");
  return PixelFilter("box", p, {});
}

test::CommandResult render_limited(uint64_t limit, std::vector<std::string> extra) {
  std::string dir = test::temp_dir("memory-render");
  std::vector<std::string> args = {"render", kCornell, "-o", dir + "/o.exr", "-q", "--spp", "1"};
  args.insert(args.end(), extra.begin(), extra.end());
  return test::run_penumbra(args, "PENUMBRA_MEMORY_LIMIT=" + std::to_string(limit));
}

}  // namespace

TEST(Memory, AbsurdResolutionFailsAtOnceWithTheEstimate) {
  std::string dir = test::temp_dir("memory-absurd");
  auto t0 = std::chrono::steady_clock::now();
  test::CommandResult r =
      test::run_penumbra({"render", kCornell, "-o", dir + "/o.exr", "-q", "--res", "200000x200000"});
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.exit_code, 1) << r.err;  // not a signal (-1) from the out-of-memory killer
  // 4e10 pixels x 56 bytes = 2.24e12 bytes = 2.0 TiB.
  EXPECT_THAT(r.err, HasSubstr("error: the 200000x200000 film would need an estimated 2.0 TiB (56 bytes per pixel), "
                               "but only "));
  EXPECT_THAT(r.err, HasSubstr(" of memory are available"));
  EXPECT_THAT(r.err, ::testing::Not(HasSubstr("bad_alloc")));
  EXPECT_LT(seconds, 10.0);  // about 0.5 s unloaded; the film alone would take minutes to zero-fill
  EXPECT_FALSE(std::ifstream(dir + "/o.exr").good());
}

TEST(Memory, EveryLargeStructureIsAnnouncedBeforeRendering) {
  // A limit of 20 MB lets the 512x512 film (56 bytes per pixel: 14.7 MB) through and stops the
  // structure behind it; 400 MB lets everything through (negative control).
  const uint64_t tight = 20'000'000, ample = 400'000'000;
  struct Case {
    std::vector<std::string> args;
    std::string message;
  } cases[] = {
      {{"--integrator", "sppm"}, "error: sppm's per-pixel statistics would need an estimated "},
      {{"--integrator", "lighttracing"},
       "error: the film's splat buffers would need an estimated 34.0 MiB (512x512 pixels, 48 bytes each in 2 MiB chunks, "
       "for each of 2 threads)"},
      {{"--integrator", "bdpt", "--param", "hrr=true"}, "error: bdpt's light-vertex cache would need an estimated "},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = {"--res", "512x512", "--threads", "2"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    test::CommandResult r = render_limited(tight, args);
    EXPECT_EQ(r.exit_code, 1) << c.message << r.err;
    EXPECT_THAT(r.err, HasSubstr(c.message));
    EXPECT_THAT(r.err, HasSubstr("but only 19.1 MiB of memory are available"));
    r = render_limited(ample, {"--res", "64x64", "--threads", "2", c.args[0], c.args[1]});
    EXPECT_EQ(r.exit_code, 0) << r.err;
  }
  // The film itself under a limit below its 14.7 MB.
  test::CommandResult r = render_limited(10'000'000, {"--res", "512x512"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("error: the 512x512 film would need an estimated 14.0 MiB (56 bytes per pixel)"));
}

TEST(Memory, FilmEstimateCoversWhatTheFilmTakes) {
  // The accumulator is 32 of the 56 estimated bytes per pixel (the rest is the output images, made
  // when the render is written). Measured as the growth of resident memory: the film zero-fills its
  // accumulator, so every page is touched.
  const Point2i res(2000, 1500);
  const uint64_t pixels = 3'000'000;
  EXPECT_EQ(FilmRgb::estimated_bytes(res, {}), pixels * 56);
  AovSet all{true, true, true, true, true, true};
  EXPECT_GT(FilmRgb::estimated_bytes(res, all), pixels * 56 + pixels * 100);
  uint64_t before = resident_bytes();
  auto film = std::make_unique<FilmRgb>(res, box_filter());
  uint64_t grown = resident_bytes() - before;
  EXPECT_GT(grown, pixels * 32 * 95 / 100) << "the film took less than its accumulator: the measure is broken";
  EXPECT_LT(grown, FilmRgb::estimated_bytes(res, {})) << "the film took more than estimated";
  // With every AOV: the buffers alone stay below the estimate too.
  film.reset();
  before = resident_bytes();
  film = std::make_unique<FilmRgb>(res, box_filter(), all);
  grown = resident_bytes() - before;
  EXPECT_LT(grown, FilmRgb::estimated_bytes(res, all));
}

TEST(Memory, AvailableMemoryHonoursTheLimitAndRequireMemoryNamesTheStructure) {
  uint64_t machine = available_memory();
  EXPECT_GT(machine, 1u << 20);
  setenv("PENUMBRA_MEMORY_LIMIT", "5000000", 1);
  EXPECT_EQ(available_memory(), 5'000'000u);
  try {
    require_memory(6'000'000, "the test structure", "3 things of 2 MB");
    ADD_FAILURE() << "6 MB were accepted under a 5 MB limit";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "the test structure would need an estimated 5.7 MiB (3 things of 2 MB), but only 4.8 MiB "
                           "of memory are available");
  }
  EXPECT_NO_THROW(require_memory(4'000'000, "a smaller one"));
  unsetenv("PENUMBRA_MEMORY_LIMIT");
  EXPECT_EQ(format_bytes(100), "100 bytes");
  EXPECT_EQ(format_bytes(3u << 30), "3.0 GiB");
}
