#include "render/progress.h"

#include <fmt/core.h>

#include <cstdio>
#include <unistd.h>

namespace penumbra {

ProgressReporter::ProgressReporter(std::string unit, bool quiet)
    : unit_(std::move(unit)), quiet_(quiet), tty_(isatty(STDERR_FILENO) != 0) {}

static std::string clock(double s) {
  if (!(s >= 0.0) || s > 1e7) return "--:--";
  int t = static_cast<int>(s + 0.5);
  return t >= 3600 ? fmt::format("{}:{:02}:{:02}", t / 3600, t / 60 % 60, t % 60)
                   : fmt::format("{:02}:{:02}", t / 60, t % 60);
}

void ProgressReporter::update(uint64_t done, uint64_t total, double elapsed, double budget) {
  if (quiet_ || total == 0) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (done < last_done_) return;
  last_done_ = done;
  double fraction = static_cast<double>(done) / static_cast<double>(total);
  if (budget > 0.0) fraction = std::max(fraction, std::min(1.0, elapsed / budget));
  int decile = static_cast<int>(fraction * 10.0);
  if (tty_ ? (elapsed - last_print_ < 0.1 && done != total) : decile == last_decile_) return;
  last_print_ = elapsed;
  last_decile_ = decile;
  double remaining = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : -1.0;
  double rate = elapsed > 0.0 ? static_cast<double>(done) / elapsed : 0.0;
  std::string line = fmt::format("{:5.1f}% {} elapsed, {} left, {:.3g} M{}/s", 100.0 * fraction,
                                 clock(elapsed), clock(remaining), rate * 1e-6, unit_);
  if (tty_) {
    int bar = static_cast<int>(fraction * 30.0);
    std::fprintf(stderr, "\r[%s%s] %s ", std::string(bar, '=').c_str(),
                 std::string(30 - bar, ' ').c_str(), line.c_str());
  } else {
    std::fprintf(stderr, "progress: %s\n", line.c_str());
  }
  std::fflush(stderr);
  printed_ = true;
}

void ProgressReporter::finish(double elapsed) {
  if (quiet_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (tty_ && printed_) std::fprintf(stderr, "\n");
  std::fprintf(stderr, "rendered in %s (%.2f s)\n", clock(elapsed).c_str(), elapsed);
}

}  // namespace penumbra
