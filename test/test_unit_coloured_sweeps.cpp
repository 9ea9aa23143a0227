// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Graph-coloured PGS sweeps (Solver::setUseColouredSweeps, PgsColouring; docs/solver-internals.md "Coloured
// sweeps"): the colouring's invariant on hand-built rows, and pyramid20's trajectory bit-identical on 1 and 2
// threads.
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <chrono>
#include <cstring>
#include <limits>
#include <set>
#include <thread>
#include <vector>

#include "body_state.h"
#include "scenes/scenes.h"
#include "scree/core/parallel.h"
#include "scree/solver/pgs.h"
#include "contact_rows.h"   // solver/src
#include "sweep_threads.h"  // solver/src

using namespace scree;
using namespace scree::detail;

namespace {
/// Whether setNumThreads(2) gives two threads (not when built without OpenMP); leaves the count at one.
bool twoThreadsAvailable() {
  setNumThreads(2);
  const bool two = getNumThreads() == 2;
  setNumThreads(1);
  return two;
}
}  // namespace

TEST_SUITE("coloured sweeps") {

namespace {
// The state compared bit for bit (test/body_state.h): every body's position, velocity, angular velocity and
// rotation.
std::vector<Real> pyramidState(const scenes::PyramidScene& s) { return scree::test::bodyState(*s.sim); }
}  // namespace

TEST_CASE("colouring: no colour holds two units that share a dynamic body; static bodies are shared freely") {
  // Bodies 0-3 dynamic, 4 static (zero inverse mass and inertia). Units of two rows each: four boxes on the
  // static ground and a chain 0-1-2-3 between them (degree 3 for the inner bodies: at least 3 colours).
  std::vector<SolverBodyState> bodies(5);
  for (int i = 0; i < 4; ++i) {
    bodies[size_t(i)].invMass = 1;
    bodies[size_t(i)].invInertia = Mat3::Identity();
  }
  const std::vector<std::pair<int, int>> pairs = {{4, 0}, {4, 1}, {4, 2}, {4, 3}, {0, 1}, {1, 2}, {2, 3}};
  std::vector<ConstraintRow> rows;
  PgsColouring c;
  for (const auto& [a, b] : pairs) {
    c.units.push_back({uint32_t(rows.size()), 2});
    for (int k = 0; k < 2; ++k) {
      ConstraintRow r;
      r.bodyA = a;
      r.bodyB = b;
      rows.push_back(r);
    }
  }
  PgsSolver::colour(rows, bodies, c);
  REQUIRE(c.sorted.size() == pairs.size());
  CHECK_FALSE(c.lastGroupSerial);
  const size_t colours = c.colourStart.size() - 1;
  // Greedy in unit order: the four ground units share only the static body (colour 0), then 0-1 takes colour 1,
  // 1-2 colour 2, 2-3 colour 1 again.
  CHECK(colours == 3);
  std::set<std::pair<uint32_t, uint32_t>> seen;
  for (size_t k = 0; k < colours; ++k) {
    std::set<int> dyn;
    for (uint32_t u = c.colourStart[k]; u < c.colourStart[k + 1]; ++u) {
      const auto& un = c.sorted[u];
      seen.insert({un.begin, un.count});
      for (int b : {rows[un.begin].bodyA, rows[un.begin].bodyB}) {
        if (b == 4) continue;
        CHECK_MESSAGE(dyn.insert(b).second, "colour " << k << " holds body " << b << " twice");
      }
    }
  }
  CHECK(seen.size() == pairs.size());  // every unit exactly once
}

TEST_CASE("coloured sweeps: pyramid20 is bit-identical on 1 and 2 threads and stands") {
  auto run = [](int threads) {
    setNumThreads(threads);
    scenes::PyramidScene s = scenes::buildPyramid20();
    s.sim->getSolver().setUseColouredSweeps(true);
    for (int i = 0; i < s.numSteps; ++i) s.step();
    setNumThreads(1);
    return std::make_pair(pyramidState(s), scenes::measurePyramid(s));
  };
  const auto [one, m1] = run(1);
  const bool twoThreads = twoThreadsAvailable();  // false without OpenMP: the check below is then trivial
  const auto [two, m2] = run(2);
  WARN_MESSAGE(twoThreads, "built without OpenMP: the 2-thread run used one thread");
  REQUIRE(one.size() == two.size());
  // Bit for bit: the units of one colour touch disjoint dynamic bodies, so the thread count cannot change the
  // result (a single ulp anywhere in 600 steps of 210 boxes would show here).
  CHECK(std::memcmp(one.data(), two.data(), one.size() * sizeof(Real)) == 0);
  // The scene's accuracy goal (issue 18: pyramid20 at 10 iterations stands with drift under 1 cm) also holds in
  // the coloured order.
  CHECK(m1.finite);
  CHECK(m1.stands);
  CHECK(m1.maxDisplacement < 0.01);
}

// ---- issue 18 (sweep scheduling): partitioned sweeps (Solver::setUsePartitionedSweeps, PgsPartition) ----
TEST_CASE("partition: regions share no dynamic body, the boundary touches both, the work is halved") {
  // Bodies 0-7 dynamic in a row along x (y scrambled, so that a cut along y would cross many contacts), body 8
  // static. Units: each box on the static ground (2 rows), and a contact between neighbours (3 rows).
  const int n = 8;
  std::vector<SolverBodyState> bodies(n + 1);
  PgsPartition p;
  p.bodyPosition.resize(n + 1, Vec3::Zero());
  const Real ys[n] = {0.3, -0.2, 0.5, 0.1, -0.4, 0.2, -0.1, 0.4};
  for (int i = 0; i < n; ++i) {
    bodies[size_t(i)].invMass = 1;
    bodies[size_t(i)].invInertia = Mat3::Identity();
    p.bodyPosition[size_t(i)] = Vec3(Real(i), ys[i], 0);
  }
  std::vector<ConstraintRow> rows;
  auto addUnit = [&](int a, int b, int count) {
    p.units.push_back({uint32_t(rows.size()), uint32_t(count)});
    for (int k = 0; k < count; ++k) {
      ConstraintRow r;
      r.bodyA = a;
      r.bodyB = b;
      rows.push_back(r);
    }
  };
  for (int i = 0; i < n; ++i) addUnit(n, i, 2);
  for (int i = 0; i + 1 < n; ++i) addUnit(i, i + 1, 3);
  PgsSolver::partition(rows, bodies, p);
  CHECK(p.axis == 0);  // x: one contact crosses the cut (y: several)
  constexpr int R = PgsPartition::kRegions;
  REQUIRE(p.split[R + 1] == p.units.size());
  REQUIRE(p.order.size() == p.units.size());
  // Every body's weight is 2 + 3 (or 2 + 1.5 at the ends): the weighted median cuts between bodies 3 and 4.
  for (int i = 0; i < n; ++i) CHECK(p.bodyRegion[size_t(i)] == (i < 4 ? 0 : 1));
  CHECK(p.bodyRegion[size_t(n)] == -1);  // static: no region
  // Region 0: ground units of 0-3 and contacts 0-1, 1-2, 2-3 (7 units); region 1 likewise; the boundary 3-4.
  CHECK(p.split[1] - p.split[0] == 7);
  CHECK(p.split[2] - p.split[1] == 7);
  CHECK(p.split[3] - p.split[2] == 1);
  std::set<uint32_t> seen;
  for (int g = 0; g <= R; ++g)
    for (uint32_t u = p.split[g]; u < p.split[g + 1]; ++u) {
      const auto& un = p.order[u];
      seen.insert(un.begin);
      std::set<int> regions;
      for (int b : {rows[un.begin].bodyA, rows[un.begin].bodyB})
        if (b != n) regions.insert(p.bodyRegion[size_t(b)]);
      if (g < R) CHECK((regions.size() == 1 && *regions.begin() == g));
      else CHECK(regions.size() == 2);
      if (u > p.split[g]) CHECK(p.order[u - 1].begin < un.begin);  // the serial order kept within a group
    }
  CHECK(seen.size() == p.units.size());
}

TEST_CASE("parallel shock pass schedule: each range waits for its frozen body's writer, only awaited ends publish") {
  // Bodies 0-3 in region 0, 4-7 in region 1, body 8 static (no region, and no range writes it: resting on it never
  // waits).
  // The ranges (free body, frozen body) in support order; three of them rest on a body of the other region.
  PgsPartition p;
  p.bodyRegion = {0, 0, 0, 0, 1, 1, 1, 1, -1};
  const std::pair<int, int> supports[] = {{0, 8}, {4, 8}, {1, 0}, {5, 4}, {2, 5}, {6, 1}, {3, 2}, {7, 6}, {3, 6}};
  std::vector<PgsSolver::ShockRange> ranges;
  for (const auto& [freeB, frozenB] : supports) ranges.push_back({0, 0, 1, freeB, frozenB});
  PgsSolver::shockSchedule(ranges, 9, p);
  // List 0 runs ranges 0, 2, 4, 6, 8. Range 4 rests on body 5, whose last writer before it is list 1's second
  // range (range 3), so it waits for a count of 2; range 8 rests on body 6, written by list 1's third (range 5).
  CHECK(p.shockList[0] == std::vector<uint32_t>{0, 2, 4, 6, 8});
  CHECK(p.shockWait[0] == std::vector<uint32_t>{0, 0, 2, 0, 3});
  // List 1 runs ranges 1, 3, 5, 7; range 5 rests on body 1, written by list 0's second (range 2). Range 7 rests on
  // body 6 of its own list: no wait.
  CHECK(p.shockList[1] == std::vector<uint32_t>{1, 3, 5, 7});
  CHECK(p.shockWait[1] == std::vector<uint32_t>{0, 0, 2, 0});
  // Only the ends that are waited for publish their count: list 0's second range, list 1's second and third.
  CHECK(p.shockPublish[0] == std::vector<uint8_t>{0, 1, 0, 0, 0});
  CHECK(p.shockPublish[1] == std::vector<uint8_t>{0, 1, 1, 0});
  // Rebuilt from scratch on the next call (no flag left from the last one).
  const std::vector<PgsSolver::ShockRange> inside = {{0, 0, 1, 0, 8}, {0, 0, 1, 4, 8}, {0, 0, 1, 1, 0}};
  PgsSolver::shockSchedule(inside, 9, p);
  CHECK(p.shockPublish[0] == std::vector<uint8_t>{0, 0});
  CHECK(p.shockPublish[1] == std::vector<uint8_t>{0});
}

namespace {
/// pyramid20's state (positions, velocities, angular velocities, the top's rotation) after `steps` steps (0: the
/// scene's 600) with partitioned sweeps on `threads` threads.
// Adaptive thread count off: the 2-thread run must really run on two threads (with it on, the count would follow
// the host's timing; the bits would not change, but the comparison would test less).
// rowThreads (if given): the fewest threads the contact rows were built on over the steps.
std::pair<std::vector<Real>, scenes::PyramidMetrics> runPartitioned(int threads, bool shock, int steps,
                                                                    int* rowThreads = nullptr, int iterations = 0) {
  setNumThreads(threads);
  scenes::PyramidScene s = scenes::buildPyramid20();
  if (iterations > 0) s.sim->getSolver().setNumIterations(iterations);
  s.sim->getSolver().setUsePartitionedSweeps(true);
  s.sim->getSolver().setUseAdaptiveSweepThreads(false);
  s.sim->getSolver().setUseShockPropagation(shock);
  if (rowThreads) *rowThreads = threads;
  for (int i = 0; i < (steps > 0 ? steps : s.numSteps); ++i) {
    s.step();
    // From the second step: the first has no region map yet, and builds its rows in contact order on one thread.
    if (rowThreads && i > 0)
      *rowThreads = std::min(*rowThreads, s.sim->getSolver().getStats().numRowBuildThreads);
  }
  setNumThreads(1);
  return {pyramidState(s), scenes::measurePyramid(s)};
}
}  // namespace

TEST_CASE("partitioned sweeps: pyramid20 is bit-identical on 1 and 2 threads, with and without the shock pass") {
  const bool twoThreads = twoThreadsAvailable();  // false without OpenMP: the check below is then trivial
  WARN_MESSAGE(twoThreads, "built without OpenMP: the 2-thread run used one thread");
  for (const bool shock : {true, false}) {
    CAPTURE(shock);
    // Without the shock pass 150 steps (2.5 s) suffice to compare bits (the 2-thread runs are slow on a loaded
    // machine; docs/solver-internals.md "Partitioned sweeps").
    const int steps = shock ? 0 : 150;
    int rowsOne = 0, rowsTwo = 0;
    const auto [one, m1] = runPartitioned(1, shock, steps, &rowsOne);
    const auto [two, m2] = runPartitioned(2, shock, steps, &rowsTwo);
    REQUIRE(one.size() == two.size());
    // The contact rows too were built (and prepared) on two threads in every step but the first of the 2-thread
    // run (pyramid20 has about 400 contacts, above the build's threshold of 128), and on one in the 1-thread run:
    // the bits below then also check that each region's rows, built and prepared on its own thread, are the
    // one-thread run's (contact_rows.cpp, pgs.cpp PgsSolver::prepare with PrepareGroups).
    CHECK(rowsOne == 1);
    if (twoThreads) CHECK(rowsTwo == 2);
    // Bit for bit: the two regions touch disjoint dynamic bodies (sweeps), and each shock range waits for the
    // writers of its frozen body (shock pass), so the thread count cannot change the result.
    CHECK(std::memcmp(one.data(), two.data(), one.size() * sizeof(Real)) == 0);
    CHECK(m1.finite);
    // With the shock pass: the accuracy goal for pyramid20 at 10 iterations (drift under 1 cm) holds in
    // the partitioned order too (measured 0.0081 cm; serial 0.0049 cm). Without it the pyramid leans whatever
    // the order (docs/solver-internals.md "pyramid20 without the shock pass"); only the bits are compared.
    if (shock) {
      CHECK(m1.stands);
      CHECK(m1.maxDisplacement < 0.01);
    }
  }
  // An odd count of sweeps: the last one is forward and ends with the boundary, which moves the regions' bodies in
  // the sweeps' local layout after the regions are done. Each thread writes its region's bodies back only after
  // that (pgs.cpp PgsSolver::iterate, the take-down's barrier); written earlier, the boundary's last impulses
  // would be lost on two threads only (a data race too: CI stage f runs this case under ThreadSanitizer).
  const auto [oddOne, o1] = runPartitioned(1, false, 60, nullptr, 9);
  const auto [oddTwo, o2] = runPartitioned(2, false, 60, nullptr, 9);
  REQUIRE(oddOne.size() == oddTwo.size());
  CHECK(std::memcmp(oddOne.data(), oddTwo.data(), oddOne.size() * sizeof(Real)) == 0);
  CHECK(o1.finite);
}

TEST_CASE("contact rows built on two threads: the serial build's bits for every kind of contact row") {
  // The row build of the partitioned path (contact_rows.cpp) groups the contacts by region, counts each region's
  // rows on its thread, places them, then fills them. Its count must agree with the fill for every row layout, not
  // only pyramid20's manifold friction. A 12-row pyramid (78 boxes) beside a row of 48 spheres on the ground, in
  // four variants: the default (box manifolds with manifold friction and single sphere points), rolling
  // resistance (per-point friction and rolling rows), the box friction model (per-point box friction), and
  // friction anchors (Solver::setUseFrictionAnchors: each group lists its anchored manifolds, joined in row
  // order). 90 steps: the spheres fall 1.7 m and land at about step 35 (0.59 s at 60 Hz), and for the rest the
  // contacts' warm starts and anchors are in use.
  //
  // Variant 4: the two-thread build fills on last step's layout when the contacts are the same pairs as last
  // step's (contact_rows.cpp, stop 50), and must notice a contact whose rows changed in number. A listener
  // switches, every third step, the first point of some contacts off (fewer normal rows), and, every fifth, some
  // whole contacts off (no rows) -- both keep the pair in the list, so the layout is guessed and found wrong on
  // the steps where the switching starts or stops. Which contacts: by the decimetre of their first body's x
  // (geometry ids differ between the two runs; the states do not).
  const bool twoThreads = twoThreadsAvailable();
  struct Switcher : ContactEventListener {
    const int* step = nullptr;
    KeepContactPolicy contact(const TimeStamp&, GeometryContact& c) override {
      const RigidBody* b = c.rigidBody(0) ? c.rigidBody(0) : c.rigidBody(1);
      const long slot = b ? long(std::floor(b->getPosition().x() * 10)) : 0;
      if (*step % 3 == 1 && slot % 2 == 0 && c.points().size() > 1) c.points()[0].enabled = false;
      if (*step % 5 == 2 && slot % 7 == 0) c.setEnable(false);
      return KEEP_CONTACT;
    }
  };
  for (int variant = 0; variant < 5; ++variant) {
    CAPTURE(variant);
    auto run = [variant](int threads, int& rowThreads, size_t& contacts) {
      setNumThreads(threads);
      scenes::PyramidScene s = scenes::buildPyramid(12);
      int step = 0;
      if (variant == 4) {
        auto l = std::make_shared<Switcher>();
        l->step = &step;
        s.sim->add(l);
      }
      for (int i = 0; i < 48; ++i) {
        auto geom = std::make_shared<Geometry>(std::make_shared<Sphere>(0.3));
        geom->setMaterial(s.material);
        auto body = std::make_shared<RigidBody>();
        body->add(geom);
        body->setMass(2.0);
        body->setPosition(Vec3(-8.0 + 0.7 * (i % 24), 3.0 + 1.5 * (i / 24), 2.0 + 0.01 * i));
        s.sim->add(body);
      }
      if (variant == 1) s.contactMaterial->setRollingResistanceCoefficient(0.05);
      if (variant == 2) s.contactMaterial->setFrictionModel(std::make_shared<BoxFrictionModel>());
      if (variant == 3) s.sim->getSolver().setUseFrictionAnchors(true);
      s.sim->getSolver().setUsePartitionedSweeps(true);
      s.sim->getSolver().setUseAdaptiveSweepThreads(false);
      rowThreads = threads;
      for (int i = 0; i < 90; ++i, ++step) {
        s.step();
        if (i >= 30) rowThreads = std::min(rowThreads, s.sim->getSolver().getStats().numRowBuildThreads);
      }
      contacts = s.sim->getContacts().size();
      setNumThreads(1);
      return scree::test::bodyState(*s.sim);
    };
    int rowsOne = 0, rowsTwo = 0;
    size_t contactsOne = 0, contactsTwo = 0;
    const std::vector<Real> one = run(1, rowsOne, contactsOne);
    const std::vector<Real> two = run(2, rowsTwo, contactsTwo);
    CHECK(contactsOne >= 128);  // the build's threshold for a second thread
    CHECK(contactsOne == contactsTwo);
    CHECK(rowsOne == 1);
    if (twoThreads) CHECK(rowsTwo == 2);
    REQUIRE(one.size() == two.size());
    CHECK(std::memcmp(one.data(), two.data(), one.size() * sizeof(Real)) == 0);
  }
}

// ---- issue 18: the partitioned sweeps' thread count by measurement (solver/src/sweep_threads.h) ----
TEST_CASE("sweep thread choice: probe schedule, the faster count wins, ties go to one thread, holds double") {
  using C = SweepThreadChoice;
  constexpr int P = C::kProbeSteps;
  // One probe with times t2 per step on two threads and t1 on one; every step's count is checked against the
  // schedule (P steps on 2, P on 1). The settling steps get an outlier that must not count.
  // Steps' times spread by `spread` (s) per step, upwards on two threads and downwards on one.
  auto probe = [](C& c, double t2, double t1, double spread = 1e-6) {
    for (int k = 0; k < P; ++k) {
      REQUIRE(c.begin(2) == 2);
      REQUIRE(c.probing());
      c.end(k < C::kSettleSteps ? 1.0 : t2 + spread * k);
    }
    for (int k = 0; k < P; ++k) {
      REQUIRE(c.begin(2) == 1);
      c.end(k < C::kSettleSteps ? 1.0 : t1 - spread * k);
    }
  };
  auto holdFor = [](C& c, int steps, int count) {
    for (int k = 0; k < steps; ++k) {
      REQUIRE(c.begin(2) == count);
      REQUIRE_FALSE(c.probing());
      c.end(1.0);  // times during a hold do not matter
    }
  };
  SUBCASE("two threads faster: kept, and each confirming probe doubles the hold up to its cap") {
    C c;
    CHECK(c.chosen() == 0);
    probe(c, 0.4e-3, 0.6e-3);
    CHECK(c.chosen() == 2);
    CHECK(c.hold() == C::kFirstHold);
    // Medians of the timed steps only (the settling steps' 1 s is left out): steps 2..7, the mean of steps 4
    // and 5.
    CHECK(std::abs(c.medianMany() - (0.4e-3 + 4.5e-6)) < 1e-15);
    CHECK(std::abs(c.medianOne() - (0.6e-3 - 4.5e-6)) < 1e-15);
    int hold = C::kFirstHold;
    for (int round = 0; round < 8; ++round) {
      holdFor(c, hold, 2);
      probe(c, 0.4e-3, 0.6e-3);
      hold = std::min(2 * hold, C::kMaxHold);
      CHECK(c.hold() == hold);
    }
    CHECK(c.hold() == C::kMaxHold);
  }
  SUBCASE("one thread faster: chosen; a later probe that finds two faster switches back and resets the hold") {
    C c;
    probe(c, 0.65e-3, 0.43e-3);
    CHECK(c.chosen() == 1);
    holdFor(c, C::kFirstHold, 1);
    probe(c, 0.65e-3, 0.43e-3);
    CHECK(c.hold() == 2 * C::kFirstHold);
    holdFor(c, 2 * C::kFirstHold, 1);
    probe(c, 0.30e-3, 0.43e-3);  // the host got faster between the cores
    CHECK(c.chosen() == 2);
    CHECK(c.hold() == C::kFirstHold);
    holdFor(c, C::kFirstHold, 2);
  }
  SUBCASE("steps that asked for the team and did not get it count as infinitely slow") {
    // endPartitionedWork passes +infinity for them (another Simulation held the team). Two of the six timed
    // steps without the team: the median is still the other steps', and two threads, faster, win. Three of six:
    // the median is infinite and one thread wins, though every step that got the team was faster.
    for (const int busy : {2, 3}) {
      CAPTURE(busy);
      C c;
      for (int k = 0; k < P; ++k) {
        REQUIRE(c.begin(2) == 2);
        const int timed = k - C::kSettleSteps;
        c.end(timed >= 0 && timed < busy ? std::numeric_limits<double>::infinity() : 0.3e-3);
      }
      for (int k = 0; k < P; ++k) {
        REQUIRE(c.begin(2) == 1);
        c.end(0.6e-3);
      }
      CHECK(c.chosen() == (busy == 2 ? 2 : 1));
      CHECK(c.medianOne() == 0.6e-3);
      if (busy == 2) CHECK(c.medianMany() == 0.3e-3);
      else CHECK(std::isinf(c.medianMany()));
    }
  }
  SUBCASE("a tie goes to one thread") {
    C c;
    probe(c, 0.5e-3, 0.5e-3, 0.0);
    CHECK(c.medianOne() == c.medianMany());
    CHECK(c.chosen() == 1);
  }
  SUBCASE("one available thread: no probe, always one; a change of the available count starts a new probe") {
    C c;
    for (int k = 0; k < 50; ++k) {
      CHECK(c.begin(1) == 1);
      CHECK_FALSE(c.probing());
      c.end(1.0);
    }
    probe(c, 0.4e-3, 0.6e-3);
    CHECK(c.chosen() == 2);
    CHECK(c.begin(1) == 1);
    c.end(1.0);
    CHECK(c.begin(2) == 2);  // back to two: probing from the start
    CHECK(c.probing());
  }
}

TEST_CASE("partitioned sweeps with the adaptive thread count: the probe schedule, and the bits of one thread") {
  // pyramid20 on two threads with Solver::setUseAdaptiveSweepThreads (the default): the first kProbeSteps steps
  // run on two threads and the next kProbeSteps on one, then the faster count (host-dependent) for the hold.
  // Whatever the counts, the state after 40 steps must be the one-thread run's, bit for bit.
  const bool twoThreads = twoThreadsAvailable();
  if (!twoThreads) {
    WARN_MESSAGE(false, "built without OpenMP: no second thread to choose");
    return;
  }
  constexpr int steps = 40, P = SweepThreadChoice::kProbeSteps;
  const auto [one, m1] = runPartitioned(1, true, steps);
  setNumThreads(2);
  scenes::PyramidScene s = scenes::buildPyramid20();
  REQUIRE(s.sim->getSolver().getUseAdaptiveSweepThreads());
  s.sim->getSolver().setUsePartitionedSweeps(true);
  std::vector<int> counts;
  for (int i = 0; i < steps; ++i) {
    s.step();
    counts.push_back(s.sim->getSolver().getStats().numSweepThreads);
  }
  setNumThreads(1);
  for (int i = 0; i < steps; ++i) {
    CAPTURE(i);
    if (i < P) CHECK(counts[size_t(i)] == 2);
    else if (i < 2 * P) CHECK(counts[size_t(i)] == 1);
    else CHECK(counts[size_t(i)] == counts[size_t(2 * P)]);  // the hold (120 steps) outlasts the run
  }
  MESSAGE("pyramid20 partitioned, adaptive: chose " << counts.back() << " thread(s) on this host");
  const std::vector<Real> two = pyramidState(s);
  REQUIRE(one.size() == two.size());
  CHECK(std::memcmp(one.data(), two.data(), one.size() * sizeof(Real)) == 0);
  // The default serial path reports one thread.
  scenes::PyramidScene d = scenes::buildPyramid20();
  d.step();
  CHECK(d.sim->getSolver().getStats().numSweepThreads == 1);
}

TEST_CASE("partitioned work that finds the team busy: the stats report the one thread it ran on, the bits hold") {
  // A step taken inside a team job finds the team in use, as one Simulation's step does while another's holds
  // the team (scree/core/parallel.h runTeamJob): the row build's, the sweeps' and the shock pass's jobs then run
  // on the calling thread alone. SolverStats must report the threads that ran, not those asked for, and the
  // state must stay the one-thread run's. pyramid20 (about 400 contacts: rows, sweeps and shock pass all ask
  // for two threads), the count fixed at two; steps 0-9 inside a job, 10-19 outside it, 20-29 inside again.
  const bool twoThreads = twoThreadsAvailable();
  if (!twoThreads) {
    WARN_MESSAGE(false, "built without OpenMP: no team to find busy");
    return;
  }
  constexpr int steps = 30;
  const auto [one, m1] = runPartitioned(1, true, steps);
  setNumThreads(2);
  scenes::PyramidScene s = scenes::buildPyramid20();
  s.sim->getSolver().setUsePartitionedSweeps(true);
  s.sim->getSolver().setUseAdaptiveSweepThreads(false);
  std::vector<int> rowThreads, sweepThreads;
  for (int i = 0; i < steps; ++i) {
    const bool inside = i < 10 || i >= 20;
    if (inside) runTeam(2, [&](int t, int) {
        if (t == 0) s.step();
      });
    else s.step();
    rowThreads.push_back(s.sim->getSolver().getStats().numRowBuildThreads);
    sweepThreads.push_back(s.sim->getSolver().getStats().numSweepThreads);
  }
  setNumThreads(1);
  for (int i = 0; i < steps; ++i) {
    CAPTURE(i);
    const int expected = i < 10 || i >= 20 ? 1 : 2;
    CHECK(rowThreads[size_t(i)] == expected);
    CHECK(sweepThreads[size_t(i)] == expected);
  }
  const std::vector<Real> mixed = pyramidState(s);
  REQUIRE(one.size() == mixed.size());
  CHECK(std::memcmp(one.data(), mixed.data(), one.size() * sizeof(Real)) == 0);
}

TEST_CASE("partitioned work too small to split: the stats report the one thread the sweeps ran on") {
  // The sweeps split only from 64 units and the shock pass from 16 ranges (pgs.cpp partitionThreads); below that
  // they run on the calling thread whatever the count asked for. tower10 (10 contacts, 10 shock ranges) asks
  // for two threads and runs on one: SolverStats::numSweepThreads must say one. pyramid20 (about 400 units) runs
  // on two and must say two. Adaptive count off, so that two threads are asked for on every step.
  const bool twoThreads = twoThreadsAvailable();
  if (!twoThreads) {
    WARN_MESSAGE(false, "built without OpenMP: no second thread to ask for");
    return;
  }
  setNumThreads(2);
  scenes::TowerScene tower = scenes::buildTower10();
  scenes::PyramidScene pyramid = scenes::buildPyramid20();
  for (Simulation* sim : {tower.sim.get(), pyramid.sim.get()}) {
    sim->getSolver().setUsePartitionedSweeps(true);
    sim->getSolver().setUseAdaptiveSweepThreads(false);
  }
  std::vector<int> towerThreads, pyramidThreads;
  for (int i = 0; i < 5; ++i) {
    tower.step();
    pyramid.step();
    towerThreads.push_back(tower.sim->getSolver().getStats().numSweepThreads);
    pyramidThreads.push_back(pyramid.sim->getSolver().getStats().numSweepThreads);
  }
  setNumThreads(1);
  for (size_t i = 0; i < towerThreads.size(); ++i) {
    CAPTURE(i);
    CHECK(towerThreads[i] == 1);
    CHECK(pyramidThreads[i] == 2);
  }
}

TEST_CASE("adaptive sweep threads: a probe whose two-thread steps find the team busy keeps one thread") {
  // The +infinity samples of SweepThreadChoice::end, end to end. pyramid20 partitioned, the adaptive count on (the
  // default), two threads. The probe's first kProbeSteps steps ask for two threads; they are taken inside a team
  // job, so the team is busy, they run on one thread and must be timed as +infinity. The next kProbeSteps ask
  // for one and run outside it with 10x the sweeps (100 against 10), so each takes several times as long
  // as a busy step. The choice must then be one thread: had the busy steps been timed as two threads' steps,
  // two threads would have won by that factor, and the hold after the probe would report two. The state must
  // also be the one-thread run's, bit for bit, under the same schedule of sweep counts.
  const bool twoThreads = twoThreadsAvailable();
  if (!twoThreads) {
    WARN_MESSAGE(false, "built without OpenMP: no second thread to choose");
    return;
  }
  constexpr int P = SweepThreadChoice::kProbeSteps, steps = 2 * P + 6;
  auto run = [&](int threads, std::vector<int>* counts) {
    setNumThreads(threads);
    scenes::PyramidScene s = scenes::buildPyramid20();
    Solver& solver = s.sim->getSolver();
    REQUIRE(solver.getUseAdaptiveSweepThreads());
    solver.setUsePartitionedSweeps(true);
    const int iterations = solver.getNumIterations();
    for (int i = 0; i < steps; ++i) {
      solver.setNumIterations(i >= P && i < 2 * P ? 10 * iterations : iterations);
      if (i < P) runTeam(2, [&](int t, int) {
          if (t == 0) s.step();
        });
      else s.step();
      if (counts) counts->push_back(solver.getStats().numSweepThreads);
    }
    setNumThreads(1);
    return pyramidState(s);
  };
  const std::vector<Real> one = run(1, nullptr);
  std::vector<int> counts;
  const std::vector<Real> adaptive = run(2, &counts);
  for (int i = 0; i < steps; ++i) {
    CAPTURE(i);
    CHECK(counts[size_t(i)] == 1);  // busy, then the probe of one, then the hold on one
  }
  REQUIRE(one.size() == adaptive.size());
  CHECK(std::memcmp(one.data(), adaptive.data(), one.size() * sizeof(Real)) == 0);
}

// ---- issue 18 (sweep scheduling): the persistent team the partitioned stages run on (scree/core/parallel.h) ----
TEST_CASE("persistent team: every index once on its own thread, barrier order, nested and concurrent calls") {
  // Two indices, two distinct threads, t = 0 on the caller; repeated so that the sleeping worker is woken too.
  for (int rep = 0; rep < 50; ++rep) {
    std::thread::id who[2];
    int seenN[2] = {0, 0}, runs[2] = {0, 0};
    detail::runTeam(2, [&](int t, int n) {
      who[t] = std::this_thread::get_id();
      seenN[t] = n;
      ++runs[t];
    });
    REQUIRE(runs[0] == 1);
    REQUIRE(runs[1] == 1);
    CHECK(seenN[0] == 2);
    CHECK(who[0] == std::this_thread::get_id());
    CHECK(who[1] != who[0]);
    if (rep == 25) std::this_thread::sleep_for(std::chrono::milliseconds(5));  // the worker sleeps on its futex
  }
  // The barrier orders phases: after barrier k, each thread sees the other's write of phase k (a missing or early
  // release shows up as a stale value on some phase).
  constexpr int kPhases = 2000;
  std::vector<int> a(kPhases, -1), b(kPhases, -1);
  int stale = 0;
  detail::TeamBarrier barrier(2);
  detail::runTeam(2, [&](int t, int n) {
    if (n < 2) return;
    std::vector<int>& mine = t == 0 ? a : b;
    const std::vector<int>& theirs = t == 0 ? b : a;
    int bad = 0;
    for (int k = 0; k < kPhases; ++k) {
      mine[size_t(k)] = k;
      barrier.wait();
      bad += theirs[size_t(k)] != k;
      barrier.wait();
    }
    if (t == 1) stale = bad;  // read after the join
  });
  CHECK(stale == 0);
  CHECK(a.back() == kPhases - 1);
  CHECK(b.back() == kPhases - 1);
  // A job that calls the team again runs the inner job on its own thread with n = 1 (no deadlock); a second user
  // thread that finds the team busy does the same. Both give the whole job's work once.
  int inner[2] = {0, 0};
  detail::runTeam(2, [&](int t, int) {
    detail::runTeam(2, [&](int u, int n) { inner[t] += (u == 0 && n == 1) ? 1 : 100; });
  });
  CHECK(inner[0] == 1);
  CHECK(inner[1] == 1);
  std::atomic<int> total{0};
  auto user = [&] {
    for (int k = 0; k < 200; ++k)
      detail::runTeam(2, [&](int t, int n) { total.fetch_add(n == 2 ? 1 : (t == 0 ? 2 : 1000)); });
  };
  std::thread other(user);
  user();
  other.join();
  CHECK(total.load() == 800);  // every call's work done exactly once: 2 x 1 with the team, 1 x 2 without
}

TEST_CASE("chunks shared from both ends: each chunk once, thread 0 a prefix, thread 1 the rest") {
  // contact_rows.h forChunksFromBothEnds (the grouped row build and store): every chunk must run exactly once,
  // thread 0's chunks must be a prefix in ascending order and thread 1's the remaining suffix in descending
  // order, on two threads, on one, and with the team busy; the thread that is ahead takes over the other's
  // chunks (one thread is slowed down by 0.5 ms a chunk, so the other must run more than half of them).
  struct Case {
    int slow, threads;
    bool busy;
  };
  const Case cases[] = {{1, 1, false}, {1, 1, true}, {1, 2, false}, {1, 2, true}, {0, 2, false}};
  for (const uint32_t numChunks : {0u, 1u, 2u, 7u, 40u}) {
    for (const auto& [slow, threads, busy] : cases) {
      CAPTURE(numChunks);
      CAPTURE(slow);
      CAPTURE(threads);
      CAPTURE(busy);
      std::vector<int> runs(numChunks, 0);
      std::vector<uint32_t> order[2];
      std::thread::id caller = std::this_thread::get_id();
      int ran = 0;
      auto body = [&] {
        ran = forChunksFromBothEnds(threads, numChunks, [&](uint32_t c) {
          const int t = std::this_thread::get_id() == caller ? 0 : 1;
          if (t == slow) std::this_thread::sleep_for(std::chrono::microseconds(500));
          ++runs[c];
          order[t].push_back(c);
        });
      };
      if (busy) runTeam(2, [&](int t, int) {
          if (t == 0) body();
        });
      else body();
      CHECK(ran == (busy ? 1 : threads));
      for (uint32_t c = 0; c < numChunks; ++c) CHECK(runs[c] == 1);
      const size_t front = order[0].size();
      for (size_t i = 0; i < front; ++i) CHECK(order[0][i] == i);
      for (size_t i = 0; i < order[1].size(); ++i) CHECK(order[1][i] == numChunks - 1 - i);
      CHECK(front + order[1].size() == numChunks);
      if (ran == 1) CHECK(order[1].empty());
      if (ran == 2 && numChunks == 40) CHECK((slow == 1 ? front : order[1].size()) > 20);
    }
  }
}

TEST_CASE("persistent team: a lost wake-up costs at most the sleep bound, not a hang") {
  // bench_rigid_stages BM_team_barrier hung in 3 of 13 runs in a KVM guest: a thread asleep on the barrier's
  // phase was never woken after the phase changed (core/src/parallel.cpp, sleepWhile). Every sleep is now bounded
  // (1 ms inside a step). The test makes the lost wake-up certain: the value is stored with no wake at all, after
  // the waiter has spun out and gone to sleep (50 ms later; its spin is teamSpinTime() = 50 us and 4 yields).
  // Without the bound the waiter sleeps for ever and ctest's timeout fails the test; with it, the waiter returns
  // after the store.
  // (The wait's length is not asserted: timing on a shared machine is the bench's business.)
  std::atomic<uint32_t> value{0};
  std::atomic<bool> returned{false};
  std::thread waiter([&] {
    detail::waitAtLeast(value, 1);
    returned.store(true);
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  CHECK_FALSE(returned.load());  // the waiter waits while the value is short of its target
  value.store(1, std::memory_order_release);  // deliberately no publish: no wake-up is sent
  waiter.join();
  CHECK(returned.load());
  // And the normal path: a waiter asleep on a value that publish() changes returns.
  std::atomic<uint32_t> flag{0};
  std::thread sleeper([&] { detail::waitAtLeast(flag, 3); });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  detail::publish(flag, 3);
  sleeper.join();
  CHECK(flag.load() == 3);
}

}  // TEST_SUITE
