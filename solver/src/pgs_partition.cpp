// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Partitioned sweep schedule (issue 18, sweep scheduling; pgs.h PgsPartition, docs/solver-internals.md
// "Partitioned sweeps"): the units cut into two regions that share no movable body plus a boundary.
//
// DESIGN:
//  - Why regions and not colours: a coloured sweep needs one barrier per colour and sweep (pyramid20: about 8
//    colours x 10 sweeps, plus the single-thread groups), and on a 2-core machine each barrier costs about as much
//    as the work between two of them. Two regions need a barrier only where the sweep passes from the regions
//    to the boundary and back: since the sweeps alternate direction, a forward sweep ends and the next backward
//    sweep begins with the boundary, so a pair of sweeps needs two barriers, ten sweeps ten. The boundary itself
//    is shared out in two phases when it is large enough (splitBoundary below): two more barriers per pair.
//  - The cut: a plane normal to one coordinate axis through the weighted median of the movable bodies' positions,
//    each body weighted by the rows of its units (a unit's rows shared equally among its movable bodies), so the
//    two regions carry about equal work. All three axes are tried and the one whose boundary holds the fewest
//    rows is kept (ties: the lower axis). Static and kinematic bodies belong to no region: the sweeps never
//    change them, so units of both regions may read them (pgs.cpp gives region 1's units private copies so that
//    no two threads store to one body).
//  - Determinism: the cut depends only on positions, rows and body indices (ties in a coordinate broken by the
//    body index), never on the thread count; within each group the units keep the serial sweep's order (the
//    boundary's: that of its phases, itself a serial order).
//  - Cost: three sorts of the movable bodies per step (pyramid20: 210 bodies), storage reused across steps.
#include <algorithm>

#include "scree/solver/pgs.h"

namespace scree::detail {

namespace {
inline bool movableBody(const SolverBodyState& b) { return PgsPartition::movable(b); }
/// A unit's movable bodies (a unit's rows all act on the same two bodies); returns how many (0-2).
int movableBodies(const std::vector<ConstraintRow>& rows, const std::vector<SolverBodyState>& bodies,
                  const PgsPartition::Unit& un, int32_t out[2]) {
  int m = 0;
  if (un.count == 0) return 0;
  const ConstraintRow& r = rows[un.begin];
  for (const int32_t b : {r.bodyA, r.bodyB})
    if (b >= 0 && movableBody(bodies[size_t(b)]) && (m == 0 || out[0] != b)) out[m++] = b;
  return m;
}
}  // namespace

void PgsSolver::partition(const std::vector<ConstraintRow>& rows, const std::vector<SolverBodyState>& bodies,
                          PgsPartition& p) {
  constexpr int R = PgsPartition::kRegions;
  static_assert(R == 2, "the cut bisects once");
  const size_t nb = bodies.size(), nu = p.units.size();
  auto unitBodies = [&](const PgsPartition::Unit& un, int32_t out[2]) { return movableBodies(rows, bodies, un, out); };
  // The cut is kept while the contact graph is unchanged (same units, bodies and row counts in the same order):
  // re-cutting every step cost about 3 % of pyramid20's step, and a cut from a few steps ago is as good.
  bool same = p.bodyRegion.size() == nb && p.signature.size() == nu;
  for (size_t u = 0; u < nu; ++u) {
    const PgsPartition::Unit& un = p.units[u];
    uint64_t sig = un.count;
    if (un.count > 0)
      sig |= uint64_t(uint32_t(rows[un.begin].bodyA) & 0xfffffu) << 20 |
             uint64_t(uint32_t(rows[un.begin].bodyB) & 0xfffffu) << 40;
    if (same && p.signature[u] != sig) same = false;
    if (!same) {
      if (p.signature.size() != nu) p.signature.resize(nu);
      p.signature[u] = sig;
    }
  }
  if (!same) cutRegions(rows, bodies, p);
  // Groups: region r, or R for the boundary; a unit with no movable body goes to region 0. Any region map
  // gives a valid schedule (a unit is in a region only if all its movable bodies are); a body the kept cut did not
  // see as movable (region -1) sends its units to the boundary, which one thread sweeps.
  p.unitGroup.resize(nu);
  uint32_t count[R + 1] = {};
  for (size_t u = 0; u < nu; ++u) {
    int32_t b[2];
    const int m = unitBodies(p.units[u], b);
    int8_t g = 0;
    if (m >= 1) g = p.bodyRegion[size_t(b[0])];
    if (m == 2 && p.bodyRegion[size_t(b[1])] != g) g = R;
    if (g < 0) g = R;
    p.unitGroup[u] = g;
    ++count[g];
  }
  p.split[0] = 0;
  for (int g = 0; g <= R; ++g) p.split[g + 1] = p.split[g] + count[g];
  uint32_t next[R + 1];
  for (int g = 0; g <= R; ++g) next[g] = p.split[g];
  p.order.resize(nu);
  for (size_t u = 0; u < nu; ++u) p.order[next[p.unitGroup[u]]++] = p.units[u];
  splitBoundary(rows, bodies, p);
}

// DESIGN (issue 18, two-thread scaling; docs/solver-internals.md "The boundary swept by both threads"): until
// stop 47 thread 0 swept the whole boundary while thread 1 waited. The boundary's units couple a body of each
// region, so half of its bodies sit in the other thread's cache: per row it cost pyramid20 about three times a
// region's row (perf), and it was about a quarter of thread 1's waits. Now the boundary is cut in two halves in
// the serial order: the first half H0, then the units of the second half that share no movable body with H0
// (H1), then the rest (J, the junction). H0 and H1 touch disjoint bodies, so they commute: thread 0 sweeps H0
// while thread 1 sweeps H1, then thread 0 sweeps J after a barrier. On one thread the order is H0, H1, J, the
// same. A colouring (units of one colour share no body) was tried first: it gave the same balance, but on
// pyramid20, whose boundary is one column of contacts, it swept the column every other contact, and the clamped
// block solves rose by 40 % (callgrind: the one-thread partitioned step +1.1 % instructions). The halves keep the
// column's order but at one contact. The split costs two barriers per pair of sweeps; it is made only when both
// halves have units enough to pay for them and J is small.
void PgsSolver::splitBoundary(const std::vector<ConstraintRow>& rows, const std::vector<SolverBodyState>& bodies,
                              PgsPartition& p) {
  constexpr int R = PgsPartition::kRegions;
  constexpr uint32_t kMinUnitsPerHalf = 4;
  const uint32_t first = p.split[R], last = p.split[R + 1], n = last - first;
  p.boundaryPhases = 0;
  if (n < 2 * kMinUnitsPerHalf) return;
  const size_t nb = std::max(bodies.size(), p.bodyRegion.size());
  if (p.bodyMark.size() < nb) p.bodyMark.resize(nb, 0);
  // Only units of two bodies the regions hold: a static or kinematic body has a private copy per view, which two
  // threads must not both write, and a body the kept cut did not see is local to the boundary's view.
  auto bodiesOf = [&](uint32_t u, int32_t b[2]) {
    if (p.order[u].count == 0) return false;
    const ConstraintRow& r = rows[p.order[u].begin];
    b[0] = r.bodyA;
    b[1] = r.bodyB;
    for (int k = 0; k < 2; ++k)
      if (b[k] < 0 || size_t(b[k]) >= p.bodyRegion.size() || p.bodyRegion[size_t(b[k])] < 0) return false;
    return true;
  };
  const uint32_t half = first + n / 2;
  bool held = true;
  int32_t b[2];
  for (uint32_t u = first; u < half && held; ++u) {
    held = bodiesOf(u, b);
    if (held) p.bodyMark[size_t(b[0])] = p.bodyMark[size_t(b[1])] = 1;
  }
  // The second half in order: H1 first, then the junction.
  p.unitScratch.clear();
  uint32_t junction = 0;
  for (int pass = 0; pass < 2 && held; ++pass)
    for (uint32_t u = half; u < last && held; ++u) {
      held = bodiesOf(u, b);
      const bool joins = held && (p.bodyMark[size_t(b[0])] || p.bodyMark[size_t(b[1])]);
      if (held && joins == (pass == 1)) p.unitScratch.push_back(p.order[u]);
      junction += held && pass == 0 && joins;
    }
  for (uint32_t u = first; u < half; ++u)  // the marks back to zero
    if (p.order[u].count > 0)
      for (const int32_t x : {rows[p.order[u].begin].bodyA, rows[p.order[u].begin].bodyB})
        if (x >= 0 && size_t(x) < p.bodyMark.size()) p.bodyMark[size_t(x)] = 0;
  // Not worth two barriers: a second half of too few units, or a junction of more than a quarter.
  const uint32_t h1 = last - half - junction;
  if (!held || h1 < kMinUnitsPerHalf || junction * 4 > n) return;
  std::copy(p.unitScratch.begin(), p.unitScratch.end(), p.order.begin() + half);
  p.boundarySplit[0] = first;
  p.boundaryMid[0] = half;
  p.boundarySplit[1] = half + h1;
  p.boundaryPhases = 1;
  if (junction > 0) {
    p.boundaryMid[1] = last;  // the junction: thread 0's
    p.boundarySplit[2] = last;
    p.boundaryPhases = 2;
  }
}

void PgsSolver::cutRegions(const std::vector<ConstraintRow>& rows, const std::vector<SolverBodyState>& bodies,
                           PgsPartition& p) {
  const size_t nb = bodies.size();
  const bool havePositions = p.bodyPosition.size() >= nb;
  auto unitBodies = [&](const PgsPartition::Unit& un, int32_t out[2]) { return movableBodies(rows, bodies, un, out); };
  p.bodyWeight.assign(nb, 0);
  Real total = 0;
  for (const PgsPartition::Unit& un : p.units) {
    int32_t b[2];
    const int m = unitBodies(un, b);
    for (int k = 0; k < m; ++k) p.bodyWeight[size_t(b[k])] += Real(un.count) / Real(m);
    if (m > 0) total += Real(un.count);
  }
  p.sortedBodies.clear();
  for (uint32_t i = 0; i < nb; ++i)
    if (p.bodyWeight[i] > 0) p.sortedBodies.push_back(i);
  p.bodyRegion.assign(nb, -1);
  // Regions for one axis: the bodies sorted by (coordinate, index), cut where the weight reaches half.
  auto cut = [&](int axis) {
    auto key = [&](uint32_t i) { return havePositions ? p.bodyPosition[i][axis] : Real(i); };
    std::sort(p.sortedBodies.begin(), p.sortedBodies.end(), [&](uint32_t a, uint32_t b) {
      const Real ka = key(a), kb = key(b);
      return ka < kb || (ka == kb && a < b);
    });
    Real acc = 0;
    for (const uint32_t i : p.sortedBodies) {
      p.bodyRegion[i] = acc < 0.5 * total ? 0 : 1;
      acc += p.bodyWeight[i];
    }
  };
  // Rows in the boundary for the current regions.
  auto boundaryRows = [&] {
    size_t n = 0;
    for (const PgsPartition::Unit& un : p.units) {
      int32_t b[2];
      if (unitBodies(un, b) == 2 && p.bodyRegion[size_t(b[0])] != p.bodyRegion[size_t(b[1])]) n += un.count;
    }
    return n;
  };
  p.axis = 0;
  if (havePositions) {
    size_t best = SIZE_MAX;
    for (int axis = 0; axis < 3; ++axis) {
      cut(axis);
      const size_t n = boundaryRows();
      if (n < best) {
        best = n;
        p.axis = axis;
      }
    }
  }
  cut(p.axis);
}

}  // namespace scree::detail
