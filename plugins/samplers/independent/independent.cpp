// Sampler "independent" (alias "random"): uniform pseudo-random numbers from PCG32.
//
// | parameter            | default | meaning                                  |
// |----------------------|---------|------------------------------------------|
// | integer pixelsamples | 16      | samples per pixel                        |
// | integer seed         | 0       | seed; different seeds give independent images |
//
// Each (pixel, seed) pair selects its own PCG32 stream, and sample i of a pixel starts 2^16 values
// into the stream per index (jump-ahead), so a sample is a pure function of (pixel, index, seed).
#include <penumbra/plugin.h>
#include <penumbra/rng.h>
#include <penumbra/sampler.h>

namespace {

using namespace penumbra;

class IndependentSampler final : public Sampler {
 public:
  IndependentSampler(int spp, int seed) : spp_(spp), seed_(seed) {}
  int samples_per_pixel() const override { return spp_; }
  // Integrators that seek to a dimension several times per sample (bdpt's subpaths) reuse the
  // pixel's stream and the sample's start: only the jump by `dimension` is repeated, and a seek
  // gives exactly the values of a fresh start.
  void start_pixel_sample(Point2i pixel, uint32_t index, uint32_t dimension) override {
    if (!have_pixel_ || pixel != pixel_) {
      pixel_start_.set_sequence(hash_ints(static_cast<uint32_t>(pixel.x), static_cast<uint32_t>(pixel.y),
                                          static_cast<uint64_t>(static_cast<uint32_t>(seed_))),
                                0);
      pixel_ = pixel;
      have_pixel_ = true;
      have_index_ = false;
    }
    if (!have_index_ || index != index_) {
      // The sample's start is built in a local and stored whole: advanced in place and copied on,
      // its state was stored in 8 bytes and reloaded in 16, which stalls store forwarding (half of
      // this function's time). The render loop takes a pixel's indices in order, so the next index
      // is one jump on from the last: exactly the same state, since jumps compose.
      Pcg32 start = sample_start_;
      if (have_index_ && static_cast<uint64_t>(index) == static_cast<uint64_t>(index_) + 1u) {
        start.advance(kIndexStride);
      } else {
        start = pixel_start_;
        start.advance(static_cast<uint64_t>(index) * kIndexStride);
      }
      sample_start_ = start;
      index_ = index;
      have_index_ = true;
      rng_ = start;
    } else {
      rng_ = sample_start_;
    }
    if (dimension) rng_.advance(dimension);
  }
  float get_1d() override { return rng_.next_float(); }
  Vec2 get_2d() override {
    float x = rng_.next_float();
    return Vec2(x, rng_.next_float());
  }
  Vec2 get_pixel_2d() override { return get_2d(); }
  std::unique_ptr<Sampler> clone() const override { return std::make_unique<IndependentSampler>(*this); }

 private:
  static constexpr uint64_t kIndexStride = 65536;  // values of the stream reserved for each sample
  int spp_, seed_;
  Pcg32 rng_, pixel_start_, sample_start_;
  Point2i pixel_{0, 0};
  uint32_t index_ = 0;
  bool have_pixel_ = false, have_index_ = false;
};

const ParamSpec kParams[] = {
    {"integer", "pixelsamples", "16", "samples per pixel"},
    {"integer", "seed", "0", "seed: different seeds give independent images"},
};

Object* create(const CreateContext& ctx) {
  int spp = ctx.params.get_int("pixelsamples");
  if (spp <= 0) throw Error(ctx.params.loc_of("pixelsamples"), "pixelsamples must be positive");
  return new IndependentSampler(spp, ctx.params.get_int("seed"));
}

const char* const kAliases[] = {"random", nullptr};

}  // namespace

PENUMBRA_PLUGIN_WITH_ALIASES(Sampler, "independent", "uniform random samples (PCG32)", kParams, create, kAliases)
