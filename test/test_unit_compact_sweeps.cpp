// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Compact manifold sweeps (pgs.cpp "Compact manifold sweeps", PgsBlocks::Manifold; docs/solver-internals.md):
// the serial sweeps with a PgsBlocks read a manifold contact from a compact record instead of its ConstraintRows.
// The law and the visiting order are the ConstraintRow sweeps', so both must give the same impulses and
// velocities up to roundoff, on rows of the layout contact_rows.cpp builds ([t1, t2, twist][normal block]) mixed
// with rows of other forms, with a static body, and with a tipping box whose block update leaves a bound.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "scree/core/parallel.h"
#include "scree/solver/pgs.h"

using namespace scree;
using namespace scree::detail;

namespace {

/// Rows of one planar manifold between bodies a (above) and b (below, -1: static ground) in contact_rows.cpp's
/// layout: a square face of half-side s centred at `centre` (world), normal +z from b to a. ca, cb: centres of
/// mass. Returns the index of its first row.
int addManifold(std::vector<ConstraintRow>& rows, int a, int b, const Vec3& ca, const Vec3& cb, const Vec3& centre,
                Real s, Real mu) {
  const Vec3 n(0, 0, 1);
  const int base = int(rows.size());
  const int firstNormal = base + 3;
  auto jac = [&](ConstraintRow& r, const Vec3& p, const Vec3& d) {
    r.bodyA = a;
    r.bodyB = b;
    r.jLinA = d;
    r.jAngA = (p - ca).cross(d);
    r.jLinB = -d;
    r.jAngB = -(p - cb).cross(d);
  };
  const Real rEff = s * std::sqrt(2.0);
  for (int k = 0; k < 3; ++k) {
    ConstraintRow f;
    if (k < 2) {
      jac(f, centre, k == 0 ? Vec3(1, 0, 0) : Vec3(0, 1, 0));
      f.mu = mu;
      f.e = 1e-6;
      if (k == 0) f.pairedRow = base + 1;
    } else {
      f.bodyA = a;
      f.bodyB = b;
      f.jAngA = n;
      f.jAngB = -n;
      f.mu = mu * rEff;
      f.e = 1e-6;
    }
    f.friction = true;
    f.normalRow = firstNormal;
    f.normalCount = 4;
    rows.push_back(f);
  }
  const Real us[4] = {-1, 1, 1, -1}, vs[4] = {-1, -1, 1, 1};
  for (int i = 0; i < 4; ++i) {
    ConstraintRow r;
    jac(r, centre + Vec3(us[i] * s, vs[i] * s, 0), n);
    r.e = 1e-8;
    r.rhs = 0.01;  // a little penetration to recover
    r.lo = 0;
    r.hi = 1e300;
    r.blockBegin = firstNormal;
    r.blockCount = 4;
    r.blockU = us[i];
    r.blockV = vs[i];
    rows.push_back(r);
  }
  return base;
}

/// A bounded free row on one body (a unit of its own in the partitioned sweeps' tests): |lambda| <= 1.
ConstraintRow boundedFreeRow(int body, const Vec3& jLin, Real rhs) {
  ConstraintRow r;
  r.bodyA = body;
  r.jLinA = jLin;
  r.jAngA = Vec3(0, 0, 1);
  r.rhs = rhs;
  r.e = 1e-4;
  r.lo = -1;
  r.hi = 1;
  return r;
}

}  // namespace

// Two unit boxes (mass 2) stacked on the static ground, the upper one tipping (w_x = 3 rad/s: its block update
// leaves a corner's bound), a free row on the upper box before the manifolds and one after. Warm start on the lower
// manifold's normals and friction; with `varied`, unequal warm starts on both manifolds' normals (so that a per-body
// sum differs from one row's impulse times four) and unequal principal inertias.
struct TippingStack {
  std::vector<SolverBodyState> bodies = std::vector<SolverBodyState>(3);
  std::vector<ConstraintRow> rows;
  int m0 = 0, m1 = 0;
  explicit TippingStack(bool varied) {
    for (int i = 0; i < 2; ++i) {
      bodies[size_t(i)].invMass = 0.5;
      bodies[size_t(i)].invInertia = varied ? Mat3(Vec3(3.0, 2.0, 2.5).asDiagonal()) : Mat3(Mat3::Identity() * 3.0);
    }
    bodies[0].v = Vec3(0.2, -0.1, -0.5);
    bodies[0].w = Vec3(0.05, 0, 0.1);
    bodies[1].v = Vec3(0, 0.1, -0.2);
    bodies[1].w = Vec3(3.0, 0.2, 0);
    const Vec3 c0(0, 0, 0.5), c1(0.1, 0, 1.5);
    ConstraintRow free1;
    free1.bodyA = 1;
    free1.jLinA = Vec3(0.3, 1, 0).normalized();
    free1.rhs = 0.05;
    free1.e = 1e-4;
    rows.push_back(free1);
    m0 = addManifold(rows, 0, -1, c0, Vec3::Zero(), Vec3(0, 0, 0), 0.5, 0.6);
    m1 = addManifold(rows, 1, 0, c1, c0, Vec3(0.05, 0, 1.0), 0.45, 0.4);
    ConstraintRow free2 = free1;
    free2.jLinA = Vec3(0, 0, 1);
    free2.jAngA = Vec3(0, 1, 0);
    free2.lo = -1;
    free2.hi = 1;
    rows.push_back(free2);
    for (int i = 0; i < 4; ++i) {
      rows[size_t(m0 + 3 + i)].lambda = varied ? 2.5 + 0.1 * i : 2.5;
      if (varied) rows[size_t(m1 + 3 + i)].lambda = 1.0 + 0.2 * i;
    }
    rows[size_t(m0)].lambda = 0.3;
  }
};

TEST_SUITE("compact sweeps") {

TEST_CASE("compact manifold sweeps give the ConstraintRow sweeps' impulses and velocities") {
  // TippingStack: the tipping box's block update leaves a corner's bound, so the clamped ConstraintRow path runs
  // inside the compact sweep; the free rows before and after the manifolds are swept in place.
  const TippingStack scene(false);
  const std::vector<ConstraintRow>& rows = scene.rows;
  const std::vector<SolverBodyState>& bodies = scene.bodies;
  const int m0 = scene.m0, m1 = scene.m1;

  std::vector<ConstraintRow> rowsC = rows, rowsR = rows;
  std::vector<SolverBodyState> bodiesC = bodies, bodiesR = bodies;
  PgsBlocks blocks;
  PgsSolver::prepare(rowsC, bodiesC, &blocks);
  PgsSolver::iterate(rowsC, bodiesC, 10, &blocks);
  // The compact path ran: both manifolds have records, the plan is row, manifold, manifold, row.
  REQUIRE(blocks.manifolds.size() == 2);
  CHECK(blocks.manifolds[0].row == uint32_t(m0));
  CHECK(blocks.manifolds[1].row == uint32_t(m1));
  REQUIRE(blocks.plan.size() == 4);
  CHECK(blocks.plan[0].manifold == -1);
  CHECK(blocks.plan[3].manifold == -1);
  // The reference: the ConstraintRow sweeps (no PgsBlocks: each block assembled and factored on its visit).
  PgsSolver::prepare(rowsR, bodiesR, nullptr);
  PgsSolver::iterate(rowsR, bodiesR, 10, nullptr);

  // Same law, other roundoff: agreement to 1e-9 of the largest impulse (the paths differ by ~1e-15 per
  // operation; 10 sweeps of a well-conditioned system do not amplify that past 1e-12).
  Real scale = 0;
  for (const ConstraintRow& r : rowsR) scale = std::max(scale, std::abs(r.lambda));
  REQUIRE(scale > 0.1);  // the rows carry load
  bool clamped = false;
  for (size_t i = 0; i < rows.size(); ++i) {
    CHECK_MESSAGE(std::abs(rowsC[i].lambda - rowsR[i].lambda) <= 1e-9 * scale,
                  "row " << i << ": compact " << rowsC[i].lambda << ", ConstraintRow " << rowsR[i].lambda);
    clamped |= rowsR[i].blockCount > 0 && rowsR[i].lambda == 0;
  }
  CHECK_MESSAGE(clamped, "the tipping box should leave a corner of its manifold at the bound");
  for (int b = 0; b < 2; ++b) {
    CHECK((bodiesC[size_t(b)].v - bodiesR[size_t(b)].v).norm() <= 1e-9);
    CHECK((bodiesC[size_t(b)].w - bodiesR[size_t(b)].w).norm() <= 1e-9);
  }
  // The static ground is not written.
  CHECK(bodiesC[2].v == Vec3::Zero());
  CHECK(bodiesC[2].w == Vec3::Zero());
}

TEST_CASE("partitioned sweeps on their own body layout give the serial sweeps' bits in the same order") {
  // PgsSolver::iterate with a partition sweeps a local copy of the bodies laid out region by region, with the
  // compact records in region order and the other units' rows re-indexed (pgs.cpp, "Partitioned sweeps"). Its
  // schedule -- forward: region 0, region 1, boundary; backward: the reverse -- is the serial symmetric sweep
  // over the units in that order. Rows built in that order therefore give the serial sweeps' result bit for
  // bit, whatever the layout did: that is the check. Scene: boxes 0, 1 (x < 0, region 0) and 2, 3 (x > 0,
  // region 1) on a static ground (body 4, shared by both regions: each gets a private copy), box 6 on box 0 and
  // box 5 on box 3, box 5 tipping (w_x = 3 rad/s: its block update leaves a bound, so compactBlock's fallback
  // runs on ConstraintRows inside region 1's sweep), a free row on box 1 and one on box 2 (units that are not
  // manifolds: their rows are swept from the local layout), and a manifold between boxes 1 and 2 (the boundary).
  std::vector<SolverBodyState> bodies(7);
  const Vec3 c[7] = {Vec3(-1.5, 0, 0.5), Vec3(-0.5, 0, 0.5), Vec3(0.5, 0, 0.5), Vec3(1.5, 0, 0.5),
                     Vec3::Zero(),       Vec3(1.5, 0, 1.5),  Vec3(-1.5, 0, 1.5)};
  for (int i : {0, 1, 2, 3, 5, 6}) {
    bodies[size_t(i)].invMass = 0.5;
    bodies[size_t(i)].invInertia = Mat3::Identity() * 3.0;
    bodies[size_t(i)].v = Vec3(0.01 * i, -0.02, -0.3);
  }
  bodies[5].w = Vec3(3.0, 0.2, 0);
  std::vector<ConstraintRow> rows;
  PgsPartition p;
  auto unit = [&](int begin) { p.units.push_back({uint32_t(begin), uint32_t(rows.size()) - uint32_t(begin)}); };
  auto freeRow = [&](int body) {
    const int begin = int(rows.size());
    rows.push_back(boundedFreeRow(body, Vec3(0.3, 1, 0).normalized(), 0.05));
    unit(begin);
  };
  // Region 0's units, region 1's, then the boundary's: the partition's order is the row order.
  unit(addManifold(rows, 0, 4, c[0], c[4], Vec3(-1.5, 0, 0), 0.5, 0.6));
  unit(addManifold(rows, 1, 4, c[1], c[4], Vec3(-0.5, 0, 0), 0.5, 0.6));
  unit(addManifold(rows, 6, 0, c[6], c[0], Vec3(-1.5, 0, 1), 0.45, 0.5));
  freeRow(1);
  unit(addManifold(rows, 2, 4, c[2], c[4], Vec3(0.5, 0, 0), 0.5, 0.6));
  unit(addManifold(rows, 3, 4, c[3], c[4], Vec3(1.5, 0, 0), 0.5, 0.6));
  unit(addManifold(rows, 5, 3, c[5], c[3], Vec3(1.55, 0, 1), 0.45, 0.4));
  freeRow(2);
  unit(addManifold(rows, 2, 1, c[2], c[1], Vec3(0, 0, 0.5), 0.3, 0.5));
  for (size_t i = 0; i < rows.size(); ++i)
    if (rows[i].blockCount > 0) rows[i].lambda = 1.5;  // warm start on every normal row
  p.bodyPosition.assign(c, c + 7);

  std::vector<ConstraintRow> rowsP = rows, rowsS = rows;
  std::vector<SolverBodyState> bodiesP = bodies, bodiesS = bodies;
  PgsBlocks blocksP, blocksS;
  PgsSolver::prepare(rowsP, bodiesP, &blocksP);
  PgsSolver::partition(rowsP, bodiesP, p);
  // The cut is the one intended: x, between boxes 1 and 2; the units keep the row order.
  constexpr int R = PgsPartition::kRegions;
  REQUIRE(p.axis == 0);
  REQUIRE(p.split[1] == 4);
  REQUIRE(p.split[2] == 8);
  REQUIRE(p.split[3] == 9);
  for (size_t u = 0; u < p.order.size(); ++u) REQUIRE(p.order[u].begin == p.units[u].begin);
  const Real dP = PgsSolver::iterate(rowsP, bodiesP, 10, &blocksP, p);
  PgsSolver::prepare(rowsS, bodiesS, &blocksS);
  const Real dS = PgsSolver::iterate(rowsS, bodiesS, 10, &blocksS);

  CHECK(dP == dS);
  bool clamped = false;
  for (size_t i = 0; i < rows.size(); ++i) {
    CHECK_MESSAGE(rowsP[i].lambda == rowsS[i].lambda,
                  "row " << i << ": partitioned " << rowsP[i].lambda << ", serial " << rowsS[i].lambda);
    // The rows point at the shared bodies again.
    CHECK(rowsP[i].bodyA == rows[i].bodyA);
    CHECK(rowsP[i].bodyB == rows[i].bodyB);
    clamped |= rows[i].bodyA == 5 && rows[i].blockCount > 0 && rowsS[i].lambda == 0;
  }
  CHECK_MESSAGE(clamped, "the tipping box should leave a corner of its manifold at the bound");
  for (size_t b = 0; b < bodies.size(); ++b) {
    CAPTURE(b);
    CHECK(bodiesP[b].v == bodiesS[b].v);
    CHECK(bodiesP[b].w == bodiesS[b].w);
  }
  CHECK(bodiesP[4].v == Vec3::Zero());  // the static ground: its copies' (zero) changes are not written back
  // Every manifold has a record, found by its first row (the shock pass's lookup), with the shared bodies.
  int records = 0;
  for (const PgsBlocks::Manifold& m : blocksP.manifolds) {
    if (m.n < 0) continue;  // a gap between regions
    ++records;
    CHECK(m.a == rows[m.row].bodyA);
    CHECK(m.b == rows[m.row].bodyB);
  }
  CHECK(records == 7);
  CHECK(R == 2);
}

// The boundary in two shares (pgs_partition.cpp splitBoundary, pgs.cpp PgsSolver::iterate): a zigzag column of 24
// boxes, L0 R0 L1 R1 ... (L_j body j at x = -0.5, R_j body 12 + j at x = +0.5, each resting on the one before it,
// the manifold centred on x = 0), so every manifold of the column joins the two regions, like the column of
// contacts on pyramid20's cut. Each box also carries two free rows (units of one body), so that the scene has the
// 64 units the partitioned sweeps need for two threads. The column's 23 manifolds split into the first 11 (thread
// 0), the last 11 (thread 1) and the 12th (the junction: it shares a box with the first half; thread 0, after a
// barrier).
TEST_CASE("partitioned sweeps: the boundary in two shares and a junction, the bits of one thread") {
  constexpr int kPerSide = 12, nb = 2 * kPerSide;
  std::vector<SolverBodyState> bodies(nb);
  std::vector<Vec3> centre(nb);
  PgsPartition proto;
  proto.bodyPosition.assign(nb, Vec3::Zero());
  for (int j = 0; j < kPerSide; ++j) {
    centre[size_t(j)] = Vec3(-0.5, 0, 0.5 + 2 * j);
    centre[size_t(kPerSide + j)] = Vec3(0.5, 0, 1.5 + 2 * j);
    // Only x differs: y and z tie, and a tie in a coordinate falls back on the body index, which gives the same
    // cut; the lowest axis wins the tie.
    proto.bodyPosition[size_t(j)] = Vec3(-0.5, 0, 0);
    proto.bodyPosition[size_t(kPerSide + j)] = Vec3(0.5, 0, 0);
  }
  for (int i = 0; i < nb; ++i) {
    bodies[size_t(i)].invMass = 1.0 / (1.0 + 0.1 * i);
    bodies[size_t(i)].invInertia = Mat3(Vec3(3.0, 2.0 + 0.05 * i, 2.5).asDiagonal());
    bodies[size_t(i)].v = Vec3(0.01 * (i % 5), -0.02 * (i % 3), -0.3 - 0.01 * i);
    bodies[size_t(i)].w = Vec3(0.02 * (i % 4), 0.01 * (i % 7), 0);
  }
  std::vector<ConstraintRow> rows;
  auto unit = [&](int begin) { proto.units.push_back({uint32_t(begin), uint32_t(rows.size()) - uint32_t(begin)}); };
  // The column in the serial order: R_j on L_j, then L_{j+1} on R_j.
  for (int k = 0; k + 1 < nb; ++k) {
    const int lower = k % 2 == 0 ? k / 2 : kPerSide + k / 2, upper = k % 2 == 0 ? kPerSide + k / 2 : k / 2 + 1;
    const Vec3 mid(0, 0, 1.0 + Real(k));
    const int m = addManifold(rows, upper, lower, centre[size_t(upper)], centre[size_t(lower)], mid, 0.3, 0.5);
    for (int i = 0; i < 4; ++i) rows[size_t(m + 3 + i)].lambda = 1.0 + 0.1 * ((k + i) % 5);
    unit(m);
  }
  for (int i = 0; i < nb; ++i)
    for (int k = 0; k < 2; ++k) {
      const int begin = int(rows.size());
      rows.push_back(boundedFreeRow(i, k == 0 ? Vec3(0.3, 1, 0).normalized() : Vec3(0, 0.6, 0.8), 0.05 * (k + 1)));
      unit(begin);
    }
  REQUIRE(proto.units.size() >= 64);

  constexpr int R = PgsPartition::kRegions;
  setNumThreads(2);
  const bool twoThreads = getNumThreads() == 2;
  WARN_MESSAGE(twoThreads, "built without OpenMP: the 2-thread run used one thread");
  for (const int iterations : {10, 9}) {  // 9: the last sweep is forward and ends with the junction
    CAPTURE(iterations);
    std::vector<ConstraintRow> rowsRun[2];
    std::vector<SolverBodyState> bodiesRun[2];
    Real delta[2] = {};
    for (int threads = 1; threads <= 2; ++threads) {
      setNumThreads(threads);
      std::vector<ConstraintRow> rs = rows;
      std::vector<SolverBodyState> bs = bodies;
      PgsPartition p = proto;
      PgsBlocks blocks;
      PgsSolver::prepare(rs, bs, &blocks);
      PgsSolver::partition(rs, bs, p);
      // The cut runs between the sides, so the whole column is the boundary: two shares and the junction.
      REQUIRE(p.axis == 0);
      for (int i = 0; i < nb; ++i) REQUIRE(p.bodyRegion[size_t(i)] == (i < kPerSide ? 0 : 1));
      REQUIRE(p.split[R + 1] - p.split[R] == uint32_t(nb - 1));
      REQUIRE(p.boundaryPhases == 2);
      CHECK(p.boundarySplit[0] == p.split[R]);
      CHECK(p.boundaryMid[0] - p.boundarySplit[0] == 11);
      CHECK(p.boundarySplit[1] - p.boundaryMid[0] == 11);
      CHECK(p.boundaryMid[1] == p.split[R + 1]);  // the junction is thread 0's
      CHECK(p.boundarySplit[2] - p.boundarySplit[1] == 1);
      // The two shares of phase 0 touch disjoint bodies; each keeps the serial order; the junction is the 12th.
      std::vector<int> share(nb, -1);
      for (uint32_t u = p.boundarySplit[0]; u < p.boundarySplit[1]; ++u) {
        const int s = u < p.boundaryMid[0] ? 0 : 1;
        const ConstraintRow& r = rs[p.order[u].begin];
        for (const int32_t x : {r.bodyA, r.bodyB}) {
          CHECK((share[size_t(x)] < 0 || share[size_t(x)] == s));
          share[size_t(x)] = s;
        }
        if (u != p.boundarySplit[0] && u != p.boundaryMid[0]) CHECK(p.order[u - 1].begin < p.order[u].begin);
      }
      CHECK(p.order[p.boundarySplit[1]].begin == proto.units[11].begin);
      CHECK(std::all_of(p.bodyMark.begin(), p.bodyMark.end(), [](uint8_t m) { return m == 0; }));
      delta[threads - 1] = PgsSolver::iterate(rs, bs, iterations, &blocks, p);
      rowsRun[threads - 1] = rs;
      bodiesRun[threads - 1] = bs;
    }
    // Bit for bit: the two shares of a phase touch disjoint bodies, so they commute.
    CHECK(delta[0] == delta[1]);
    for (size_t i = 0; i < rows.size(); ++i) {
      CAPTURE(i);
      CHECK(std::memcmp(&rowsRun[0][i].lambda, &rowsRun[1][i].lambda, sizeof(Real)) == 0);
      CHECK(rowsRun[1][i].bodyA == rows[i].bodyA);  // the rows point at the shared bodies again
    }
    for (int b = 0; b < nb; ++b) {
      CAPTURE(b);
      CHECK(bodiesRun[0][size_t(b)].v == bodiesRun[1][size_t(b)].v);
      CHECK(bodiesRun[0][size_t(b)].w == bodiesRun[1][size_t(b)].w);
      CHECK(bodiesRun[1][size_t(b)].v.allFinite());
    }
    // The sweeps moved the column (else the comparison would be empty).
    CHECK((bodiesRun[0][0].v - bodies[0].v).norm() > 1e-3);
  }
  setNumThreads(1);
}

// Largest |lambda| of the rows and the largest difference between two runs' impulses and velocities.
void compareRuns(const std::vector<ConstraintRow>& rowsD, const std::vector<ConstraintRow>& rowsP,
                 const std::vector<SolverBodyState>& bodiesD, const std::vector<SolverBodyState>& bodiesP) {
  Real scale = 0;
  for (const ConstraintRow& r : rowsP) scale = std::max(scale, std::abs(r.lambda));
  REQUIRE(scale > 0.1);  // the rows carry load
  // The two runs differ only in the order in which the warm start's impulses are summed (a few ulp of the
  // velocities); 10 sweeps of this well-conditioned system do not amplify that past 1e-12 of the impulses.
  for (size_t i = 0; i < rowsP.size(); ++i)
    CHECK_MESSAGE(std::abs(rowsD[i].lambda - rowsP[i].lambda) <= 1e-12 * scale,
                  "row " << i << ": deferred " << rowsD[i].lambda << ", prepared " << rowsP[i].lambda);
  for (size_t b = 0; b < bodiesP.size(); ++b) {
    CAPTURE(b);
    CHECK((bodiesD[b].v - bodiesP[b].v).norm() <= 1e-12);
    CHECK((bodiesD[b].w - bodiesP[b].w).norm() <= 1e-12);
  }
}

TEST_CASE("normal rows prepared on first use give the prepared rows' sweeps, fallbacks and shock pass") {
  // PgsSolver::prepare with deferBlockRows leaves the normal blocks' rows without M^-1 J^T (pgs.cpp, "deferred
  // block rows"): the warm start is applied per body, and the paths that read the rows prepare them first.
  const TippingStack scene(true);
  const PgsSolver::ShockRange m0{uint32_t(scene.m0), 7, 1, 0, -1}, m1{uint32_t(scene.m1), 7, 1, 1, 0};

  SUBCASE("the sweeps, with the tipping box's bound-hit fallback") {
    std::vector<ConstraintRow> rowsD = scene.rows, rowsP = scene.rows;
    std::vector<SolverBodyState> bodiesD = scene.bodies, bodiesP = scene.bodies;
    PgsBlocks blocksD, blocksP;
    PgsSolver::prepare(rowsD, bodiesD, &blocksD, true);
    // Deferred: the blocks say so and their rows have no M^-1 J^T yet.
    REQUIRE(blocksD.starts.size() == 2);
    for (uint32_t slot = 0; slot < 2; ++slot) CHECK_FALSE(blocksD.blocks[slot].rowsReady);
    CHECK(rowsD[size_t(scene.m1 + 3)].mJAngA == Vec3::Zero());
    PgsSolver::prepare(rowsP, bodiesP, &blocksP);
    // The warm start moved the bodies alike.
    for (size_t b = 0; b < 2; ++b) CHECK((bodiesD[b].w - bodiesP[b].w).norm() <= 1e-14);
    PgsSolver::iterate(rowsD, bodiesD, 10, &blocksD);
    PgsSolver::iterate(rowsP, bodiesP, 10, &blocksP);
    compareRuns(rowsD, rowsP, bodiesD, bodiesP);
    // The tipping box's block left a bound, so its fallback prepared its rows (the prepared path's bits); the
    // lower box's block never did and is still deferred.
    bool clamped = false;
    for (int i = 0; i < 4; ++i) clamped |= rowsP[size_t(scene.m1 + 3 + i)].lambda == 0;
    REQUIRE_MESSAGE(clamped, "the tipping box should leave a corner of its manifold at the bound");
    const int32_t slot1 = rowsD[size_t(scene.m1 + 3)].blockSlot, slot0 = rowsD[size_t(scene.m0 + 3)].blockSlot;
    CHECK(blocksD.blocks[size_t(slot1)].rowsReady);
    CHECK_FALSE(blocksD.blocks[size_t(slot0)].rowsReady);
    for (int i = 0; i < 4; ++i) {
      const ConstraintRow &d = rowsD[size_t(scene.m1 + 3 + i)], &q = rowsP[size_t(scene.m1 + 3 + i)];
      CHECK(d.mJAngA == q.mJAngA);
      CHECK(d.mJAngB == q.mJAngB);
      CHECK(d.invDiag == q.invDiag);
    }
    // Then the shock pass over both supports (from the compact records).
    PgsSolver::shockPass(rowsD, bodiesD, {m0, m1}, 16, &blocksD);
    PgsSolver::shockPass(rowsP, bodiesP, {m0, m1}, 16, &blocksP);
    compareRuns(rowsD, rowsP, bodiesD, bodiesP);
  }
  SUBCASE("the shock pass's fallback sweeps on rows no sweep prepared") {
    // Straight from prepare: no compact records, so each support is first tried exactly (solveSupportExactly);
    // the tipping box's solution leaves the bounds and its rows are swept with the lower box frozen.
    std::vector<ConstraintRow> rowsD = scene.rows, rowsP = scene.rows;
    std::vector<SolverBodyState> bodiesD = scene.bodies, bodiesP = scene.bodies;
    PgsBlocks blocksD, blocksP;
    PgsSolver::prepare(rowsD, bodiesD, &blocksD, true);
    PgsSolver::prepare(rowsP, bodiesP, &blocksP);
    PgsSolver::shockPass(rowsD, bodiesD, {m0, m1}, 16, &blocksD);
    PgsSolver::shockPass(rowsP, bodiesP, {m0, m1}, 16, &blocksP);
    compareRuns(rowsD, rowsP, bodiesD, bodiesP);
    CHECK(blocksD.blocks[size_t(rowsD[size_t(scene.m1 + 3)].blockSlot)].rowsReady);  // it was swept
  }
  SUBCASE("a manifold outside the compact layout, swept as ConstraintRows, serial and partitioned") {
    // An upper bound on the tipping box's normal rows keeps it out of the compact layout (fitsCompactLayout):
    // its rows are swept in place, so they are prepared when the sweeps' records are built.
    std::vector<ConstraintRow> rows = scene.rows;
    for (int i = 0; i < 4; ++i) rows[size_t(scene.m1 + 3 + i)].hi = 1e6;
    for (const bool partitioned : {false, true}) {
      CAPTURE(partitioned);
      std::vector<ConstraintRow> rowsD = rows, rowsP = rows;
      std::vector<SolverBodyState> bodiesD = scene.bodies, bodiesP = scene.bodies;
      PgsBlocks blocksD, blocksP;
      PgsPartition pD, pP;
      for (PgsPartition* p : {&pD, &pP}) {
        p->units = {{0, 1}, {uint32_t(scene.m0), 7}, {uint32_t(scene.m1), 7}, {uint32_t(scene.m1 + 7), 1}};
        p->bodyPosition = {Vec3(0, 0, 0.5), Vec3(0.1, 0, 1.5), Vec3::Zero()};
      }
      PgsSolver::prepare(rowsD, bodiesD, &blocksD, true);
      PgsSolver::prepare(rowsP, bodiesP, &blocksP);
      if (partitioned) {
        PgsSolver::partition(rowsD, bodiesD, pD);
        PgsSolver::partition(rowsP, bodiesP, pP);
        PgsSolver::iterate(rowsD, bodiesD, 10, &blocksD, pD);
        PgsSolver::iterate(rowsP, bodiesP, 10, &blocksP, pP);
      } else {
        PgsSolver::iterate(rowsD, bodiesD, 10, &blocksD);
        PgsSolver::iterate(rowsP, bodiesP, 10, &blocksP);
      }
      REQUIRE(blocksD.manifolds.size() >= 1);  // the lower box's manifold is still swept from its record
      compareRuns(rowsD, rowsP, bodiesD, bodiesP);
    }
  }
  SUBCASE("the coloured sweeps prepare every deferred block first") {
    std::vector<ConstraintRow> rowsD = scene.rows, rowsP = scene.rows;
    std::vector<SolverBodyState> bodiesD = scene.bodies, bodiesP = scene.bodies;
    PgsBlocks blocksD, blocksP;
    PgsColouring cD, cP;
    for (PgsColouring* c : {&cD, &cP}) {
      c->units.push_back({0, 1});
      c->units.push_back({uint32_t(scene.m0), 7});
      c->units.push_back({uint32_t(scene.m1), 7});
      c->units.push_back({uint32_t(scene.m1 + 7), 1});
    }
    PgsSolver::prepare(rowsD, bodiesD, &blocksD, true);
    PgsSolver::prepare(rowsP, bodiesP, &blocksP);
    PgsSolver::colour(rowsD, bodiesD, cD);
    PgsSolver::colour(rowsP, bodiesP, cP);
    PgsSolver::iterate(rowsD, bodiesD, 10, &blocksD, cD);
    PgsSolver::iterate(rowsP, bodiesP, 10, &blocksP, cP);
    compareRuns(rowsD, rowsP, bodiesD, bodiesP);
  }
}

TEST_CASE("a plain prepare after partitioned sweeps: the shock pass finds no record of the step before") {
  // The HYBRID path (solve_stage.cpp hybridPath) prepares its rows with the plain PgsSolver::prepare, sweeps a
  // subset of them without compact records and runs the shock pass, which looks a support's record up by its
  // first row (PgsBlocks::rowManifold, filled by the partitioned sweeps). After a step of partitioned sweeps in
  // the same PgsBlocks, that lookup must find nothing, so that each support is solved from this step's rows as
  // with a fresh PgsBlocks; before stop 46 the plain prepare left the lookup of the step before in place, pointing
  // at records it had just cleared. Step 1: TippingStack, partitioned sweeps. Step 2: its rows again, with step
  // 1's impulses as the warm start, prepared plainly in the same PgsBlocks, then the shock pass; against the same
  // on a fresh PgsBlocks, bit for bit.
  const TippingStack scene(true);
  const PgsSolver::ShockRange m0{uint32_t(scene.m0), 7, 1, 0, -1}, m1{uint32_t(scene.m1), 7, 1, 1, 0};
  PgsBlocks blocks;
  PgsPartition p;
  p.units = {{0, 1}, {uint32_t(scene.m0), 7}, {uint32_t(scene.m1), 7}, {uint32_t(scene.m1 + 7), 1}};
  p.bodyPosition = {Vec3(0, 0, 0.5), Vec3(0.1, 0, 1.5), Vec3::Zero()};
  std::vector<ConstraintRow> rows1 = scene.rows;
  std::vector<SolverBodyState> bodies1 = scene.bodies;
  PgsSolver::prepare(rows1, bodies1, &blocks);
  PgsSolver::partition(rows1, bodies1, p);
  PgsSolver::iterate(rows1, bodies1, 10, &blocks, p);
  // Both supports were swept from records, which the lookup finds.
  REQUIRE(blocks.rowManifold.size() == rows1.size());
  REQUIRE(blocks.rowManifold[size_t(scene.m0)] >= 0);
  REQUIRE(blocks.rowManifold[size_t(scene.m1)] >= 0);

  std::vector<ConstraintRow> rows2 = scene.rows;
  for (size_t i = 0; i < rows2.size(); ++i) rows2[i].lambda = rows1[i].lambda;
  std::vector<ConstraintRow> rowsF = rows2;
  std::vector<SolverBodyState> bodies2 = scene.bodies, bodiesF = scene.bodies;
  PgsBlocks fresh;
  PgsSolver::prepare(rows2, bodies2, &blocks);
  PgsSolver::prepare(rowsF, bodiesF, &fresh);
  PgsSolver::shockPass(rows2, bodies2, {m0, m1}, 16, &blocks);
  PgsSolver::shockPass(rowsF, bodiesF, {m0, m1}, 16, &fresh);
  Real scale = 0;
  for (size_t i = 0; i < rowsF.size(); ++i) {
    CAPTURE(i);
    CHECK(rows2[i].lambda == rowsF[i].lambda);
    scale = std::max(scale, std::abs(rowsF[i].lambda));
  }
  CHECK(scale > 0.1);  // the supports carry load
  for (size_t b = 0; b < bodiesF.size(); ++b) {
    CAPTURE(b);
    CHECK(bodies2[b].v == bodiesF[b].v);
    CHECK(bodies2[b].w == bodiesF[b].w);
  }
}

TEST_CASE("prepare on rows grouped by region: the serial prepare's bits, the regions on two threads") {
  // PgsSolver::prepare with PrepareGroups (pgs.cpp; the grouped contact row build lays the rows out so):
  // region 0's rows, region 1's, then the rest (boundary contacts, joints), the regions on two threads at once
  // and the rest after them. Every body's warm-start sum must keep the row order of the serial prepare on the
  // same rows, so bodies, rows and block operators must come out bit for bit as the serial prepare's. Scene
  // (as in the partitioned-sweeps test above): boxes 0, 1, 6 in region 0, boxes 2, 3, 5 in region 1, a static
  // ground (body 4) that both regions' rows touch, a boundary manifold between boxes 1 and 2 and a joint-like
  // row between boxes 0 and 3 in the rest, so that boxes 0, 1, 2 and 3 get impulses from a region's rows and
  // from the rest. Every row carries a different warm-start impulse (a sum's order shows in its last bits).
  std::vector<SolverBodyState> bodies(7);
  const Vec3 c[7] = {Vec3(-1.5, 0, 0.5), Vec3(-0.5, 0, 0.5), Vec3(0.5, 0, 0.5), Vec3(1.5, 0, 0.5),
                     Vec3::Zero(),       Vec3(1.5, 0, 1.5),  Vec3(-1.5, 0, 1.5)};
  for (int i : {0, 1, 2, 3, 5, 6}) {
    bodies[size_t(i)].invMass = 0.5 + 0.01 * i;
    bodies[size_t(i)].invInertia = Mat3(Vec3(3.0, 2.0 + 0.1 * i, 2.5).asDiagonal());
    bodies[size_t(i)].v = Vec3(0.01 * i, -0.02, -0.3);
    bodies[size_t(i)].w = Vec3(0.1, -0.03 * i, 0.02);
  }
  std::vector<ConstraintRow> rows;
  auto freeRow = [&](int a, int b) {
    ConstraintRow r;
    r.bodyA = a;
    r.bodyB = b;
    r.jLinA = Vec3(0.3, 1, 0).normalized();
    r.jAngA = Vec3(0, 0.2, 1);
    r.jLinB = -r.jLinA;
    r.jAngB = Vec3(0.1, 0, -1);
    r.e = 1e-4;
    rows.push_back(r);
  };
  addManifold(rows, 0, 4, c[0], c[4], Vec3(-1.5, 0, 0), 0.5, 0.6);
  addManifold(rows, 6, 0, c[6], c[0], Vec3(-1.5, 0, 1.0), 0.45, 0.5);
  addManifold(rows, 1, 4, c[1], c[4], Vec3(-0.5, 0, 0), 0.5, 0.6);
  freeRow(1, -1);
  const uint32_t end0 = uint32_t(rows.size());
  addManifold(rows, 3, 4, c[3], c[4], Vec3(1.5, 0, 0), 0.5, 0.6);
  addManifold(rows, 5, 3, c[5], c[3], Vec3(1.5, 0, 1.0), 0.45, 0.4);
  freeRow(2, 4);
  addManifold(rows, 2, 4, c[2], c[4], Vec3(0.5, 0, 0), 0.5, 0.6);
  const uint32_t end1 = uint32_t(rows.size());
  addManifold(rows, 2, 1, c[2], c[1], Vec3(0, 0, 0.5), 0.3, 0.6);  // the boundary
  freeRow(0, 3);                                                      // a joint's row across the regions
  for (size_t i = 0; i < rows.size(); ++i) rows[i].lambda = 0.5 + 0.037 * Real(i);
  setNumThreads(2);
  const int threads = getNumThreads();
  for (const bool defer : {true, false}) {
    CAPTURE(defer);
    std::vector<ConstraintRow> rowsS = rows, rowsG = rows;
    std::vector<SolverBodyState> bodiesS = bodies, bodiesG = bodies;
    PgsBlocks blocksS, blocksG;
    PgsSolver::prepare(rowsS, bodiesS, &blocksS, defer);
    PgsSolver::PrepareGroups groups;
    groups.rowEnd[0] = end0;
    groups.rowEnd[1] = end1;
    groups.threads = threads;
    bool busy = false;
    groups.teamBusy = &busy;
    PgsSolver::prepare(rowsG, bodiesG, &blocksG, defer, groups);
    CHECK_FALSE(busy);
    CHECK(blocksG.anyDeferred == blocksS.anyDeferred);
    for (size_t b = 0; b < bodies.size(); ++b) {
      CAPTURE(b);
      CHECK(std::memcmp(bodiesS[b].v.data(), bodiesG[b].v.data(), sizeof(Vec3)) == 0);
      CHECK(std::memcmp(bodiesS[b].w.data(), bodiesG[b].w.data(), sizeof(Vec3)) == 0);
    }
    CHECK(bodiesS[0].v != bodies[0].v);  // the warm start moved the bodies
    for (size_t i = 0; i < rows.size(); ++i) {
      CAPTURE(i);
      const ConstraintRow &s = rowsS[i], &g = rowsG[i];
      for (const auto& [a, b] : {std::pair{&s.mJLinA, &g.mJLinA}, {&s.mJAngA, &g.mJAngA}, {&s.mJLinB, &g.mJLinB},
                                 {&s.mJAngB, &g.mJAngB}})
        CHECK(std::memcmp(a->data(), b->data(), sizeof(Vec3)) == 0);
      CHECK(std::memcmp(&s.diag, &g.diag, sizeof(Real)) == 0);
      // A block's slot differs (each region numbers its own), its operators must not.
      REQUIRE((s.blockSlot >= 0) == (g.blockSlot >= 0));
      if (s.blockSlot < 0) continue;
      const PgsBlocks::Block &bs = blocksS.blocks[size_t(s.blockSlot)], &bg = blocksG.blocks[size_t(g.blockSlot)];
      CHECK(bs.rowsReady == bg.rowsReady);
      CHECK(std::memcmp(bs.wAngA, bg.wAngA, sizeof(bs.wAngA)) == 0);
      CHECK(std::memcmp(bs.wLinB, bg.wLinB, sizeof(bs.wLinB)) == 0);
      CHECK(std::memcmp(bs.sInv[0], bg.sInv[0], sizeof(bs.sInv[0])) == 0);
    }
  }
  setNumThreads(1);
}

}  // TEST_SUITE
