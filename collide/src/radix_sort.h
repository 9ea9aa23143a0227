// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace scree::detail {

/// Sorts 64-bit keys ascending: the same result as std::sort (a total order on integers has one sorted sequence).
///
/// DESIGN (issue 18, docs/solver-internals.md "Broadphase keys by radix"). The uniform grid sorts its cell keys
/// (cell hash << 32 | box) and its pair keys (box a << 32 | box b) every step; std::sort's comparisons on these
/// keys are data-dependent branches, and on pyramid20 the two sorts were 2.6 % of the step (perf, Intel Xeon
/// host). A least-significant-digit radix sort by bytes does no comparisons: one pass counts every byte's
/// histogram at once, a byte that all keys share is skipped (the pair keys of a few hundred boxes differ in only
/// two of their eight bytes, the cell keys in about five), and each remaining byte is one stable scatter into
/// `tmp`. Below kRadixMin keys std::sort's insertion sort is cheaper than clearing the histograms.
inline void radixSortKeys(std::vector<uint64_t>& keys, std::vector<uint64_t>& tmp) {
  constexpr size_t kRadixMin = 64;
  const size_t n = keys.size();
  if (n < kRadixMin) {
    std::sort(keys.begin(), keys.end());
    return;
  }
  std::array<std::array<uint32_t, 256>, 8> count{};
  for (uint64_t k : keys)
    for (int b = 0; b < 8; ++b) ++count[size_t(b)][(k >> (8 * b)) & 0xff];
  tmp.resize(n);
  uint64_t* src = keys.data();
  uint64_t* dst = tmp.data();
  for (int b = 0; b < 8; ++b) {
    std::array<uint32_t, 256>& c = count[size_t(b)];
    // A byte every key shares leaves the order as it is.
    if (c[(src[0] >> (8 * b)) & 0xff] == n) continue;
    uint32_t sum = 0;
    for (uint32_t& x : c) {
      const uint32_t here = x;
      x = sum;
      sum += here;
    }
    for (size_t i = 0; i < n; ++i) {
      const uint64_t k = src[i];
      dst[c[(k >> (8 * b)) & 0xff]++] = k;
    }
    std::swap(src, dst);
  }
  if (src != keys.data()) std::copy(src, src + n, keys.data());
}

}  // namespace scree::detail
