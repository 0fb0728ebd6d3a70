#include "render/ray_counter.h"

#include <memory>
#include <mutex>
#include <vector>

namespace penumbra {

thread_local constinit ThreadRayCount* t_ray_count __attribute__((tls_model("initial-exec"))) = nullptr;

namespace {
std::mutex g_mutex;
// Counters outlive their threads so the total stays readable after a thread pool shrinks.
std::vector<std::unique_ptr<ThreadRayCount>>& counters() {
  static std::vector<std::unique_ptr<ThreadRayCount>> v;
  return v;
}
}  // namespace

void count_rays_slow_path() {
  std::lock_guard<std::mutex> lock(g_mutex);
  counters().push_back(std::make_unique<ThreadRayCount>());
  t_ray_count = counters().back().get();
}

uint64_t total_rays() {
  std::lock_guard<std::mutex> lock(g_mutex);
  uint64_t sum = 0;
  for (const auto& c : counters()) sum += c->rays;
  return sum;
}

}  // namespace penumbra
