// Memory that is announced: before a large allocation (a film, a light-vertex cache, per-pixel
// statistics) the code estimates its bytes and asks require_memory(), so a render that cannot fit
// fails at once with the estimate instead of std::bad_alloc, or the kernel's out-of-memory killer,
// hours later. For plugin authors: call it in begin_render() for anything that grows with the
// resolution or the sample count.
#pragma once

#include <cstdint>
#include <string>

namespace penumbra {

/// Bytes this process can still allocate: the kernel's MemAvailable (/proc/meminfo; sysconf's free
/// pages where there is none), lowered by the limit of the process's cgroup (a batch job's share:
/// memory.max - memory.current) and by $PENUMBRA_MEMORY_LIMIT (bytes, for shared machines and tests).
uint64_t available_memory();

/// Throws Error "<what> would need an estimated 1.5 TiB (<how>), but only 20.1 GiB of memory are
/// available" when `bytes` exceeds available_memory(); `how` explains the estimate, e.g.
/// "200000x200000 pixels, 32 bytes each".
void require_memory(uint64_t bytes, const std::string& what, const std::string& how = "");

/// "1.5 GiB", "512 KiB", "100 bytes".
std::string format_bytes(uint64_t bytes);

}  // namespace penumbra
