#include "util/alias_table.h"

#include <cmath>
#include <stdexcept>

namespace penumbra {

AliasTable::AliasTable(std::span<const float> weights) {
  const size_t n = weights.size();
  if (n == 0) return;
  if (n > UINT32_MAX) throw std::length_error("AliasTable: more than 2^32 items");
  std::vector<double> w(n);
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    w[i] = weights[i] > 0.f ? double(weights[i]) : 0.0;  // false for NaN as well
    sum += w[i];
  }
  if (!(sum > 0.0) || !std::isfinite(sum)) {
    w.assign(n, 1.0);
    sum = double(n);
  }
  pmf_.resize(n);
  bins_.resize(n);
  // Each item's probability in units of one bin (mean 1), in place of its weight. Items below 1
  // ("small") are topped up by one above ("large"), which then gives away what it filled and is
  // sorted again.
  std::vector<double>& scaled = w;
  std::vector<uint32_t> small, large;
  for (size_t i = 0; i < n; ++i) {
    pmf_[i] = float(w[i] / sum);
    scaled[i] = w[i] / sum * double(n);
    (scaled[i] < 1.0 ? small : large).push_back(uint32_t(i));
  }
  while (!small.empty() && !large.empty()) {
    uint32_t s = small.back(), l = large.back();
    small.pop_back();
    large.pop_back();
    bins_[s].q = float(scaled[s]);
    bins_[s].alias = l;
    scaled[l] -= 1.0 - scaled[s];
    (scaled[l] < 1.0 ? small : large).push_back(l);
  }
  // What is left holds (up to rounding) exactly one bin's worth each: it keeps its whole bin. An item
  // of zero weight cannot be left over: its deficit of a whole bin is far above any rounding.
  for (uint32_t i : small) bins_[i] = Bin{1.f, i};
  for (uint32_t i : large) bins_[i] = Bin{1.f, i};
}

}  // namespace penumbra
