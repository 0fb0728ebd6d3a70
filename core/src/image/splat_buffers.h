// Splats from any thread, summed so that the result does not depend on which thread added what or
// in which order: each thread adds into its own buffer (no atomics, no locks, no serial stage), in
// 128-bit fixed point, and integer sums are exact and associative. The buffers are allocated per
// 16x16 block on a thread's first splat into it (48 bytes per pixel and thread where it splats).
// Splats land at random pixels, so each one used to wait for a cache miss (6 % of bdpt's time): a
// splat is now prefetched when it arrives and added a few splats later, from a short per-thread
// queue that fixed_totals() empties before it reads the sums.
#pragma once

#include <penumbra/color.h>
#include <penumbra/integrator.h>
#include <penumbra/math.h>

#include <tbb/enumerable_thread_specific.h>

#include <atomic>
#include <memory>
#include <vector>

namespace penumbra {

class SplatBuffers {
 public:
  explicit SplatBuffers(Point2i resolution);
  /// Bytes when each of `threads` threads splats into every block (what bidirectional integrators
  /// reach): the blocks, each thread's block table, and the sums made for the image.
  static uint64_t worst_case_bytes(Point2i resolution, int threads);
  /// Adds `v` at pixel (x, y), which must be inside the film. Returns false (and adds nothing) for
  /// a value too large for the fixed-point range (above 2^80 in magnitude) or not finite.
  bool add(int x, int y, const Rgb& v);
  /// The sum of every thread's splats, 3 values per pixel, row-major.
  std::vector<double> totals() const;
  bool any() const { return any_.load(std::memory_order_relaxed); }
  /// Checkpoints: the exact integer sums (every thread's), and a restored base they add to.
  void save(StateWriter& out) const;
  void load(StateReader& in);
  /// Resolution of one unit: 2^-40 (values below ~1e-12 per splat round to zero).
  static constexpr double kScale = 0x1p40;

 private:
  static constexpr int kBlock = 16;
  using Fixed = __int128;
  struct Block {
    Fixed v[kBlock * kBlock * 3] = {};
  };
  static constexpr int kPending = 4;
  struct Pending {
    Fixed* p;
    Fixed q[3];
  };
  // Blocks are carved from 2 MiB chunks mapped for the purpose and marked for huge pages: splats
  // land on random blocks, and with 4 KiB pages (three per block) each add waited on its first
  // prefetch, as TLB misses make it do (docs/benchmarks.md, "Results built in place").
  static constexpr size_t kChunkBytes = size_t{2} << 20;
  static constexpr size_t kBlocksPerChunk = kChunkBytes / sizeof(Block);
  struct Unmap {
    void operator()(void* p) const;
  };
  struct ThreadBuffer {
    std::vector<Block*> blocks;  // per 16x16 block of the film, null until the first splat there
    std::vector<std::unique_ptr<void, Unmap>> chunks;
    size_t chunk_used = kBlocksPerChunk;  // blocks taken from the last chunk
    Pending pending[kPending];
    int pending_count = 0, pending_next = 0;
    Block* new_block();
  };
  static void apply(const Pending& e) {
    for (int c = 0; c < 3; ++c) e.p[c] += e.q[c];
  }
  static void flush(ThreadBuffer& tb);
  ThreadBuffer& local();
  Point2i resolution_;
  int blocks_x_, blocks_y_;
  uint64_t id_;  // unique per instance, so a thread's cached buffer is never another film's
  mutable tbb::enumerable_thread_specific<ThreadBuffer> threads_;
  std::atomic<bool> any_{false};
  std::vector<Fixed> base_;  // sums restored from a checkpoint (empty unless resumed)
  std::vector<Fixed> fixed_totals() const;
};

}  // namespace penumbra
