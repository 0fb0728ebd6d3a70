// The light-vertex cache of one iteration (Georgiev et al. 2012's "light vertex cache", the store
// that hierarchical Russian roulette and probabilistic connections draw from): M light subpaths,
// each up to maxdepth + 1 vertices, plus the list of their vertices that a connection can end at.
//
// Path j < pixel count is exactly the light subpath that pixel j's sample of this iteration would
// trace (same sampler, same dimensions), so the pixel sample reuses it instead of tracing its own:
// the cache costs no extra light paths when M equals the pixel count (the default). Paths beyond the
// pixel count use an independent PCG stream per (seed, iteration, path). Paths are traced in
// parallel into fixed slots, so the cache is the same whatever the thread count.
#pragma once

#include "subpath.h"

#include <penumbra/rng.h>

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace penumbra::bdpt {

class LightCache {
 public:
  explicit LightCache(int max_depth) : stride_(max_depth + 1) {}

  /// Traces the M paths of the iteration whose pixel samples have index `index`. `proto` is the
  /// render's sampler (cloned per thread); `resolution` gives the pixel of path j < pixel count.
  /// When `stop` says so (the time budget is spent) tracing ends early: the cache is then incomplete
  /// and must not be rendered with.
  void trace(const Context& ctx, const Sampler& proto, Point2i resolution, uint32_t index, size_t M, uint64_t seed,
             const std::function<bool()>& stop = {});

  size_t path_count() const { return lengths_.size(); }
  const Vertex* path(size_t j) const { return &vertices_[j * stride_]; }
  int path_length(size_t j) const { return lengths_[j]; }

  /// Vertices a connection can end at: surface vertices (index >= 1 on their path) with a
  /// non-specular lobe. `ref(i)` locates vertex i of that list, `positions()` lists their positions.
  struct Ref {
    uint32_t path;
    uint32_t vertex;  // index on the path (s = vertex + 1 light vertices when connected)
  };
  size_t vertex_count() const { return refs_.size(); }
  Ref ref(size_t i) const { return refs_[i]; }
  const Vertex& vertex(size_t i) const { return vertices_[refs_[i].path * stride_ + refs_[i].vertex]; }
  std::span<const Vec3> positions() const { return positions_; }
  size_t memory_bytes() const;
  /// Bytes trace() will hold for M paths: every slot of every path, plus, in the worst case where
  /// every vertex can be connected to, its reference and position.
  uint64_t estimated_bytes(size_t M) const {
    return static_cast<uint64_t>(M) * (stride_ * (sizeof(Vertex) + sizeof(Ref) + sizeof(Vec3)) + sizeof(int));
  }
  size_t stride() const { return stride_; }

 private:
  size_t stride_;
  std::vector<Vertex> vertices_;  // path j occupies [j * stride_, (j + 1) * stride_)
  std::vector<int> lengths_;
  std::vector<Ref> refs_;
  std::vector<Vec3> positions_;
};

/// A sampler that is one PCG32 stream per (pixel, index, seed), for paths that have no pixel.
class StreamSampler final : public Sampler {
 public:
  explicit StreamSampler(uint64_t seed) : seed_(seed) {}
  int samples_per_pixel() const override { return 1; }
  void start_pixel_sample(Point2i pixel, uint32_t index, uint32_t dimension) override;
  float get_1d() override { return rng_.next_float(); }
  Vec2 get_2d() override {
    float x = rng_.next_float();
    return Vec2(x, rng_.next_float());
  }
  Vec2 get_pixel_2d() override { return get_2d(); }
  std::unique_ptr<Sampler> clone() const override { return std::make_unique<StreamSampler>(seed_); }

 private:
  uint64_t seed_;
  Pcg32 rng_;
};

}  // namespace penumbra::bdpt
