#include "light_cache.h"

#include <penumbra/rng.h>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <memory>

namespace penumbra::bdpt {

void StreamSampler::start_pixel_sample(Point2i pixel, uint32_t index, uint32_t dimension) {
  rng_.set_sequence(hash_ints(static_cast<uint32_t>(pixel.x), static_cast<uint32_t>(pixel.y), index), seed_);
  rng_.advance(dimension);  // one output per dimension, so seeking a dimension is a jump
}

void LightCache::trace(const Context& ctx, const Sampler& proto, Point2i resolution, uint32_t index, size_t M,
                       uint64_t seed, const std::function<bool()>& stop) {
  size_t pixels = static_cast<size_t>(resolution.x) * resolution.y;
  vertices_.resize(M * stride_);
  lengths_.assign(M, 0);
  tbb::enumerable_thread_specific<std::unique_ptr<Sampler>> samplers([&] { return proto.clone(); });
  tbb::enumerable_thread_specific<StreamSampler> streams(hash_ints(seed, 0x4c43u /* "LC" */));
  tbb::parallel_for(tbb::blocked_range<size_t>(0, M, 256), [&](const tbb::blocked_range<size_t>& r) {
    if (stop && stop()) return;
    for (size_t j = r.begin(); j < r.end(); ++j) {
      Point2i pixel;
      Sampler* sampler;
      if (j < pixels) {
        pixel = Point2i(static_cast<int>(j % resolution.x), static_cast<int>(j / resolution.x));
        sampler = samplers.local().get();
      } else {
        pixel = Point2i(static_cast<int>(j & 0xffffffffu), static_cast<int>(j >> 32));
        sampler = &streams.local();
      }
      PathSampler ps(*sampler, pixel, index);
      lengths_[j] = light_subpath(ctx, ps, &vertices_[j * stride_]);
    }
  });

  refs_.clear();
  positions_.clear();
  for (size_t j = 0; j < M; ++j)
    for (int v = 1; v < lengths_[j]; ++v) {
      const Vertex& x = vertices_[j * stride_ + v];
      if (x.kind != VertexKind::Surface || !x.connectible()) continue;
      refs_.push_back(Ref{static_cast<uint32_t>(j), static_cast<uint32_t>(v)});
      positions_.push_back(x.p);
    }
}

size_t LightCache::memory_bytes() const {
  return vertices_.capacity() * sizeof(Vertex) + lengths_.capacity() * sizeof(int) +
         refs_.capacity() * sizeof(Ref) + positions_.capacity() * sizeof(Vec3);
}

}  // namespace penumbra::bdpt
