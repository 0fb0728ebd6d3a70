#include <penumbra/error.h>
#include <penumbra/memory.h>

#include <fmt/core.h>

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace penumbra {

namespace {

// "MemAvailable:   12345 kB" from /proc/meminfo, in bytes; 0 when absent.
uint64_t mem_available() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  uint64_t kb = 0;
  std::string unit;
  while (in >> key >> kb >> unit)
    if (key == "MemAvailable:") return kb * 1024;
  long pages = sysconf(_SC_AVPHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : 0;
}

// The process's cgroup v2 folder ("0::/path" in /proc/self/cgroup), or "".
std::string cgroup_folder() {
  std::ifstream in("/proc/self/cgroup");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("0::", 0) == 0) return "/sys/fs/cgroup" + line.substr(3);
  return "";
}

bool read_number(const std::string& path, uint64_t* out) {
  std::ifstream in(path);
  std::string text;
  if (!(in >> text) || text == "max") return false;
  char* end = nullptr;
  unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (end == text.c_str() || *end != '\0') return false;
  *out = v;
  return true;
}

}  // namespace

uint64_t available_memory() {
  uint64_t available = mem_available();
  if (available == 0) available = UINT64_MAX;  // unknown: do not refuse
  std::string cg = cgroup_folder();
  uint64_t max = 0, current = 0;
  if (!cg.empty() && read_number(cg + "/memory.max", &max) && read_number(cg + "/memory.current", &current))
    available = std::min(available, max > current ? max - current : 0);
  if (const char* limit = std::getenv("PENUMBRA_MEMORY_LIMIT"); limit && *limit) {
    char* end = nullptr;
    unsigned long long v = std::strtoull(limit, &end, 10);
    if (end != limit && *end == '\0') available = std::min<uint64_t>(available, v);
  }
  return available;
}

std::string format_bytes(uint64_t bytes) {
  static const char* const units[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  double v = static_cast<double>(bytes);
  int u = 0;
  while (v >= 1024.0 && u < 6) v /= 1024.0, ++u;
  return u == 0 ? fmt::format("{} bytes", bytes) : fmt::format("{:.1f} {}", v, units[u]);
}

void require_memory(uint64_t bytes, const std::string& what, const std::string& how) {
  uint64_t available = available_memory();
  if (bytes <= available) return;
  throw Error(fmt::format("{} would need an estimated {}{}, but only {} of memory are available", what,
                          format_bytes(bytes), how.empty() ? "" : fmt::format(" ({})", how),
                          format_bytes(available)));
}

}  // namespace penumbra
