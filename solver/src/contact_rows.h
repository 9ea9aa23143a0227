// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Contact rows and their warm-start cache (solver-private; built by contact_rows.cpp, read back by
// store_results.cpp).
//
// Row layout of one solved GeometryContact: [friction and rolling rows of all its points][its normal rows], so
// the PGS sweeps meet a contact's tangents next to each other and its normals last. Each enabled point gets a
// normal row (contact_law.h), two friction rows when mu > 0 (the friction model decides box, scaled box or
// projected cone) and two rolling-resistance rows when the material has a rolling coefficient.
//
// Manifolds (DESIGN, issue 18; docs/solver-internals.md "Resting stacks"): a contact of 2..16 points with one
// normal and ITERATIVE solve type has its normal rows solved as one block (ConstraintRow::blockCount, pgs.cpp).
// When its points also share mu (> 0), surface velocity and no primary direction, have no rolling resistance
// and the friction model is a scaled box or projected cone, its friction is not per point but one tangent pair
// at the manifold's centre bounded by mu * sum(lambda_n) and one twist row about the normal bounded by
// mu * r_eff * sum(lambda_n) (r_eff the points' mean distance from the centre): [t1, t2, twist][normals].
// Per-point friction rows solved in Gauss-Seidel order push a symmetric manifold sideways (each corner's row sees
// the previous corners' impulses); the centre pair acts on the manifold as a whole.
//
// Warm start: the impulses of last step's points, keyed by (geometry pair, narrowphase feature id), start
// this step's rows; the cache also carries the approach speed of a speculative stop (the impact memory of the
// contact law).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <utility>
#include <vector>

#include "scree/core/math.h"
#include "scree/core/parallel.h"

namespace scree::detail {

/// A contact point and its rows.
struct PointRows {
  uint32_t contact, point;
  int32_t normal, t1;  // t1 = -1: no friction rows; t2 = t1 + 1
  Vec3 tangent1, tangent2;
  Real impactSpeed;
  // Manifold friction (twist >= 0): t1, t2 are the manifold's rows at its centre, shared by its points. The
  // point reports the share  F / n + lambda_twist * twistArm  of the manifold's friction impulse F, where
  // twistArm = normal x (point - centre) / sum |point - centre|^2: the shares sum to F and their moment about the
  // centre is the twist impulse, so the warm start rebuilds both from the points' cached friction.
  int32_t twist = -1;
  Real share = 1;
  Vec3 twistArm = Vec3::Zero();
};

/// Where the parallel row build puts one contact's rows (contact_rows.cpp): its first row, point and coupling,
/// its row count (0: not solved) and point count; and where the grouped store puts its first warm-start entry
/// (store_results.cpp: the entries in contact order).
struct ContactLayout {
  uint32_t row, point, coupling, count;
  uint32_t points = 0, entry = 0;
};

/// A run of one group's contacts for the grouped build and store (contact_rows.cpp, store_results.cpp): entries
/// [first, last) of SimulationState::contactGroups[group].
struct ContactChunk {
  uint32_t group, first, last;
};

/// What the rows of one chunk (or of the serial build) tallied (contact_rows.cpp; summed in chunk order after the
/// build). mismatch: a contact of a fill on last step's layout (contact_rows.cpp) found its row or point count
/// changed and wrote nothing.
struct ChunkTally {
  size_t numPoints = 0, numWarm = 0, numSolved = 0;
  bool nonIterative = false;
  bool mismatch = false;
  ChunkTally& operator+=(const ChunkTally& o) {
    numPoints += o.numPoints;
    numWarm += o.numWarm;
    numSolved += o.numSolved;
    nonIterative = nonIterative || o.nonIterative;
    mismatch = mismatch || o.mismatch;
    return *this;
  }
};

/// Runs f(c) for every chunk c in [0, numChunks) on `threads` threads of the team (scree/core/parallel.h): thread
/// 0 takes chunks from the front, thread 1 from the back, each claim one atomic add, until they meet; on one
/// thread (or a busy team) thread 0 takes them all. For work whose result does not depend on which thread does
/// a chunk (each chunk writes its own places). Returns the fewest threads a job got (1 when the team was busy).
///
/// DESIGN (issue 18, two-thread scaling; docs/solver-internals.md "The row build and the store shared from both
/// ends"): the grouped row build and the store gave each region's contacts to the region's thread, which
/// balanced the counts (pyramid20: 191, 190 and the boundary's 19) but not the times. With the host's cores
/// trading lines fast, perf gave thread 0's share of the fill about twice thread 1's samples (probably because
/// thread 0 runs the serial stages between the steps, whose data push its region's rows out of its cache); where
/// they trade lines slowly, thread 1's first reads of the contacts the narrowphase wrote made its count pass
/// three times thread 0's. Sharing from both ends lets the thread that is ahead take over the other's last
/// chunks, and each region's contacts still go mostly to its thread. Measured on pyramid20, two threads: 3-8 %
/// faster in the slow state, no measurable change in the fast one.
template <class F>
int forChunksFromBothEnds(int threads, uint32_t numChunks, F&& f) {
  threads = std::min(threads, 2);
  int ran = threads;
  std::atomic<uint32_t> claimed{0};
  runTeam(threads, [&](int t, int n) {
    if (t == 0) ran = n;
    for (uint32_t mine = 0; claimed.fetch_add(1, std::memory_order_relaxed) < numChunks; ++mine)
      f(t == 0 ? mine : numChunks - 1 - mine);
  });
  return ran;
}

/// The row range and solver bodies of one solved contact or constraint (the couplings of the shock order).
struct CouplingRange {
  int32_t ia, ib;
  uint32_t begin, count;
  bool joint;
};

class WarmStartCache {
 public:
  struct Entry {
    uint64_t pair;
    uint32_t feature;
    Real normal;
    Vec3 friction;
    Real impactSpeed;
    Vec3 point;  ///< the contact point (world, at the start of its step)
    bool operator<(const Entry& o) const { return pair != o.pair ? pair < o.pair : feature < o.feature; }
  };
  const Entry* find(uint64_t pair, uint32_t feature) const {
    const Entry key{pair, feature, 0, Vec3::Zero(), 0, Vec3::Zero()};
    auto it = std::lower_bound(current_.begin(), current_.end(), key);
    if (it != current_.end() && it->pair == pair && it->feature == feature) return &*it;
    return nullptr;
  }
  /// The entry of (pair, feature), else the pair's entry nearest to `point` within kMatchDistance, else null.
  ///
  /// Why the position fallback (DESIGN: this is what stopped resting towers from toppling by themselves): on
  /// exactly coincident faces (an aligned stack) a corner of the clipped incident face lies on a reference side
  /// plane, and roundoff decides which clip label -- which feature id -- it gets. Measured on the issue-18 tower
  /// (10 boxes of 0.6 m, docs/solver-internals.md "Resting stacks"): at step 3 two of the top manifold's four
  /// points got new ids and started from zero while the other two kept last step's impulse; that unequal start
  /// tilted the box and warm starting fed the tilt back step after step (top offset 1.4 mm at 1.5 s, fallen at
  /// 2.5 s). Matched by position the tower stays within 0.2 mm for 5 s. The distance is small on purpose: at
  /// 1 mm pyramid20's points picked up their neighbours' impulses (drift 0.3 -> 6.7 cm at 16 iterations).
  const Entry* find(uint64_t pair, uint32_t feature, const Vec3& point) const {
    if (const Entry* e = find(pair, feature)) return e;
    const Entry key{pair, 0, 0, Vec3::Zero(), 0, Vec3::Zero()};
    const Entry* best = nullptr;
    Real bestD2 = kMatchDistance * kMatchDistance;
    for (auto it = std::lower_bound(current_.begin(), current_.end(), key);
         it != current_.end() && it->pair == pair; ++it) {
      const Real d2 = (it->point - point).squaredNorm();
      if (d2 <= bestD2) {
        bestD2 = d2;
        best = &*it;
      }
    }
    return best;
  }
  /// The entries of one pair, [first, second) (one binary search per contact instead of one or two per point;
  /// issue 18, row build cost). find(range, ...) gives the same entry as find(pair, ...).
  std::pair<const Entry*, const Entry*> pairRange(uint64_t pair) const {
    const Entry key{pair, 0, 0, Vec3::Zero(), 0, Vec3::Zero()};
    auto it = std::lower_bound(current_.begin(), current_.end(), key);
    auto end = it;
    while (end != current_.end() && end->pair == pair) ++end;
    const Entry* base = current_.data();
    return {base + (it - current_.begin()), base + (end - current_.begin())};
  }
  /// pairRange(pair) for pairs asked in ascending order (the row build's contacts are sorted by pair, like the
  /// entries): a cursor walks the entries forward from the last pair's, so a step's lookups are one pass over the
  /// cache instead of a binary search each, whose first probes missed the cache (perf: 2.7 % of buildContactRows
  /// on pyramid20, issue 18). A pair below the cursor (contacts not in pair order) falls back to the binary
  /// search. Any cursor inside the entries gives pairRange's range (the entries before it are below the pair, or
  /// the search falls back); one left past the end by a commit of fewer entries is clamped. Start each pass with
  /// resetCursor(), so that it walks from the first entry.
  std::pair<const Entry*, const Entry*> pairRangeAscending(uint64_t pair) { return pairRangeAscending(pair, cursor_); }
  /// pairRangeAscending with the caller's cursor (one per thread of the parallel row build; start it at 0).
  std::pair<const Entry*, const Entry*> pairRangeAscending(uint64_t pair, size_t& cursor) const {
    const Entry* base = current_.data();
    const Entry* last = base + current_.size();
    const Entry* it = base + std::min(cursor, current_.size());
    if (it != base && it[-1].pair >= pair) return pairRange(pair);  // behind the cursor
    // Forward: a few entries linearly (the next pair's are usually next), then a binary search of the rest.
    constexpr int kLinear = 8;
    int k = 0;
    while (it != last && it->pair < pair && k < kLinear) {
      ++it;
      ++k;
    }
    if (it != last && it->pair < pair) {
      const Entry key{pair, 0, 0, Vec3::Zero(), 0, Vec3::Zero()};
      it = base + (std::lower_bound(current_.begin() + (it - base), current_.end(), key) - current_.begin());
    }
    const Entry* end = it;
    while (end != last && end->pair == pair) ++end;
    cursor = size_t(end - base);
    return {it, end};
  }
  void resetCursor() { cursor_ = 0; }
  static const Entry* find(std::pair<const Entry*, const Entry*> range, uint32_t feature, const Vec3& point) {
    for (const Entry* e = range.first; e != range.second; ++e)
      if (e->feature == feature) return e;
    const Entry* best = nullptr;
    Real bestD2 = kMatchDistance * kMatchDistance;
    for (const Entry* e = range.first; e != range.second; ++e) {
      const Real d2 = (e->point - point).squaredNorm();
      if (d2 <= bestD2) {
        bestD2 = d2;
        best = e;
      }
    }
    return best;
  }
  static constexpr Real kMatchDistance = 1e-5;  ///< m
  /// Collect this step's entries with add(), then commit() makes them the cache the next step reads.
  void beginStore() { next_.clear(); }
  void add(const Entry& e) { next_.push_back(e); }
  /// The store in place (store_results.cpp, grouped rows): n entries, each written once by set() on any thread,
  /// each contact's run then ordered by sortRun on the thread that wrote it, and commitPlaced. Last step's
  /// storage is overwritten, not cleared: clearing would refill it with zeros on the calling thread.
  void beginStorePlaced(size_t n) { next_.resize(n); }
  void set(size_t i, const Entry& e) { next_[i] = e; }
  /// Orders entries [begin, end), one pair's, by feature (stable insertion sort: what commit() does to a pair's run).
  void sortRun(size_t begin, size_t end) {
    for (size_t i = begin + 1; i < end; ++i) {
      if (!(next_[i] < next_[i - 1])) continue;
      const Entry e = next_[i];
      size_t j = i;
      for (; j > begin && e < next_[j - 1]; --j) next_[j] = next_[j - 1];
      next_[j] = e;
    }
  }
  /// Makes the placed entries the cache. pairsAscending: the runs' pairs strictly ascend (Space::collide sorts its
  /// contacts by pair), so the sorted runs are sorted entries; otherwise everything is sorted here.
  void commitPlaced(bool pairsAscending) {
    if (!pairsAscending) std::sort(next_.begin(), next_.end());
    std::swap(current_, next_);
  }
  void commit() {
    // The entries arrive in contact order, which Space::collide sorts by geometry pair, i.e. by the key's first
    // field: only each pair's few points need ordering by feature (insertion sort, stable). std::sort on all 80-
    // byte entries was 1.1 % of pyramid20's step (issue 18). Whatever order they came in, the result is sorted.
    for (size_t i = 1; i < next_.size(); ++i) {
      if (!(next_[i] < next_[i - 1])) continue;
      if (next_[i].pair != next_[i - 1].pair) {  // not in pair order: sort everything
        std::sort(next_.begin(), next_.end());
        break;
      }
      const Entry e = next_[i];
      size_t j = i;
      for (; j > 0 && e < next_[j - 1]; --j) next_[j] = next_[j - 1];
      next_[j] = e;
    }
    std::swap(current_, next_);
  }

 private:
  std::vector<Entry> current_, next_;
  size_t cursor_ = 0;  ///< pairRangeAscending: the first entry after the last pair asked
};

}  // namespace scree::detail
