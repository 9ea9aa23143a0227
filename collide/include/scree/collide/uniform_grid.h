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
  UniformGrid() = default;
  /// A grid whose findPairs() reuses its candidates (setReuseRatio).
  explicit UniformGrid(Real reuseRatio) { setReuseRatio(reuseRatio); }
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

  /// Reuse between calls (issue 18; 0, the default, turns it off). With a ratio r > 0, findPairs() finds its
  /// candidates among boxes enlarged by r times their largest extent on every side, keeps them, and on later
  /// calls, while every box is non-empty and lies inside its enlarged box, returns the kept candidates whose
  /// boxes overlap now, without binning or sorting. The pairs and their order are findPairs()'s either way:
  /// two boxes that overlap lie inside enlarged boxes that overlap. A box that leaves its enlarged box, a change
  /// in the number of boxes or an empty box makes the next call bin afresh. Space turns it on (space.cpp).
  /// Throws std::invalid_argument unless r is finite and >= 0.
  void setReuseRatio(Real r);
  Real getReuseRatio() const { return reuseRatio_; }
  /// Whether the last findPairs() returned kept candidates (no binning).
  bool lastCallReused() const { return lastReused_; }

  /// Work done by the last findPairs() (read-only, for tests and profiling). Cell entries: (cell, box) entries
  /// binned, after dropping a box's repeats within one hash bucket. Candidate tests: box pairs tested by AABB,
  /// i.e. pairs sharing a bucket plus every oversize box against the binned and the other oversize boxes.
  size_t getNumCellEntries() const { return numCellEntries_; }
  size_t getNumCandidateTests() const { return numCandidateTests_; }

 private:
  /// findPairs() without reuse.
  void findPairsExact(const std::vector<Aabb>& boxes, std::vector<std::pair<uint32_t, uint32_t>>& outPairs);
  Real reuseRatio_ = 0;
  bool lastReused_ = false;
  bool haveKept_ = false;
  bool usedKept_ = false;  ///< the kept candidates were reused at least once since they were found
  int backoff_ = 0;        ///< calls to bin plainly after kept candidates went unused (findPairs)
  int skip_ = 0;           ///< of which still to go
  std::vector<Aabb> enlarged_;                              ///< the boxes the kept candidates were found for
  std::vector<std::pair<uint32_t, uint32_t>> candidates_;  ///< their overlapping pairs, sorted

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
