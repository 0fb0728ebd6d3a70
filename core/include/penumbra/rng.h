// PCG32 (O'Neill 2014) with jump-ahead, and integer hashing to derive independent streams from
// (pixel, sample index, seed) tuples.
#pragma once

#include <penumbra/math.h>

#include <array>
#include <bit>
#include <cstdint>

namespace penumbra {

/// 64-bit finaliser of MurmurHash3: decorrelates sequential inputs.
inline uint64_t mix_bits(uint64_t v) {
  v ^= v >> 31;
  v *= 0x7fb5d329728ea185ull;
  v ^= v >> 27;
  v *= 0x81dadef4bc2dd44dull;
  v ^= v >> 33;
  return v;
}

/// Hash of up to four integers.
inline uint64_t hash_ints(uint64_t a, uint64_t b = 0, uint64_t c = 0, uint64_t d = 0) {
  uint64_t h = mix_bits(a + 0x9e3779b97f4a7c15ull);
  h = mix_bits(h ^ (b + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2)));
  h = mix_bits(h ^ (c + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2)));
  return mix_bits(h ^ (d + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2)));
}

class Pcg32 {
 public:
  Pcg32() { set_sequence(0, 0x853c49e6748fea9bull); }
  Pcg32(uint64_t sequence, uint64_t seed) { set_sequence(sequence, seed); }

  /// Selects stream `sequence` (any value) starting from `seed`.
  void set_sequence(uint64_t sequence, uint64_t seed) {
    state_ = 0u;
    inc_ = (sequence << 1u) | 1u;
    next_u32();
    state_ += seed;
    next_u32();
  }

  uint32_t next_u32() {
    uint64_t old = state_;
    state_ = old * kMult + inc_;
    uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
  }

  /// Uniform in [0, 1).
  float next_float() { return std::min(OneMinusEpsilon, next_u32() * 0x1p-32f); }

  /// Skips `delta` outputs: one step from a table for the low 8 bits of `delta`, then one per higher
  /// set bit (a sample-index jump, index * 2^16, costs one step per set bit of the index).
  void advance(uint64_t delta) {
    const Jump& low = kJumps[delta & 255u];
    state_ = low.mult * state_ + low.inc_factor * inc_;
    for (uint64_t high = delta >> 8u; high; high &= high - 1u) {
      const Jump& j = kPow2Jumps[8 + std::countr_zero(high)];
      state_ = j.mult * state_ + j.inc_factor * inc_;
    }
  }

 private:
  static constexpr uint64_t kMult = 0x5851f42d4c957f2dull;
  // n steps of state' = kMult state + inc make state_n = mult_n state + inc_factor_n inc, where
  // mult_n = kMult^n and inc_factor_n = 1 + kMult + ... + kMult^(n-1) (mod 2^64) do not depend on
  // the stream: advance() skips up to 255 outputs with two multiplications instead of a loop.
  // Jumps of any lengths commute (they are powers of the same step), so they apply in any order.
  struct Jump {
    uint64_t mult, inc_factor;
  };
  static constexpr std::array<Jump, 256> kJumps = [] {
    std::array<Jump, 256> t{};
    uint64_t mult = 1u, inc_factor = 0u;
    for (Jump& j : t) {
      j = Jump{mult, inc_factor};
      inc_factor = inc_factor * kMult + 1u;
      mult *= kMult;
    }
    return t;
  }();
  // Jumps of 2^k outputs: doubling n gives mult_2n = mult_n^2, inc_factor_2n = inc_factor_n (mult_n + 1).
  static constexpr std::array<Jump, 64> kPow2Jumps = [] {
    std::array<Jump, 64> t{};
    uint64_t mult = kMult, inc_factor = 1u;
    for (Jump& j : t) {
      j = Jump{mult, inc_factor};
      inc_factor *= mult + 1u;
      mult *= mult;
    }
    return t;
  }();
  uint64_t state_, inc_;
};

}  // namespace penumbra
