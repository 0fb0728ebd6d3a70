// Interrupted renders keep their work: the real program gets SIGINT or SIGTERM in the middle of a
// render, writes its image and a checkpoint and exits with 75; `--resume` continues, and the result
// equals the uninterrupted render bit for bit for every integrator (other thread count too). A
// second signal exits at once; a checkpoint of another render, or a damaged one, is refused.
#include "render/render_session.h"
#include "support/command.h"

#include <penumbra/image.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <fmt/core.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <thread>

using namespace penumbra;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

extern char** environ;

namespace {

const std::string kScene = std::string(PENUMBRA_SOURCE_DIR) + "/scenes/cornell-box/scene.pbrt";

// The program started in the background with stderr in `err_file`.
pid_t spawn_penumbra(const std::vector<std::string>& args, const std::string& err_file) {
  std::vector<std::string> all = {PENUMBRA_BINARY};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = -1;
  int rc = posix_spawn(&pid, PENUMBRA_BINARY, &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? pid : -1;
}

int wait_exit_code(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

bool wait_for_file(const std::string& path, pid_t pid) {
  auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60)) {
    if (fs::exists(path)) return true;
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return fs::exists(path);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

struct Case {
  std::string integrator;
  int spp;       // long enough that a signal after the first checkpoint lands mid-render
  int signal;
  bool spectral = false;  // per-sample wavelengths (path), or per-pass ones (sppm) that a resume must redraw alike
  std::string name() const { return integrator + (spectral ? "_spectral" : ""); }
};

std::vector<std::string> render_args(const Case& c, const std::string& out, int threads) {
  std::vector<std::string> args = {"render", kScene, "--integrator", c.integrator, "--spp", std::to_string(c.spp),
                                   "--res", "40x40", "--threads", std::to_string(threads), "-o", out, "-q"};
  if (c.spectral) args.push_back("--spectral");
  return args;
}

class Interrupt : public ::testing::TestWithParam<Case> {};

TEST_P(Interrupt, ResumeGivesTheUninterruptedImageBitForBit) {
  Case c = GetParam();
  std::string dir = test::temp_dir("interrupt-" + c.name());
  std::string full = dir + "/full.exr", part = dir + "/part.exr", ckpt = dir + "/part.ckpt";
  test::CommandResult ref = test::run_penumbra(render_args(c, full, 2));
  ASSERT_EQ(ref.exit_code, 0) << ref.err;

  // Interrupted as soon as the first periodic checkpoint exists, i.e. a pass or more into the render.
  std::vector<std::string> args = render_args(c, part, 2);
  args.insert(args.end(), {"--checkpoint", ckpt, "--checkpoint-every", "0.02"});
  pid_t pid = spawn_penumbra(args, dir + "/err.txt");
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(wait_for_file(ckpt, pid));
  kill(pid, c.signal);
  int code = wait_exit_code(pid);
  std::string err = test::read_file(dir + "/err.txt");
  ASSERT_EQ(code, 75) << "the render ended before the signal or did not handle it: " << err;
  EXPECT_THAT(err, HasSubstr(c.signal == SIGTERM ? "interrupted (SIGTERM)" : "interrupted (SIGINT)"));
  EXPECT_THAT(err, HasSubstr("--resume " + ckpt));
  // The image of what was done is written, and is not the finished render.
  ImageRgb partial = read_image(part);
  ImageRgb reference = read_image(full);
  ASSERT_EQ(partial.pixels.size(), reference.pixels.size());
  EXPECT_NE(partial.pixels, reference.pixels);

  // Resumed on one thread (the reference used two).
  std::vector<std::string> resume = render_args(c, part, 1);
  resume.insert(resume.end(), {"--resume", ckpt});
  test::CommandResult r = test::run_penumbra(resume);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ImageRgb resumed = read_image(part);
  ASSERT_EQ(resumed.pixels.size(), reference.pixels.size());
  size_t differing = 0;
  for (size_t i = 0; i < resumed.pixels.size(); ++i) differing += resumed.pixels[i] != reference.pixels[i];
  EXPECT_EQ(differing, 0u) << "of " << resumed.pixels.size() << " values";
}

INSTANTIATE_TEST_SUITE_P(EveryIntegrator, Interrupt,
                         ::testing::Values(Case{"path", 1500, SIGINT}, Case{"bdpt", 300, SIGTERM},
                                           Case{"lighttracing", 600, SIGINT}, Case{"sppm", 800, SIGTERM},
                                           Case{"path", 1500, SIGINT, true}, Case{"sppm", 800, SIGTERM, true}),
                         [](const auto& info) { return info.param.name(); });

TEST(Interrupt, SecondSignalExitsAtOnceWithoutWriting) {
  std::string dir = test::temp_dir("interrupt-twice");
  std::string out = dir + "/out.exr", ckpt = dir + "/out.ckpt", err = dir + "/err.txt";
  // Passes of up to 16 spp at 160x160 with bdpt last long enough for a second signal to arrive
  // inside the pass the first one lets finish.
  pid_t pid = spawn_penumbra({"render", kScene, "--integrator", "bdpt", "--spp", "100000", "--res", "160x160", "-o",
                              out, "-q", "--checkpoint", ckpt, "--checkpoint-every", "0.02"},
                             err);
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(wait_for_file(ckpt, pid));
  kill(pid, SIGINT);
  // Signals of one kind do not queue: the second is sent once the first has been handled.
  for (int i = 0; i < 5000 && test::read_file(err).find("interrupted:") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  kill(pid, SIGINT);
  EXPECT_EQ(wait_exit_code(pid), 130);
  EXPECT_THAT(test::read_file(err), HasSubstr("second signal"));
  EXPECT_FALSE(fs::exists(out));
}

class Refusal : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::temp_dir("refusal");
    fs::copy(fs::path(kScene).parent_path(), dir_, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
    scene_ = dir_ + "/" + fs::path(kScene).filename().string();
    ckpt_ = dir_ + "/c.ckpt";
    pid_t pid = spawn_penumbra({"render", scene_, "--spp", "100000", "--res", "16x16", "--threads", "1", "-o",
                                dir_ + "/a.exr", "-q", "--checkpoint", ckpt_, "--checkpoint-every", "0.01"},
                               dir_ + "/err.txt");
    ASSERT_GT(pid, 0);
    ASSERT_TRUE(wait_for_file(ckpt_, pid));
    kill(pid, SIGTERM);
    ASSERT_EQ(wait_exit_code(pid), 75) << test::read_file(dir_ + "/err.txt");
  }
  test::CommandResult resume(const std::string& scene, std::vector<std::string> extra, std::string ckpt = "") {
    std::vector<std::string> args = {"render", scene, "--spp", "100000", "--res", "16x16", "-o", dir_ + "/b.exr", "-q",
                                     "--resume", ckpt.empty() ? ckpt_ : ckpt};
    args.insert(args.end(), extra.begin(), extra.end());
    auto t0 = std::chrono::steady_clock::now();
    test::CommandResult r = test::run_penumbra(args);
    seconds_ = std::max(seconds_, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    return r;
  }
  std::string dir_, scene_, ckpt_;
  double seconds_ = 0.0;
};

TEST_F(Refusal, OtherSettingsAreNamed) {
  test::CommandResult r = resume(scene_, {"--seed", "7"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("belongs to another render; seed: checkpoint '0', this render '7'"));
  r = resume(scene_, {"--integrator", "bdpt"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("integrator: checkpoint 'path', this render 'bdpt'"));
  EXPECT_FALSE(fs::exists(dir_ + "/b.exr"));
}

TEST_F(Refusal, AChangedSceneIsRefused) {
  std::string text = test::read_file(scene_);
  size_t at = text.find("WorldBegin");
  ASSERT_NE(at, std::string::npos);
  std::ofstream(scene_) << text.substr(0, at) << "WorldBegin\nShape \"sphere\" \"float radius\" [ 0.02 ]\n"
                        << text.substr(at + 10);
  test::CommandResult r = resume(scene_, {});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("another version of the scene"));
}

TEST_F(Refusal, DamagedOrForeignFilesAreRefusedBeforeRendering) {
  std::string bytes = test::read_file(ckpt_);
  std::ofstream(ckpt_, std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() / 2);
  test::CommandResult r = resume(scene_, {});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("damaged or truncated"));
  std::ofstream(ckpt_, std::ios::trunc) << "not a checkpoint\n";
  r = resume(scene_, {});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("not a Penumbra checkpoint"));
  r = resume(scene_, {}, dir_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("not a regular file"));
  // 100000 spp at 16x16 would take minutes: the refusals came before any rendering.
  EXPECT_LT(seconds_, 20.0);
}

TEST(Checkpoint, UnwritableCheckpointFolderIsAnErrorBeforeRendering) {
  test::CommandResult r = test::run_penumbra({"render", kScene, "--spp", "100000", "--res", "16x16", "-o",
                                              test::temp_dir("ckpt-folder") + "/a.exr", "-q", "--checkpoint",
                                              "/nonexistent-folder/c.ckpt"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--checkpoint /nonexistent-folder/c.ckpt: folder '/nonexistent-folder' does not exist"));
}

}  // namespace

// The race behind a flaky CI run: the handlers were removed when render() returned, so a second
// signal that arrived while the image was being written killed the process with no message. They
// now stay installed until the result (and with it the outputs) is done with.
TEST(Interrupt, HandlersStayInstalledWhileTheOutputsAreWritten) {
  struct sigaction before {};
  sigaction(SIGINT, nullptr, &before);
  ASSERT_EQ(before.sa_handler, SIG_DFL);
  RenderSettings settings;
  settings.scene_file = kScene;
  settings.resolution = std::make_pair(8, 8);
  settings.spp = 1;
  settings.quiet = true;
  settings.output = test::temp_dir("interrupt-lifetime") + "/out.exr";
  settings.handle_signals = true;
  std::optional<RenderResult> result = render(settings);
  struct sigaction during {};
  sigaction(SIGINT, nullptr, &during);
  EXPECT_NE(during.sa_handler, SIG_DFL) << "render() returned with the default SIGINT action back";
  write_outputs(settings, *result);
  sigaction(SIGINT, nullptr, &during);
  EXPECT_NE(during.sa_handler, SIG_DFL);
  result.reset();
  struct sigaction after {};
  sigaction(SIGINT, nullptr, &after);
  EXPECT_EQ(after.sa_handler, SIG_DFL) << "the previous handler comes back once the result is gone";
}
