// Counts rays per thread without contention; the total is read once a render has finished.
#pragma once

#include <cstdint>

namespace penumbra {

void count_rays_slow_path();
// A cache line each: two threads' counters in one line (8-byte heap blocks, allocated one after the
// other) made every ray a write to a line the other core also writes, which cost the path tracer
// 30 % of its speed on 2 threads whenever the heap's layout put them together (docs/benchmarks.md).
struct alignas(64) ThreadRayCount {
  uint64_t rays = 0;
};
// Initial-exec TLS: libpenumbra-core is loaded with the program (never dlopen'ed), so the counter
// is one fs-relative load instead of a __tls_get_addr call per ray. constinit: without it, every
// caller in another file first loads and tests the address of a possible dynamic initialiser
// (GCC's TLS wrapper), twice per ray.
extern thread_local constinit ThreadRayCount* t_ray_count __attribute__((tls_model("initial-exec")));

inline void count_ray() {
  if (!t_ray_count) count_rays_slow_path();
  ++t_ray_count->rays;
}

/// Sum over all threads that ever traced a ray (read while no render is running).
uint64_t total_rays();

}  // namespace penumbra
