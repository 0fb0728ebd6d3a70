#include "image/splat_buffers.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <new>
#include <sys/mman.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace penumbra {

namespace {
std::atomic<uint64_t> next_id{1};
}

SplatBuffers::SplatBuffers(Point2i resolution)
    : resolution_(resolution),
      blocks_x_((resolution.x + kBlock - 1) / kBlock),
      blocks_y_((resolution.y + kBlock - 1) / kBlock),
      id_(next_id.fetch_add(1)) {}

uint64_t SplatBuffers::worst_case_bytes(Point2i resolution, int threads) {
  uint64_t blocks = static_cast<uint64_t>((resolution.x + kBlock - 1) / kBlock) * ((resolution.y + kBlock - 1) / kBlock);
  uint64_t chunks = (blocks + kBlocksPerChunk - 1) / kBlocksPerChunk;
  uint64_t pixels = static_cast<uint64_t>(resolution.x) * resolution.y;
  return static_cast<uint64_t>(std::max(threads, 1)) * (chunks * kChunkBytes + blocks * sizeof(Block*)) +
         pixels * 3 * sizeof(double);
}

void SplatBuffers::Unmap::operator()(void* p) const { munmap(p, kChunkBytes); }

SplatBuffers::Block* SplatBuffers::ThreadBuffer::new_block() {
  if (chunk_used == kBlocksPerChunk) {
    // Fresh pages, 2 MiB-aligned: twice the size is mapped and the ends beyond the aligned chunk
    // are returned, so the first touch can fault in a huge page (where the kernel allows them).
    size_t span = 2 * kChunkBytes;
    void* raw = mmap(nullptr, span, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (raw == MAP_FAILED) throw std::bad_alloc();
    uintptr_t start = reinterpret_cast<uintptr_t>(raw);
    uintptr_t aligned = (start + kChunkBytes - 1) & ~(uintptr_t{kChunkBytes} - 1);
    if (aligned > start) munmap(raw, aligned - start);
    if (aligned + kChunkBytes < start + span)
      munmap(reinterpret_cast<void*>(aligned + kChunkBytes), start + span - aligned - kChunkBytes);
    void* chunk = reinterpret_cast<void*>(aligned);
    madvise(chunk, kChunkBytes, MADV_HUGEPAGE);  // a hint: without huge pages all works as before
    chunks.emplace_back(chunk);
    chunk_used = 0;
  }
  void* at = static_cast<char*>(chunks.back().get()) + chunk_used++ * sizeof(Block);
  return new (at) Block{};
}

// The calling thread's buffer: TBB's lookup by thread id once, then a thread-local cache (a splat
// costs a comparison instead of a hash lookup).
SplatBuffers::ThreadBuffer& SplatBuffers::local() {
  // Initial-exec TLS, as the ray counter's (render/ray_counter.h).
  thread_local uint64_t cached_id __attribute__((tls_model("initial-exec"))) = 0;
  thread_local ThreadBuffer* cached __attribute__((tls_model("initial-exec"))) = nullptr;
  if (cached_id != id_) {
    cached = &threads_.local();
    cached_id = id_;
  }
  return *cached;
}

namespace {
// Round to nearest (ties to even, the default rounding mode) for |x| < 2^62: on x86-64 one
// instruction, where std::nearbyint and the conversion to 128 bits are two library calls.
inline int64_t round_to_int64(double x) {
#if defined(__SSE2__)
  return _mm_cvtsd_si64(_mm_set_sd(x));
#else
  return static_cast<int64_t>(std::nearbyint(x));
#endif
}
}  // namespace

bool SplatBuffers::add(int x, int y, const Rgb& v) {
  Fixed q[3];
  for (int c = 0; c < 3; ++c) {
    double s = static_cast<double>(v[c]) * kScale;
    if (!(std::abs(s) < 0x1p120)) return false;
    q[c] = std::abs(s) < 0x1p62 ? static_cast<Fixed>(round_to_int64(s)) : static_cast<Fixed>(std::nearbyint(s));
  }
  ThreadBuffer& tb = local();
  if (tb.blocks.empty()) tb.blocks.resize(static_cast<size_t>(blocks_x_) * blocks_y_);
  Block*& b = tb.blocks[static_cast<size_t>(y / kBlock) * blocks_x_ + x / kBlock];
  if (!b) {
    b = tb.new_block();
    any_.store(true, std::memory_order_relaxed);
  }
  Fixed* p = &b->v[3 * ((y % kBlock) * kBlock + x % kBlock)];
  // The pixel's 48 bytes span at most two cache lines.
  __builtin_prefetch(p, 1);
  __builtin_prefetch(reinterpret_cast<const char*>(p) + sizeof(Fixed) * 3 - 1, 1);
  Pending& slot = tb.pending[tb.pending_next];
  if (tb.pending_count == kPending)
    apply(slot);
  else
    ++tb.pending_count;
  slot.p = p;
  for (int c = 0; c < 3; ++c) slot.q[c] = q[c];
  tb.pending_next = (tb.pending_next + 1) % kPending;
  return true;
}

void SplatBuffers::flush(ThreadBuffer& tb) {
  // The queue holds the last pending_count splats, ending just before pending_next.
  for (int i = 0; i < tb.pending_count; ++i) apply(tb.pending[(tb.pending_next + kPending - 1 - i) % kPending]);
  tb.pending_count = 0;
  tb.pending_next = 0;
}

std::vector<SplatBuffers::Fixed> SplatBuffers::fixed_totals() const {
  // Called between passes, when no thread adds: the queued splats of every thread go in first.
  for (ThreadBuffer& tb : threads_) flush(tb);
  const size_t n = 3 * static_cast<size_t>(resolution_.x) * resolution_.y;
  std::vector<Fixed> out = base_.empty() ? std::vector<Fixed>(n, Fixed(0)) : base_;
  for (int by = 0; by < blocks_y_; ++by)
    for (int bx = 0; bx < blocks_x_; ++bx) {
      size_t block = static_cast<size_t>(by) * blocks_x_ + bx;
      for (const ThreadBuffer& tb : threads_) {
        if (tb.blocks.empty() || !tb.blocks[block]) continue;
        const Fixed* v = tb.blocks[block]->v;
        for (int y = by * kBlock; y < std::min((by + 1) * kBlock, resolution_.y); ++y)
          for (int x = bx * kBlock; x < std::min((bx + 1) * kBlock, resolution_.x); ++x)
            for (int c = 0; c < 3; ++c)
              out[3 * (static_cast<size_t>(y) * resolution_.x + x) + c] += v[3 * ((y % kBlock) * kBlock + x % kBlock) + c];
      }
    }
  return out;
}

std::vector<double> SplatBuffers::totals() const {
  std::vector<Fixed> sums = fixed_totals();
  std::vector<double> out(sums.size());
  for (size_t i = 0; i < sums.size(); ++i) out[i] = static_cast<double>(sums[i]) / kScale;
  return out;
}

void SplatBuffers::save(StateWriter& out) const {
  out.value<uint8_t>(any() ? 1 : 0);
  if (any()) out.vector(fixed_totals());
}

void SplatBuffers::load(StateReader& in) {
  bool had = in.value<uint8_t>() != 0;
  if (!had) return;
  in.vector(base_, 3 * static_cast<uint64_t>(resolution_.x) * resolution_.y);
  any_.store(true, std::memory_order_relaxed);
}

}  // namespace penumbra
