// Sampler "halton": the Halton sequence (radical inverses in the first 1024 prime bases), with the
// sequence laid over the image so that every pixel receives its own well-spread subsequence.
//
// | parameter             | default       | meaning                                            |
// |-----------------------|---------------|----------------------------------------------------|
// | integer pixelsamples  | 16            | samples per pixel                                  |
// | integer seed          | 0             | seed; different seeds give independent images      |
// | string randomization  | permutedigits | permutedigits, owen or none                        |
//
// Pixel mapping (after pbrt-v4's HaltonSampler, with a fixed scale so that the sampler needs no
// image resolution): dimension 0 scaled by 128 = 2^7 and dimension 1 by 243 = 3^5 tile the plane
// with 128x243-pixel tiles, and the Halton points that fall in pixel (x mod 128, y mod 243) are those
// whose index has fixed low digits in base 2 and base 3. The Chinese remainder theorem gives the
// first such index; sample i of the pixel is index first + i * 31104 (31104 = 128 * 243).
// get_pixel_2d() returns the position inside the pixel, the radical inverse of the remaining digits.
// Dimension d >= 2 is the radical inverse of the same index in the d-th prime (5, 7, 11, ...).
//
// Randomisation, keyed by (pixel, seed, dimension):
//  - permutedigits: each digit position of each dimension gets a random permutation of the digits;
//    permutations are random affine maps d -> (a d + c) mod b (b prime, a != 0), a family in which
//    any two digits map to a uniformly distributed pair, so the estimator's variance (a function of
//    pairs of points only) equals that of uniformly random permutations at a fraction of the cost;
//  - owen: nested (Owen) scrambling: the permutation of a digit is keyed by all digits above it;
//  - none: the plain sequence; the 128x243 tiles then repeat each other.
// Unlike pbrt-v4, which randomises the sequence once for the whole image, every pixel gets its own
// keys: in large bases (thousands), pixels of a tile share leading digits (31104 indices,
// fewer digit values), which correlates the errors of neighbouring pixels in deep dimensions. With
// filter importance sampling nothing is gained from structure across pixels; each pixel's own
// subsequence keeps its stratification under any digit permutation.
// Dimensions past the 1024th prime come from a counter-based hash of (pixel, seed, index, dimension).
#include <penumbra/plugin.h>
#include <penumbra/rng.h>
#include <penumbra/sampler.h>

#include <algorithm>
#include <array>
#include <string>

namespace {

using namespace penumbra;

constexpr uint32_t kPrimeCount = 1024;
constexpr uint64_t kScaleX = 128, kScaleY = 243;  // 2^7, 3^5
constexpr int kDigitsX = 7, kDigitsY = 5;
constexpr uint64_t kStride = kScaleX * kScaleY;
constexpr uint64_t kGolden = 0x9e3779b97f4a7c15ull;

enum class Randomization { None, PermuteDigits, Owen };

const std::array<uint32_t, kPrimeCount>& primes() {
  static const std::array<uint32_t, kPrimeCount> table = [] {
    std::array<uint32_t, kPrimeCount> p{};
    uint32_t count = 0;
    for (uint32_t n = 2; count < kPrimeCount; ++n) {
      bool prime = true;
      for (uint32_t i = 0; i < count && p[i] * p[i] <= n; ++i)
        if (n % p[i] == 0) { prime = false; break; }
      if (prime) p[count++] = n;
    }
    return p;
  }();
  return table;
}

/// a^-1 mod m (extended Euclid); a and m coprime.
constexpr uint64_t inverse_mod(uint64_t a, uint64_t m) {
  int64_t t = 0, new_t = 1, r = static_cast<int64_t>(m), new_r = static_cast<int64_t>(a % m);
  while (new_r != 0) {
    int64_t q = r / new_r;
    int64_t tmp = t - q * new_t;
    t = new_t, new_t = tmp;
    tmp = r - q * new_r;
    r = new_r, new_r = tmp;
  }
  return static_cast<uint64_t>(t < 0 ? t + static_cast<int64_t>(m) : t);
}

/// The Halton index < kStride whose point lies in tile pixel (x, y): the low base-2 digits of the
/// index, reversed, are x and the low base-3 digits, reversed, are y.
uint64_t first_index(uint64_t x, uint64_t y) {
  uint64_t low2 = 0, low3 = 0;
  for (int k = 0; k < kDigitsX; ++k, x /= 2) low2 = low2 * 2 + x % 2;
  for (int k = 0; k < kDigitsY; ++k, y /= 3) low3 = low3 * 3 + y % 3;
  constexpr uint64_t kCrtX = kScaleY * inverse_mod(kScaleY, kScaleX);  // 1 mod 2^7, 0 mod 3^5
  constexpr uint64_t kCrtY = kScaleX * inverse_mod(kScaleX, kScaleY);  // 0 mod 2^7, 1 mod 3^5
  return (low2 * kCrtX + low3 * kCrtY) % kStride;
}

/// A random affine permutation of the digits of prime base b, chosen by `key` (the factor and the
/// offset come from its two halves by multiply-shift range reduction, which avoids divisions).
uint32_t permute_digit(uint32_t digit, uint32_t base, uint64_t key) {
  uint32_t a = 1 + static_cast<uint32_t>(((key & 0xffffffffu) * (base - 1)) >> 32);
  uint32_t c = static_cast<uint32_t>(((key >> 32) * base) >> 32);
  return (a * digit + c) % base;
}

/// Radical inverse of n in base b, randomised with keys derived from `key`.
float radical_inverse(uint64_t n, uint32_t base, Randomization r, uint64_t key) {
  const double inv_base = 1.0 / base;
  double value = 0.0, weight = inv_base;
  // `weight * base` bounds what all remaining digits can add: below 2^-24 they cannot matter to a float
  // in [0, 1) at the resolution the Sobol sampler gives too. Randomised, zero digits past the end of n
  // are permuted as well, so that every value is uniform.
  while ((n != 0 || r != Randomization::None) && weight * base >= 0x1p-24) {
    uint32_t digit;
    if (n <= 0xffffffffu) {  // 32-bit division is much cheaper, and indices this small are the rule
      auto n32 = static_cast<uint32_t>(n);
      digit = n32 % base;
      n = n32 / base;
    } else {
      digit = static_cast<uint32_t>(n % base);
      n /= base;
    }
    if (r != Randomization::None) {
      uint32_t permuted = permute_digit(digit, base, key);
      // The next digit's key: a fresh one per position, and for Owen one per prefix of digits.
      key = mix_bits(key + kGolden * (r == Randomization::Owen ? digit + 1 : 1));
      digit = permuted;
    }
    value += digit * weight;
    weight *= inv_base;
  }
  return std::min(OneMinusEpsilon, static_cast<float>(value));
}

/// a mod m in [0, m), for negative a too.
uint64_t wrap(int a, uint64_t m) {
  int64_t r = static_cast<int64_t>(a) % static_cast<int64_t>(m);
  return static_cast<uint64_t>(r < 0 ? r + static_cast<int64_t>(m) : r);
}

class HaltonSampler final : public DimensionSampler {
 public:
  HaltonSampler(int spp, int seed, Randomization r) : spp_(spp), seed_(seed), randomization_(r) {}

  int samples_per_pixel() const override { return spp_; }

  void start(Point2i pixel, uint32_t index) override {
    uint64_t x = wrap(pixel.x, kScaleX), y = wrap(pixel.y, kScaleY);
    halton_index_ = first_index(x, y) + static_cast<uint64_t>(index) * kStride;
    pixel_key_ = hash_ints(static_cast<uint32_t>(pixel.x), static_cast<uint32_t>(pixel.y), static_cast<uint32_t>(seed_));
    index_ = index;
  }

  std::unique_ptr<Sampler> clone() const override { return std::make_unique<HaltonSampler>(*this); }

 private:
  float value(uint32_t dim) const override {
    if (dim >= kPrimeCount) {
      uint64_t h = hash_ints(pixel_key_, index_, dim);
      return std::min(OneMinusEpsilon, static_cast<float>(h >> 40) * 0x1p-24f);
    }
    uint64_t key = mix_bits(pixel_key_ + (dim + 1ull) * kGolden);
    // Dimensions 0 and 1: the digits that select the pixel are dropped, leaving the offset in it.
    if (dim == 0) return radical_inverse(halton_index_ >> kDigitsX, 2, randomization_, key);
    if (dim == 1) return radical_inverse(halton_index_ / kScaleY, 3, randomization_, key);
    return radical_inverse(halton_index_, primes()[dim], randomization_, key);
  }

  int spp_, seed_;
  Randomization randomization_;
  uint64_t halton_index_ = 0, pixel_key_ = 0;
  uint32_t index_ = 0;
};

const ParamSpec kParams[] = {
    {"integer", "pixelsamples", "16", "samples per pixel"},
    {"integer", "seed", "0", "seed: different seeds give independent images"},
    {"string", "randomization", "permutedigits", "permutedigits, owen or none"},
};

Object* create(const CreateContext& ctx) {
  int spp = ctx.params.get_int("pixelsamples");
  if (spp <= 0) throw Error(ctx.params.loc_of("pixelsamples"), "pixelsamples must be positive");
  std::string name = ctx.params.get_string("randomization");
  Randomization r;
  if (name == "permutedigits") r = Randomization::PermuteDigits;
  else if (name == "owen") r = Randomization::Owen;
  else if (name == "none") r = Randomization::None;
  else
    throw Error(ctx.params.loc_of("randomization"),
                "randomization '" + name + "' is not supported by sampler 'halton'; available: permutedigits, owen, none");
  return new HaltonSampler(spp, ctx.params.get_int("seed"), r);
}

}  // namespace

PENUMBRA_PLUGIN(Sampler, "halton", "Halton sequence over 128x243-pixel tiles, randomised digit permutations",
                kParams, create)
