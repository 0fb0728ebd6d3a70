// Progress on stderr: a single updating line on a terminal, plain lines every 10 % otherwise.
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace penumbra {

class ProgressReporter {
 public:
  /// `unit` names what is counted ("samples"); `quiet` disables all output.
  ProgressReporter(std::string unit, bool quiet);
  /// Thread-safe; prints at most ten times a second.
  void update(uint64_t done, uint64_t total, double elapsed_seconds, double budget_seconds);
  void finish(double elapsed_seconds);

 private:
  std::string unit_;
  bool quiet_, tty_;
  std::mutex mutex_;
  double last_print_ = -1.0;
  int last_decile_ = -1;
  uint64_t last_done_ = 0;
  bool printed_ = false;
};

}  // namespace penumbra
