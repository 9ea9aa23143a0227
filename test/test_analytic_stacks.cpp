// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Stacks at rest: the analytic answer is "nothing moves". tower10 and pyramid20 (bench/scenes, docs/scenes.md)
// must stand 10 s (600 steps at 1/60) with every box within 1 cm of its start; mass_ratio (1000 kg on 1 kg) must
// hold.
//
// Iterations: docs/scenes.md runs every engine with 10 solver iterations; Scree's default is 16. The first cases
// use the engine default 16 (stated in each MESSAGE); a sweep case runs 5 to 64 iterations and asserts that the
// error does not grow with the count.
#include <doctest/doctest.h>

#include "test_world.h"

using namespace scree;
using namespace scree::scenes;

namespace {
// 1 cm per box: the docs/scenes.md goal for tower10 ("drift under 1 cm"). Contact compliance accounts for
// micrometres (1 kg on 4 points of E = 4e8 N/m: 6 nm per box; the bottom of the tower 10x that), so anything
// near 1 cm is solver error.
constexpr Real kMaxDrift = 0.01;
constexpr int kDefaultIterations = 16;
}  // namespace

TEST_SUITE("solver") {

TEST_CASE("tower10 stands 10 s with every box within 1 cm (16 iterations)") {
  TowerScene s = buildTower10();
  s.sim->getSolver().setNumIterations(kDefaultIterations);
  const TowerMetrics m = runTower(s);
  MESSAGE("tower10, " << kDefaultIterations << " iterations: largest box drift " << m.maxDisplacement * 100
                      << " cm, top dxy " << m.topHorizontal * 100 << " cm, top dz " << m.topVertical * 100 << " cm");
  CHECK(m.finite);
  CHECK(m.maxDisplacement < kMaxDrift);
}

TEST_CASE("pyramid20 stands 10 s with every box within 1 cm (16 iterations)") {
  PyramidScene s = buildPyramid20();
  s.sim->getSolver().setNumIterations(kDefaultIterations);
  const PyramidMetrics m = runPyramid(s);
  MESSAGE("pyramid20, " << kDefaultIterations << " iterations: largest box drift " << m.maxDisplacement * 100
                        << " cm, top dz " << m.topDz * 100 << " cm, stands " << m.stands);
  CHECK(m.finite);
  CHECK(m.stands);
  CHECK(m.maxDisplacement < kMaxDrift);
}

TEST_CASE("pyramid20 stands 10 s with every box within 1 cm at the scene's 10 iterations (issue 18)") {
  // The issue-18 bound at docs/scenes.md's 10 iterations. Measured 0.015 cm with the default manifold block and
  // manifold friction (0.41 cm with both off; 2.1 cm with both on while the shock pass's impulses were the
  // warm start, docs/solver-internals.md "Resting stacks: the shock pass and the warm start").
  PyramidScene s = buildPyramid20();
  REQUIRE(s.sim->getSolver().getNumIterations() == 10);
  const PyramidMetrics m = runPyramid(s);
  MESSAGE("pyramid20, 10 iterations: largest box drift " << m.maxDisplacement * 100 << " cm, top dz "
                                                         << m.topDz * 100 << " cm");
  CHECK(m.finite);
  CHECK(m.stands);
  CHECK(m.maxDisplacement < kMaxDrift);
}

// Without the shock pass the plain sweeps are too weak per sweep for 20 rows at 10 iterations (78.6 cm of drift at
// 10 s without friction anchors, 8.6 cm with them and a rattle of the top rows; docs/solver-internals.md,
// "pyramid20 without the shock pass"). Issue 18's goal (< 3 cm) is met with the coarse correction
// (Solver::setUseCoarseCorrection): test_analytic_coarse_correction.cpp.

TEST_CASE("mass_ratio: 1000 kg on 1 kg holds, heavy box within 1 cm of 1.5 m (scene's 10 iterations)") {
  // Bound 1 cm on the final and on the worst height error over the run: compliance alone sinks the heavy box
  // by (1000 + 1001) kg g / (4 E) ~ 12 micrometres; ODE's direct solver holds it 6 mm low, Bullet, Jolt and
  // ODE QuickStep squeeze the light box out (docs/scenes.md). The light box must stay under the heavy one.
  MassRatioScene s = buildMassRatio();
  const MassRatioMetrics m = runMassRatio(s);
  MESSAGE("mass_ratio, " << s.sim->getSolver().getNumIterations() << " iterations: heavy error "
                         << m.heavyError * 1e3 << " mm (worst " << m.heavyErrorWorst * 1e3 << " mm), overlap "
                         << m.overlap * 1e3 << " mm (worst " << m.overlapWorst * 1e3 << " mm), squeezed "
                         << m.squeezed << " (step " << m.squeezedAtStep << ")");
  CHECK(m.finite);
  CHECK_FALSE(m.squeezed);
  CHECK(m.heavyError < 0.01);
  CHECK(m.heavyErrorWorst < 0.01);
  // Boxes must not sink into each other by more than the same bound.
  CHECK(m.overlapWorst < 0.01);
}

TEST_CASE("iteration sweep: more PGS sweeps never make the stacks worse (5 to 64 iterations)") {
  // The three scenes at 5, 10, 16, 32 and 64 iterations. Gauss-Seidel's residual shrinks with every sweep, so the
  // solver error a scene shows must not grow with the count. Measured (this code, Release):
  //   iterations        5       10      16      32      64
  //   pyramid20 drift   1.87    1.06    0.34    0.25    0.10 cm
  //   mass_ratio worst  79.0    55.0    27.9    25.6    24.1 um  (heavy box below 1.5 m, worst over the run)
  //   tower10 drift     15      33      16      12      2.2 um
  // Since the warm start matches points whose feature id changed by position (contact_rows.h), mass_ratio's
  // warm start is no longer lost, and its worst error sits at the compliance floor from 5 iterations on:
  // 23.81, 23.83, 23.82, 23.82, 23.84 um (pyramid20 1.42, 0.41, 0.18, 0.08, 0.05 cm). Those differ by less than
  // 0.1 um, 0.4 % of the sink: the error then only has to stay within 0.1 um of the previous count's.
  // Asserted: pyramid20's drift and mass_ratio's worst heavy error fall with every step of the sweep; at 64
  // iterations pyramid20's drift is under a tenth of its 5-iteration value (measured 1/18) and the heavy box's
  // worst error is within 10 % of the compliance sink, (1000 + 1001) kg g / (4 E) = 24.5 um for E = 2e8 N/m per
  // corner (measured -2 %: what is left of 64 sweeps on a 1000:1 ratio). tower10 is not monotone at this
  // scale (micrometres, below what the sweeps resolve once shock propagation has fixed the column), so it gets a
  // bound: 0.1 mm at every count, 3x the worst measured and a hundredth of the scene's 1 cm goal. Every run
  // stays finite, pyramid20 stands and the light box is never squeezed out.
  const int counts[] = {5, 10, 16, 32, 64};
  constexpr int n = 5;
  TowerMetrics tower[n];
  PyramidMetrics pyr[n];
  MassRatioMetrics mr[n];
  Real sink = 0;
  for (int k = 0; k < n; ++k) {
    CAPTURE(counts[k]);
    TowerScene t = buildTower10();
    t.sim->getSolver().setNumIterations(counts[k]);
    tower[k] = runTower(t);
    PyramidScene p = buildPyramid20();
    p.sim->getSolver().setNumIterations(counts[k]);
    pyr[k] = runPyramid(p);
    MassRatioScene m = buildMassRatio();
    m.sim->getSolver().setNumIterations(counts[k]);
    mr[k] = runMassRatio(m);
    sink = (1000 + 1001) * m.sim->getUniformGravity().norm() / (4 * m.contactMaterial->getYoungsModulus());
    MESSAGE("iterations " << counts[k] << ": tower10 drift " << tower[k].maxDisplacement * 1e6
                          << " um; pyramid20 drift " << pyr[k].maxDisplacement * 100 << " cm; mass_ratio heavy error "
                          << mr[k].heavyError * 1e6 << " um (worst " << mr[k].heavyErrorWorst * 1e6
                          << " um, compliance sink " << sink * 1e6 << " um), squeezed " << mr[k].squeezed);
    CHECK(tower[k].finite);
    CHECK(pyr[k].finite);
    CHECK(mr[k].finite);
    CHECK(pyr[k].stands);
    CHECK_FALSE(mr[k].squeezed);
    CHECK(tower[k].maxDisplacement < 1e-4);
    if (k > 0) {
      CHECK(pyr[k].maxDisplacement < pyr[k - 1].maxDisplacement);
      CHECK(mr[k].heavyErrorWorst < mr[k - 1].heavyErrorWorst + 1e-7);
    }
  }
  CHECK(pyr[n - 1].maxDisplacement < 0.1 * pyr[0].maxDisplacement);
  CHECK(mr[n - 1].heavyErrorWorst == doctest::Approx(sink).epsilon(0.1));
}

}  // TEST_SUITE
