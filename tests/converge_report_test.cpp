// The HTML report of `penumbra converge` opens in headless Chromium (Debian's chromium, installed by
// scripts/install-deps.sh) with no console message, and a screenshot of it holds the plots and the
// images. Negative control: a page with a script error does log a console message, so its absence
// means something.
#include "image/image_io.h"
#include "support/command.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>

using namespace penumbra;
using ::testing::HasSubstr;
using ::testing::Not;

namespace {

struct Browser {
  std::string log;
  int exit_code = -1;
};

// Loads `html` in headless Chromium, writes a screenshot to `png`, and returns its log (console
// messages are logged as "INFO:CONSOLE").
Browser open_in_chromium(const std::string& html, const std::string& png, const std::string& profile) {
  std::string cmd = "timeout 120 chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
                    "--disable-background-networking --disable-component-update --disable-sync --user-data-dir=" +
                    profile + " --enable-logging=stderr --v=0 --window-size=1300,2400 --screenshot=" + png + " file://" +
                    html + " 2>&1";
  Browser b;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return b;
  char buf[4096];
  while (fgets(buf, sizeof buf, p)) b.log += buf;
  b.exit_code = pclose(p);
  return b;
}

}  // namespace

TEST(ConvergeReport, OpensInHeadlessChromiumWithoutConsoleErrors) {
  ASSERT_EQ(std::system("command -v chromium >/dev/null 2>&1"), 0)
      << "chromium is not installed (scripts/install-deps.sh installs Debian's chromium)";
  std::string dir = test::temp_dir("converge-report");
  auto r = test::run_penumbra({"converge", std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt",
                               "--configs", "path:independent,path:sobol", "--make-reference", "1", "--time", "0.3",
                               "--runs", "3", "--snapshots", "3", "--res", "24x24", "-o", dir},
                              "PENUMBRA_REFERENCE_CACHE=" + dir + "/cache");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::string html = test::read_file(dir + "/report.html");
  for (const char* part : {"<svg class=\"plot\"", "Ratios at equal time", "data:image/png;base64,", "id=\"wipe\"",
                           "path:independent", "path:sobol", "error of path:sobol"})
    EXPECT_THAT(html, HasSubstr(part));
  EXPECT_THAT(html, Not(HasSubstr("src=\"http")));  // self-contained: nothing fetched

  Browser ok = open_in_chromium(dir + "/report.html", dir + "/shot.png", dir + "/profile");
  EXPECT_EQ(ok.exit_code, 0) << ok.log;
  EXPECT_THAT(ok.log, Not(HasSubstr("CONSOLE"))) << ok.log;
  ASSERT_TRUE(std::filesystem::exists(dir + "/shot.png")) << ok.log;
  // The screenshot is not a blank page: its pixels vary (plots, tables and images were drawn).
  ImageRgb shot = read_image(dir + "/shot.png");
  ASSERT_GT(shot.pixels.size(), 0u);
  double mean = 0.0, var = 0.0;
  for (float v : shot.pixels) mean += v;
  mean /= shot.pixels.size();
  for (float v : shot.pixels) var += (v - mean) * (v - mean);
  var /= shot.pixels.size();
  EXPECT_GT(var, 1e-3) << "the screenshot is uniform";

  std::string bad = test::write_file(dir, "bad.html", "<html><body><script>undefined_function();</script></body></html>");
  Browser broken = open_in_chromium(bad, dir + "/bad.png", dir + "/profile-bad");
  EXPECT_THAT(broken.log, HasSubstr("CONSOLE")) << "a script error must show in the log";
}
