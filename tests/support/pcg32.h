// A tiny PCG32 (O'Neill 2014, XSH-RR output on a 64-bit LCG) so that statistical tests draw the same
// numbers on every machine and standard library, which std::uniform_real_distribution does not promise.
#pragma once

#include <cstdint>

namespace penumbra::test {

class Pcg32 {
 public:
  explicit Pcg32(uint64_t seed, uint64_t stream = 0x5851f42d4c957f2dull) {
    increment_ = (stream << 1u) | 1u;  // the LCG increment must be odd
    next_u32();
    state_ += seed;
    next_u32();
  }

  uint32_t next_u32() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ull + increment_;
    auto mixed = uint32_t(((old >> 18u) ^ old) >> 27u);
    auto rotation = uint32_t(old >> 59u);
    return (mixed >> rotation) | (mixed << ((32u - rotation) & 31u));
  }

  /// Uniform in [0, 1): the top 24 bits fill a float mantissa exactly, so 1 is never returned.
  float next_float() { return float(next_u32() >> 8) * 0x1p-24f; }

 private:
  uint64_t state_ = 0;
  uint64_t increment_ = 0;
};

}  // namespace penumbra::test
