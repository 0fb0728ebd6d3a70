#include "render/interrupt.h"

#include <atomic>
#include <csignal>
#include <cstring>

#include <unistd.h>

namespace penumbra {

namespace {

std::atomic<int> g_signal{0};
struct sigaction g_old_int, g_old_term;

void write_stderr(const char* text) {
  ssize_t ignored = ::write(STDERR_FILENO, text, std::strlen(text));
  (void)ignored;
}

// Async-signal-safe: an atomic store and write(2), or _exit(2).
void on_signal(int sig) {
  int expected = 0;
  if (!g_signal.compare_exchange_strong(expected, sig)) {
    write_stderr("\npenumbra: second signal: exiting now, without writing\n");
    _exit(128 + sig);
  }
  write_stderr(sig == SIGTERM ? "\npenumbra: SIGTERM: finishing the current pass, then writing the image and a checkpoint "
                                "(a second signal exits at once)\n"
                              : "\npenumbra: interrupted: finishing the current pass, then writing the image and a "
                                "checkpoint (press Ctrl-C again to exit at once)\n");
}

}  // namespace

InterruptGuard::InterruptGuard() {
  g_signal.store(0);
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, &g_old_int);
  sigaction(SIGTERM, &sa, &g_old_term);
}

InterruptGuard::~InterruptGuard() {
  sigaction(SIGINT, &g_old_int, nullptr);
  sigaction(SIGTERM, &g_old_term, nullptr);
}

int InterruptGuard::signal_received() { return g_signal.load(); }

}  // namespace penumbra
