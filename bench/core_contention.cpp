#include "core_contention.h"
#include "timing.h"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <thread>
#include <vector>

namespace penumbra::bench {

namespace {

// One multiply-add behind a call; the empty asm keeps the compiler from seeing through it.
[[gnu::noinline]] uint32_t probe_step(uint32_t x) {
  asm volatile("" : "+r"(x));
  return x * 2654435761u + 1u;
}

}  // namespace

CoreContention probe_core(long steps) {
  // The two loops alternate in eight parts of each, and the figures are the parts' medians: the
  // host may also take the processor away for a few milliseconds, which lands in one part of one
  // loop, whereas a sibling thread's contention lasts through all of them.
  constexpr int kParts = 8;
  const long part = std::max(1L, steps / kParts);
  std::vector<double> call(kParts), chain(kParts), quotient(kParts);
  uint32_t sum = 0;
  uint64_t h = 1;
  for (int k = 0; k < kParts; ++k) {
    double t0 = now();
    for (long i = 0; i < part; ++i) sum += probe_step(static_cast<uint32_t>(i));  // independent calls
    double t1 = now();
    for (long i = 0; i < part; ++i) {  // each step waits for the last
      h = h * 6364136223846793005ull + 1442695040888963407ull + sum;
      asm volatile("" : "+r"(h));
    }
    double t2 = now();
    call[k] = (t1 - t0) / static_cast<double>(part) * 1e9;
    chain[k] = (t2 - t1) / static_cast<double>(part) * 1e9;
    quotient[k] = call[k] / chain[k];
  }
  asm volatile("" : : "r"(h));
  CoreContention c;
  c.call_ns = median(call);
  c.chain_ns = median(chain);
  c.index = median(quotient);
  return c;
}

double probe_cores(int threads, long steps) {
  // The thread pool's workers spin for a while after parallel work before they sleep; a probe run
  // then shares its processor with one of them.
  std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (threads <= 1) return probe_core(steps).index;
  // One probe per processor the program may use: new threads start on their parent's processor
  // and two probes sharing one for a while measured each other.
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  sched_getaffinity(0, sizeof allowed, &allowed);
  std::vector<int> cpus;
  for (int c = 0; c < CPU_SETSIZE && static_cast<int>(cpus.size()) < threads; ++c)
    if (CPU_ISSET(c, &allowed)) cpus.push_back(c);
  std::vector<double> index(threads);
  std::vector<std::thread> workers;
  for (int k = 0; k < threads; ++k)
    workers.emplace_back([&, k] {
      if (k < static_cast<int>(cpus.size())) {
        cpu_set_t one;
        CPU_ZERO(&one);
        CPU_SET(cpus[k], &one);
        pthread_setaffinity_np(pthread_self(), sizeof one, &one);
      }
      index[k] = probe_core(steps).index;
    });
  for (std::thread& w : workers) w.join();
  return *std::max_element(index.begin(), index.end());
}

}  // namespace penumbra::bench
