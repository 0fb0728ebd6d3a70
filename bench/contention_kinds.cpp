// Which kinds of code slow down when another hardware thread shares this processor core.
//
// bench/core_contention.h detects the contention; this program says what it costs each kind of
// work, so that a change to the renderer can be judged by the kind of code it removes. Seven loops
// alternate in parts of 0.2-1 ms each, and every second the program prints each loop's median time
// per step over that second's parts:
//   call   independent calls of an out-of-line function (call, return, a multiply-add);
//   alu    16 independent one-cycle integer operations in 8 chains: as many per cycle as the core's
//          arithmetic units take (the kind of code that issues 3-4 instructions per cycle);
//   jump   taken jumps, each to the next instruction, and no calls;
//   code2, code12, code48
//          one operation of a straight-line function of 2, 12 or 48 KB (4-byte independent one-cycle
//          operations): the first fits any front-end cache; the second fits a decoded-operation
//          cache of 4096 operations held alone and not one shared with another thread; the third
//          fits neither that nor the 32 KB instruction cache, so the decoders set its pace;
//   chain  one step of a chain of dependent 64-bit multiply-adds: latency only, so the clock sets its
//          pace and nothing else moves it.
// At the end it splits the seconds into quiet and contended ones by the call loop's time over the
// chain's (the index of bench/core_contention.h), and prints each loop's median in both and their
// quotient. x86-64 only (GCC inline assembly).
//
// Usage: penumbra-bench-contention [--seconds N]   (default 120; pin it with taskset -c CPU)
#include "number_options.h"
#include "timing.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <vector>

namespace {

using penumbra::bench::median;
using penumbra::bench::now;

[[gnu::noinline]] uint32_t call_step(uint32_t x) {
  asm volatile("" : "+r"(x));
  return x * 2654435761u + 1u;
}

[[gnu::noinline]] void alu_steps(long n) {
  uint64_t a = 1, b = 2, c = 3, d = 4, e = 5, f = 6, g = 7, h = 8;
  for (long i = 0; i < n; ++i)
    asm volatile(
        "add $1, %0\n xor $3, %1\n add $5, %2\n xor $7, %3\n add $9, %4\n xor $11, %5\n add $13, %6\n xor $15, %7\n"
        "xor $2, %0\n add $4, %1\n xor $6, %2\n add $8, %3\n xor $10, %4\n add $12, %5\n xor $14, %6\n add $16, %7\n"
        : "+r"(a), "+r"(b), "+r"(c), "+r"(d), "+r"(e), "+r"(f), "+r"(g), "+r"(h));
}

constexpr int kJumps = 64;
[[gnu::noinline]] void jumps() {
  uint64_t a = 0;
  asm volatile(".rept 64\n jmp 1f\n nop\n 1: add $1, %0\n .endr\n" : "+r"(a));
}

// Straight-line code of 4 x `repeats` 4-byte operations (add or xor of an 8-bit immediate to a
// 64-bit register), in four independent chains.
#define PENUMBRA_STRAIGHT_CODE(name, repeats)                                                        \
  [[gnu::noinline]] void name() {                                                                    \
    uint64_t a = 1, b = 2, c = 3, d = 4;                                                             \
    asm volatile(".rept " #repeats "\n add $1, %0\n xor $3, %1\n add $5, %2\n xor $7, %3\n .endr\n" \
                 : "+r"(a), "+r"(b), "+r"(c), "+r"(d));                                              \
  }
PENUMBRA_STRAIGHT_CODE(code_2kb, 128)
PENUMBRA_STRAIGHT_CODE(code_12kb, 768)
PENUMBRA_STRAIGHT_CODE(code_48kb, 3072)

uint64_t chain_steps(long n, uint64_t x) {
  for (long i = 0; i < n; ++i) {
    x = x * 6364136223846793005ull + 1442695040888963407ull;
    asm volatile("" : "+r"(x));
  }
  return x;
}

constexpr int kLoops = 7;
const char* const kNames[kLoops] = {"call", "alu", "jump", "code2", "code12", "code48", "chain"};

// Nanoseconds per operation of `fn`, which does `ops` operations a call, over about `total` of them.
template <class Fn>
double ns_per_op(Fn fn, long ops, long total) {
  const long calls = total / ops;
  double t0 = now();
  for (long i = 0; i < calls; ++i) fn();
  return (now() - t0) / (static_cast<double>(calls) * static_cast<double>(ops)) * 1e9;
}

// One part of each loop; nanoseconds per step.
void run_parts(double* ns) {
  const long n = 300'000;
  double t0 = now();
  uint32_t s = 0;
  for (long i = 0; i < n; ++i) s += call_step(static_cast<uint32_t>(i));
  double t1 = now();
  alu_steps(n);
  double t2 = now();
  ns[0] = (t1 - t0) / n * 1e9;
  ns[1] = (t2 - t1) / n * 1e9;
  ns[2] = ns_per_op(jumps, kJumps, 4 * n);
  // As many operations of each code size (4 per repeat of its `.rept`).
  ns[3] = ns_per_op(code_2kb, 4 * 128, 32 * n);
  ns[4] = ns_per_op(code_12kb, 4 * 768, 32 * n);
  ns[5] = ns_per_op(code_48kb, 4 * 3072, 32 * n);
  double t3 = now();
  uint64_t x = chain_steps(n, s);
  ns[6] = (now() - t3) / n * 1e9;
  asm volatile("" : : "r"(x));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"How much each kind of code slows when the processor core is contended"};
  int seconds = 120;
  app.add_option("--seconds", seconds, "how long to measure (default 120)")
      ->check(penumbra::cli::positive_whole_number());
  if (std::optional<int> status = penumbra::cli::parse_tool_options(app, argc, argv, "penumbra-bench-contention:"))
    return *status;

  std::vector<double> per_second[kLoops];  // each second's median, per loop
  std::printf("# second, then ns per step of: call alu(16 operations) jump code2 code12 code48 (one operation) chain\n");
  for (int sec = 0; sec < seconds; ++sec) {
    std::vector<double> parts[kLoops];
    for (double end = now() + 1.0; now() < end;) {
      double ns[kLoops];
      run_parts(ns);
      for (int k = 0; k < kLoops; ++k) parts[k].push_back(ns[k]);
    }
    std::printf("%d", sec);
    for (int k = 0; k < kLoops; ++k) {
      per_second[k].push_back(median(parts[k]));
      std::printf(" %.4f", per_second[k].back());
    }
    std::printf("\n");
    std::fflush(stdout);
  }

  // Quiet seconds: the call loop within 10 % of its fastest (against the clock); contended: 30 % or
  // more above it. Seconds in between are left out of both.
  std::vector<double> index(seconds);
  for (int s = 0; s < seconds; ++s) index[s] = per_second[0][s] / per_second[kLoops - 1][s];
  double idle = *std::min_element(index.begin(), index.end());
  std::vector<double> quiet[kLoops], contended[kLoops];
  for (int s = 0; s < seconds; ++s)
    for (int k = 0; k < kLoops; ++k) {
      if (index[s] <= 1.1 * idle) quiet[k].push_back(per_second[k][s]);
      else if (index[s] >= 1.3 * idle) contended[k].push_back(per_second[k][s]);
    }
  std::printf("# %zu quiet and %zu contended seconds of %d (call/chain within 10 %% of its smallest, %.3f, "
              "or 30 %% or more above it)\n",
              quiet[0].size(), contended[0].size(), seconds, idle);
  if (quiet[0].empty() || contended[0].empty()) {
    std::printf("# no comparison: the core was %s throughout\n", quiet[0].empty() ? "contended" : "quiet");
    return 0;
  }
  for (int k = 0; k < kLoops; ++k) {
    double q = median(quiet[k]), c = median(contended[k]);
    std::printf("# %-6s quiet %.4f ns, contended %.4f ns: x%.2f\n", kNames[k], q, c, c / q);
  }
  return 0;
}
