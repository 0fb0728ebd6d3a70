// SIGINT and SIGTERM during a render: the first asks the render to stop after the current pass
// (and write its image and a checkpoint); a second ends the process at once. Installed for the
// duration of one render and the writing of its outputs (RenderResult::signal_handlers); the
// previous handlers come back afterwards.
#pragma once

namespace penumbra {

class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;
  /// The first signal received since the guard was made, or 0.
  static int signal_received();
};

}  // namespace penumbra
