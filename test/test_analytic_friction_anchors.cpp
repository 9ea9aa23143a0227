// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Friction anchors (Solver::setUseFrictionAnchors; solver/src/friction_anchor.h, docs/solver-internals.md
// "Friction anchors"). What they must do: pull back the tangential creep that velocity-level friction lets
// accumulate in a sticking contact (pyramid20 without the shock pass, a cube sticking on an incline), leave
// sliding contacts exactly as they were (slide, incline mu 0.5), and add no energy.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "test_world.h"

using namespace scree;
using namespace scree::scenes;

namespace {

Real kineticEnergy(const std::vector<RigidBodyRef>& boxes) {
  Real e = 0;
  for (const RigidBodyRef& b : boxes)
    e += 0.5 * b->getMass() * b->getVelocity().squaredNorm() +
         0.5 * b->getAngularVelocity().dot(b->getInertiaTensor() * b->getAngularVelocity());
  return e;
}

struct PyramidRun {
  Real maxDisplacement = 0;  ///< m, every box, at 10 s
  Real lowerDisplacement = 0;  ///< m, the boxes of rows 0..13 (all but the top 6 rows), at 10 s
  Real meanKinetic = 0;      ///< J, mean over the last 5 s
  bool finite = true;
};

/// seed 0: the reference scene as built; seed k > 0: every box moved along x by a pseudo-random amount within
/// +-0.5 nm (a roundoff-sized perturbation; the metrics below are in cm and J).
PyramidRun runPyramidNoShock(bool anchors, int seed = 0) {
  PyramidScene s = buildPyramid20();
  s.sim->getSolver().setUseShockPropagation(false);
  s.sim->getSolver().setUseFrictionAnchors(anchors);
  uint64_t state = uint64_t(seed);
  if (seed > 0)
    for (const RigidBodyRef& b : s.boxes)
      b->setPosition(b->getPosition() + Vec3(0.5e-9 * splitmixSymmetric(state), 0, 0));
  PyramidRun r;
  int n = 0;
  for (int k = 0; k < s.numSteps; ++k) {
    s.step();
    if (k >= s.numSteps / 2) {
      r.meanKinetic += kineticEnergy(s.boxes);
      ++n;
    }
  }
  r.meanKinetic /= n;
  const PyramidMetrics m = measurePyramid(s);
  r.maxDisplacement = m.maxDisplacement;
  r.finite = m.finite;
  // Rows 0..13 hold 20 + 19 + ... + 7 boxes.
  size_t lower = 0;
  for (int row = 0; row < 14; ++row) lower += size_t(20 - row);
  for (size_t i = 0; i < lower; ++i)
    r.lowerDisplacement = std::max(r.lowerDisplacement, (s.boxes[i]->getPosition() - s.initialPositions[i]).norm());
  return r;
}

}  // namespace

TEST_SUITE("solver") {

TEST_CASE("friction anchors: pyramid20 without the shock pass leans far less at 10 iterations, with less energy") {
  // Without anchors the sweeps' leftover tangential velocity accumulates: every row slides a little relative to
  // the one below (measured 58-107 cm at 10 s over eight starts as below, the worst box of rows 0-13 included).
  // With anchors the lower 14 rows stay within 2.2-4.1 cm (bound 5 cm and a tenth of the anchor-free figure);
  // the top rows still rattle (the pyramid's top oscillates at about 3 Hz with +-0.3 m/s, with and without
  // anchors: the normal rows do not converge in 10 sweeps), so the top boxes slip and the whole pyramid
  // (measured 4.2-14.4 cm) stays above issue 18's 3 cm (the skipped case in test_analytic_stacks.cpp); bound
  // 25 cm, under a third of the anchor-free lean.
  // Energy: the position term must not pump. Without the shock pass the resting pyramid is an unstable rest
  // state of the 10-sweep solve (docs/solver-internals.md), so one run's energy is one sample of a chaotic
  // motion: a change in the last bits of the block factorisation once moved the reference start's anchor-free
  // energy from 5.0 J to 2.1 J, level with the anchored run's (2.2 J). Over the reference start and seven starts
  // moved by +-0.5 nm the anchor-free runs gave 2.8-5.3 J (mean 4.3 J) and the anchored ones 1.4-1.9 J (mean
  // 1.6 J), lower in 8 of 8. So the energy is compared as the mean over four starts (the reference and three
  // moved ones), and the lean bounds hold for each run.
  constexpr int kStarts = 4;
  Real offEnergy = 0, onEnergy = 0;
  for (int seed = 0; seed < kStarts; ++seed) {
    const PyramidRun off = runPyramidNoShock(false, seed), on = runPyramidNoShock(true, seed);
    MESSAGE("pyramid20, no shock pass, 10 iterations, start " << seed << ", drift at 10 s: anchors off "
            << off.maxDisplacement * 100 << " cm, on " << on.maxDisplacement * 100 << " cm (rows 0-13: "
            << on.lowerDisplacement * 100 << " cm, off " << off.lowerDisplacement * 100
            << " cm); mean kinetic energy of the last 5 s: off " << off.meanKinetic << " J, on " << on.meanKinetic
            << " J");
    CHECK(off.finite);
    CHECK(on.finite);
    CHECK(off.maxDisplacement > 0.25);  // the defect the anchors address is present without them
    CHECK(on.maxDisplacement < 0.25);
    CHECK(on.maxDisplacement < 0.3 * off.maxDisplacement);
    CHECK(on.lowerDisplacement < 0.05);
    CHECK(on.lowerDisplacement < 0.1 * off.lowerDisplacement);
    offEnergy += off.meanKinetic / kStarts;
    onEnergy += on.meanKinetic / kStarts;
  }
  MESSAGE("mean over " << kStarts << " starts: off " << offEnergy << " J, on " << onEnergy << " J");
  CHECK(onEnergy <= offEnergy);
}

TEST_CASE("friction anchors: a sliding box and a cube sliding down an incline move as without them") {
  // A sliding manifold is at its Coulomb bound and drops its anchor whenever its anchors lie 1 % of its radius
  // apart; a new anchor adds nothing to its rows, and rows at their bound give the bound whatever their target.
  // So incline mu 0.5 (test_analytic_friction.cpp) gives the same bits. The slide is the same up to its stop;
  // after it the box sticks and its anchor holds the friction rows' viscous creep (as on the mu 0.6 incline
  // below): the final positions differ by 1.1e-10 m (bound 1e-9 m).
  SlideScene a = buildSlide(0.3, 5.0), b = buildSlide(0.3, 5.0);
  b.sim->getSolver().setUseFrictionAnchors(true);
  const SlideMetrics ma = runSlide(a), mb = runSlide(b);
  MESSAGE("slide: " << ma.distance << " m without anchors, " << mb.distance << " m with; position differs by "
                     << (b.box->getPosition() - a.box->getPosition()).norm() << " m");
  CHECK(std::abs(mb.distance - ma.distance) < 1e-9);
  CHECK((b.box->getPosition() - a.box->getPosition()).norm() < 1e-9);
  CHECK(std::abs(mb.distanceErr) < 0.02);
  InclineScene c = buildIncline(0.5), d = buildIncline(0.5);
  d.sim->getSolver().setUseFrictionAnchors(true);
  const InclineMetrics mc = runIncline(c), md = runIncline(d);
  MESSAGE("incline mu 0.5: " << mc.displacement << " m without anchors, " << md.displacement << " m with; differs by "
                             << md.displacement - mc.displacement << " m");
  CHECK(md.displacement == mc.displacement);
  CHECK(std::abs(md.error) < 0.02);
}

TEST_CASE("friction anchors: a cube sticking on a 30 degree incline (mu 0.6) creeps less than half as far") {
  // Without anchors the cube creeps at the friction rows' viscous compliance (surface viscosity 5e-9 m/(N s)
  // times the 4.9 N along the slope: 25 nm/s; measured 31 nm in 2 s at every iteration count). With anchors the
  // position term holds the creep where a g = that speed, g = 25 nm/s / 12.6 1/s = 2 nm, reached within a few
  // damping times (measured 7 nm in 2 s).
  InclineScene a = buildIncline(0.6), b = buildIncline(0.6);
  b.sim->getSolver().setUseFrictionAnchors(true);
  const InclineMetrics ma = runIncline(a), mb = runIncline(b);
  MESSAGE("incline mu 0.6 creep in 2 s: " << ma.displacement * 1e9 << " nm without anchors, "
                                          << mb.displacement * 1e9 << " nm with");
  CHECK(std::abs(ma.displacement) < 1e-3);
  CHECK(std::abs(mb.displacement) < 0.5 * std::abs(ma.displacement));
}

}  // TEST_SUITE
