// Discrete sampling in constant time by Walker's alias method (Vose's construction), for choosing
// one of many items by weight: the scene's lights by power. A CDF needs a binary search over all
// items per sample (or a scan, for a few); here a sample reads one bin whatever the count.
//
// Each of the n bins holds a threshold q and an alias: u picks bin i = floor(u n), and the rest of
// u n, compared with q, picks i or its alias. Vose's construction fills the bins so that item i
// is picked with probability weight_i / sum of weights. Unlike a CDF, neighbouring u do not pick
// neighbouring items, which no caller here relies on.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace penumbra {

class AliasTable {
 public:
  AliasTable() = default;
  /// Items with probabilities proportional to `weights` (negative and NaN weights count as zero);
  /// when no weight is positive (or their sum is not finite), every item is equally likely.
  explicit AliasTable(std::span<const float> weights);

  /// An item drawn with probability pmf(i), for u in [0, 1). An item of zero weight is never drawn
  /// unless every weight is zero. The table must not be empty.
  size_t sample(float u) const {
    // Without branches: whether u keeps the bin's item or takes its alias is a coin flip of the bin's
    // odds, which a branch predictor cannot learn (a branch here cost 4x the time for two lights). The
    // index is 32-bit because a float converts to it in one instruction (to size_t in several, with
    // a branch).
    const uint32_t n = uint32_t(bins_.size());
    const float x = u * float(n);
    const uint32_t i = std::min(uint32_t(x), n - 1);  // min: u rounding up to 1 in the product
    const Bin& b = bins_[i];
    const uint32_t keep = 0u - uint32_t(x - float(i) < b.q);  // all ones to keep i
    return b.alias ^ ((i ^ b.alias) & keep);
  }
  /// Probability of drawing item i (0 outside the table).
  float pmf(size_t i) const { return i < pmf_.size() ? pmf_[i] : 0.f; }

 private:
  struct Bin {
    float q = 1.f;       // the part of the bin's width that keeps item i; the rest goes to `alias`
    uint32_t alias = 0;
  };
  std::vector<Bin> bins_;
  std::vector<float> pmf_;
};

}  // namespace penumbra
