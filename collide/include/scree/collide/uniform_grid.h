// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Uniform-grid broadphase.
//
// Finite AABBs are binned into cubic cells of a hashed grid (cell size chosen from the size distribution:
// by default twice the median of the boxes' largest extents, overridable). Boxes larger than
// `oversizeFactor` cells along any axis (big static boxes), and infinite ones (planes), go to a separate
// list; each of those is tested against every finite box by AABB and against the other oversize ones.
// Candidate pairs are emitted once, as (lower index, higher index), in sorted order so results are
// deterministic. Cost is linear in N for evenly sized objects. Up to kAllPairsMax boxes every pair is tested
// by AABB instead (same pairs, same order; cheaper than hashing and sorting for a handful of boxes).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "scree/core/math.h"

namespace scree::detail {

class UniformGrid {
 public:
  /// 0 (default) = automatic from the box sizes.
  void setCellSize(Real size);
  Real getCellSize() const { return cellSize_; }
  /// Cell size used by the last findPairs() (0: it had at most kAllPairsMax boxes and used no cells).
  Real getUsedCellSize() const { return usedCellSize_; }
  void setOversizeFactor(Real f);

  /// At most this many boxes: all pairs by AABB, no cells (getUsedCellSize() and getNumCellEntries() 0).
  static constexpr uint32_t kAllPairsMax = 32;

  /// All pairs (i, j), i < j, whose boxes overlap, sorted. Boxes with lo > hi (empty) are skipped.
  void findPairs(const std::vector<Aabb>& boxes, std::vector<std::pair<uint32_t, uint32_t>>& outPairs);

  /// Work done by the last findPairs() (read-only, for tests and profiling). Cell entries: (cell, box) entries
  /// binned, after dropping a box's repeats within one hash bucket. Candidate tests: box pairs tested by AABB,
  /// i.e. pairs sharing a bucket plus every oversize box against the binned and the other oversize boxes.
  size_t getNumCellEntries() const { return numCellEntries_; }
  size_t getNumCandidateTests() const { return numCandidateTests_; }

 private:
  Real cellSize_ = 0;
  Real usedCellSize_ = 0;
  Real oversizeFactor_ = 8;
  size_t numCellEntries_ = 0;
  size_t numCandidateTests_ = 0;
  // Scratch kept between calls (no per-step allocation once warm).
  std::vector<uint64_t> cellKeys_;
  std::vector<uint32_t> cellItems_;
  std::vector<uint32_t> oversize_;
  std::vector<uint32_t> finite_;
  std::vector<Real> sizes_;
  std::vector<uint64_t> pairKeys_;
  std::vector<uint64_t> sortTmp_;  ///< radixSortKeys' scatter buffer
};

}  // namespace scree::detail
