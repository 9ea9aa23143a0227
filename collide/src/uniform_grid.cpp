// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Hashed uniform grid (after Teschner et al. 2003, "Optimized spatial hashing for collision detection of
// deformable objects"; the cell hash itself differs, see cellHash).
//
// Algorithm per findPairs():
//  1. Classify: empty boxes are skipped; infinite ones and boxes spanning more than oversizeFactor cells on an
//     axis go to the oversize list; the rest are binned.
//  2. Bin: one 64-bit word per (cell, box) = (32-bit cell hash << 32) | box index, sorted. Equal words (a box
//     whose cells collide in the hash) are deduplicated, so within one hash bucket each box appears once.
//  3. Pairs inside a bucket: two overlapping boxes share the cell that contains the max of their lo corners
//     (it lies inside both boxes); the pair is reported only from the bucket of that "owner" cell. So every
//     overlapping pair is found exactly once without a hash set, even across hash collisions.
//  4. Oversize boxes are tested by AABB against all binned boxes and against each other.
//  5. Pairs are gathered as (i << 32 | j) words and sorted, which gives the (i, j) lexicographic order.
// Cost: O(N) cells for evenly sized boxes plus the sorts; the scratch vectors are members and keep their
// capacity, so a warm grid does not allocate. Serial on purpose: the sort dominates and a parallel version
// would need a deterministic merge; not worth it at the sizes seen so far.
#include "scree/collide/uniform_grid.h"

#include <algorithm>
#include <cmath>

#include "radix_sort.h"
#include "scree/core/errors.h"

namespace scree::detail {

namespace {

constexpr Real kInfiniteCoord = 1e299;  // |coordinate| beyond this counts as unbounded (planes use 1e300)

bool isEmpty(const Aabb& b) {
  // NaN compares false, so a NaN box is treated as empty (never reported).
  return !(b.lo.x() <= b.hi.x() && b.lo.y() <= b.hi.y() && b.lo.z() <= b.hi.z());
}

bool isUnbounded(const Aabb& b) {
  return !(b.lo.array().abs() < kInfiniteCoord).all() || !(b.hi.array().abs() < kInfiniteCoord).all();
}

/// Integer cell coordinate, clamped so the conversion never overflows for huge finite coordinates.
int64_t cellCoord(Real x, Real invCell) {
  const Real c = std::floor(x * invCell);
  const Real lim = 4.0e18;
  return int64_t(std::clamp(c, -lim, lim));
}

uint32_t cellHash(int64_t x, int64_t y, int64_t z) {
  // Teschner et al. XOR three products with small primes; with two's-complement coordinates that gives pairs of
  // cells such as (x, y, z) and (x, -y, -z) the same value (60 % of the cells within 11 of the origin share their
  // bucket with another cell), which doubled the candidate tests (test_unit_broadphase). A sum with odd 64-bit
  // constants has no such small-offset collisions; a final avalanche mixes the bits kept.
  uint64_t h = uint64_t(x) * 0x9E3779B97F4A7C15ull + uint64_t(y) * 0xC2B2AE3D27D4EB4Full +
               uint64_t(z) * 0x165667B19E3779F9ull;
  h ^= h >> 29;
  h *= 0xbf58476d1ce4e5b9ull;
  h ^= h >> 32;
  return uint32_t(h);
}

}  // namespace

void UniformGrid::setCellSize(Real size) {
  detail::requireNonNegative("UniformGrid::setCellSize", "size", size);
  cellSize_ = size;
}

void UniformGrid::setOversizeFactor(Real f) {
  if (!(std::isfinite(f) && f >= 1)) detail::throwInvalid("UniformGrid::setOversizeFactor", "factor", f, "must be finite and >= 1");
  oversizeFactor_ = f;
}

void UniformGrid::setReuseRatio(Real r) {
  if (!(std::isfinite(r) && r >= 0)) detail::throwInvalid("UniformGrid::setReuseRatio", "ratio", r, "must be finite and >= 0");
  reuseRatio_ = r;
  haveKept_ = false;
  backoff_ = skip_ = 0;
}

// DESIGN (issue 18, broadphase reuse; docs/solver-internals.md "Broadphase reuse"): a resting scene's boxes move
// by micrometres per step, yet binning, sorting and the owner-cell tests ran every step (findPairs and its
// radix sorts: about 5 % of pyramid20's step). As Box2D's enlarged AABBs, but all or nothing: the candidates are
// the pairs of enlarged boxes, found by the grid when any box leaves its enlarged box, and each call keeps those
// whose boxes overlap now. Containment is tested with the same <= comparisons as Aabb::overlaps, so a pair that
// overlaps now is among the candidates exactly (lo_e <= lo <= hi' <= hi'_e on every axis), and the candidates
// are sorted like the grid's output: the pairs and their order do not change, only the work.
void UniformGrid::findPairs(const std::vector<Aabb>& boxes, std::vector<std::pair<uint32_t, uint32_t>>& outPairs) {
  lastReused_ = false;
  if (!(reuseRatio_ > 0)) {
    findPairsExact(boxes, outPairs);
    return;
  }
  const size_t n = boxes.size();
  auto inside = [](const Aabb& b, const Aabb& e) {
    return e.lo.x() <= b.lo.x() && e.lo.y() <= b.lo.y() && e.lo.z() <= b.lo.z() && b.hi.x() <= e.hi.x() &&
           b.hi.y() <= e.hi.y() && b.hi.z() <= e.hi.z();
  };
  // Back-off: when the candidates found by the last binning were not reused even once (the boxes move faster than
  // their enlargement allows), the next calls bin the boxes themselves, 1, 2, 4 ... 64 calls before trying
  // again, so that a scene in motion pays little more than the containment test for the option.
  if (skip_ > 0) {
    --skip_;
    haveKept_ = false;
    findPairsExact(boxes, outPairs);
    return;
  }
  bool reuse = haveKept_ && enlarged_.size() == n;
  for (size_t i = 0; reuse && i < n; ++i) reuse = !isEmpty(boxes[i]) && inside(boxes[i], enlarged_[i]);
  if (reuse) {
    backoff_ = 0;
    usedKept_ = true;
  } else if (haveKept_ && !usedKept_) {
    backoff_ = backoff_ == 0 ? 1 : std::min(2 * backoff_, 64);
    skip_ = backoff_ - 1;
    haveKept_ = false;
    findPairsExact(boxes, outPairs);
    return;
  }
  if (!reuse) {
    // Bin afresh: the enlarged boxes' pairs become the candidates (none kept while a box is empty: an empty
    // box enlarged may not be empty).
    haveKept_ = false;
    enlarged_.resize(n);
    bool empty = false;
    for (size_t i = 0; i < n; ++i) {
      Aabb e = boxes[i];
      empty = empty || isEmpty(e);
      e.inflate(reuseRatio_ * e.extent().maxCoeff());
      enlarged_[i] = e;
    }
    if (empty) {
      findPairsExact(boxes, outPairs);
      return;
    }
    findPairsExact(enlarged_, candidates_);
    haveKept_ = true;
    usedKept_ = false;
  } else {
    lastReused_ = true;
    numCellEntries_ = 0;
    numCandidateTests_ = candidates_.size();
  }
  outPairs.clear();
  for (const auto& [i, j] : candidates_)
    if (boxes[i].overlaps(boxes[j])) outPairs.emplace_back(i, j);
}

void UniformGrid::findPairsExact(const std::vector<Aabb>& boxes,
                                 std::vector<std::pair<uint32_t, uint32_t>>& outPairs) {
  outPairs.clear();
  cellKeys_.clear();
  cellItems_.clear();
  oversize_.clear();
  finite_.clear();
  sizes_.clear();
  pairKeys_.clear();
  const uint32_t n = uint32_t(boxes.size());

  // --- few boxes: every pair by AABB ------------------------------------------------------------------------
  // Hashing, sorting and the owner-cell test cost more than n (n - 1) / 2 AABB tests for a handful of boxes
  // (tower10's 11 geometries: the grid was 3 % of its step, docs/solver-internals.md "Fixed cost of small rigid
  // scenes"). The loop meets the pairs in (i, j) order, so the output is the grid's, sorted, without a sort.
  if (n <= kAllPairsMax) {
    size_t tests = 0;
    for (uint32_t i = 0; i < n; ++i) {
      const Aabb& a = boxes[i];
      if (isEmpty(a)) continue;
      for (uint32_t j = i + 1; j < n; ++j) {
        const Aabb& b = boxes[j];
        if (isEmpty(b)) continue;
        ++tests;
        if (a.overlaps(b)) outPairs.emplace_back(i, j);
      }
    }
    usedCellSize_ = 0;
    numCellEntries_ = 0;
    numCandidateTests_ = tests;
    return;
  }
  // --- 1. classify -------------------------------------------------------------------------------------
  for (uint32_t i = 0; i < n; ++i) {
    const Aabb& b = boxes[i];
    if (isEmpty(b)) continue;
    if (isUnbounded(b)) oversize_.push_back(i);
    else {
      finite_.push_back(i);
      sizes_.push_back(b.extent().maxCoeff());
    }
  }

  // --- cell size: explicit, or twice the median largest extent --------------------------------------------
  Real cell = cellSize_;
  if (!(cell > 0)) {
    cell = 0;
    if (!sizes_.empty()) {
      auto mid = sizes_.begin() + sizes_.size() / 2;
      std::nth_element(sizes_.begin(), mid, sizes_.end());
      cell = 2 * *mid;
      // Point-like boxes (median extent 0): fall back to the largest extent, then to 1 m.
      if (!(cell > 0)) cell = *std::max_element(sizes_.begin(), sizes_.end());
    }
    if (!(cell > 0) || !std::isfinite(cell)) cell = 1;
  }
  usedCellSize_ = cell;
  const Real inv = 1 / cell;

  // --- 2. bin finite boxes (moving the too-large ones to the oversize list) --------------------------------
  size_t kept = 0;
  for (uint32_t i : finite_) {
    const Aabb& b = boxes[i];
    const int64_t x0 = cellCoord(b.lo.x(), inv), x1 = cellCoord(b.hi.x(), inv);
    const int64_t y0 = cellCoord(b.lo.y(), inv), y1 = cellCoord(b.hi.y(), inv);
    const int64_t z0 = cellCoord(b.lo.z(), inv), z1 = cellCoord(b.hi.z(), inv);
    if (Real(x1 - x0 + 1) > oversizeFactor_ || Real(y1 - y0 + 1) > oversizeFactor_ ||
        Real(z1 - z0 + 1) > oversizeFactor_) {
      oversize_.push_back(i);
      continue;
    }
    finite_[kept++] = i;
    for (int64_t x = x0; x <= x1; ++x)
      for (int64_t y = y0; y <= y1; ++y)
        for (int64_t z = z0; z <= z1; ++z) cellKeys_.push_back((uint64_t(cellHash(x, y, z)) << 32) | i);
  }
  finite_.resize(kept);
  radixSortKeys(cellKeys_, sortTmp_);
  cellKeys_.erase(std::unique(cellKeys_.begin(), cellKeys_.end()), cellKeys_.end());

  // --- 3. pairs within each bucket, owner-cell rule -----------------------------------------------------
  const size_t nk = cellKeys_.size();
  numCellEntries_ = nk;
  size_t tests = 0;
  for (size_t s = 0; s < nk;) {
    const uint32_t key = uint32_t(cellKeys_[s] >> 32);
    size_t e = s + 1;
    while (e < nk && uint32_t(cellKeys_[e] >> 32) == key) ++e;
    tests += (e - s) * (e - s - 1) / 2;
    for (size_t p = s; p < e; ++p) {
      const uint32_t a = uint32_t(cellKeys_[p]);
      const Aabb& ba = boxes[a];
      for (size_t q = p + 1; q < e; ++q) {
        const uint32_t b = uint32_t(cellKeys_[q]);  // b > a: the bucket is sorted by index
        const Aabb& bb = boxes[b];
        if (!ba.overlaps(bb)) continue;
        const Vec3 lo = ba.lo.cwiseMax(bb.lo);
        if (cellHash(cellCoord(lo.x(), inv), cellCoord(lo.y(), inv), cellCoord(lo.z(), inv)) != key) continue;
        pairKeys_.push_back((uint64_t(a) << 32) | b);
      }
    }
    s = e;
  }

  // --- 4. oversize boxes against everything ---------------------------------------------------------------
  const size_t no = oversize_.size();
  if (no > 0) tests += no * finite_.size() + no * (no - 1) / 2;
  numCandidateTests_ = tests;
  for (size_t k = 0; k < oversize_.size(); ++k) {
    const uint32_t o = oversize_[k];
    const Aabb& bo = boxes[o];
    for (uint32_t f : finite_)
      if (bo.overlaps(boxes[f])) pairKeys_.push_back(o < f ? (uint64_t(o) << 32) | f : (uint64_t(f) << 32) | o);
    for (size_t m = k + 1; m < oversize_.size(); ++m) {
      const uint32_t o2 = oversize_[m];
      if (bo.overlaps(boxes[o2]))
        pairKeys_.push_back(o < o2 ? (uint64_t(o) << 32) | o2 : (uint64_t(o2) << 32) | o);
    }
  }

  // --- 5. sorted output ------------------------------------------------------------------------------------
  radixSortKeys(pairKeys_, sortTmp_);
  outPairs.reserve(pairKeys_.size());
  for (uint64_t k : pairKeys_) outPairs.emplace_back(uint32_t(k >> 32), uint32_t(k));
}

}  // namespace scree::detail
