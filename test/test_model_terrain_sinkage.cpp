// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Terrain sinkage against the law's closed form: a plate pressed quasi-statically settles at
// z* = D ln(p/p0) / ((d+1) ln M) (terrain.h), grows with load, falls with deformability; a rolling wheel's
// second pass over its rut sinks less than the first. The ledger is checked after every step.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "terrain_world.h"
#include "test_build.h"

using namespace scree;
using namespace scree::test;

namespace {

struct PlateResult {
  Real mean = 0, min = 0, max = 0;  ///< plastic sinkage of the inner 9 x 9 vertices, m
  std::vector<Real> vertex;          ///< each inner vertex's sinkage, row by row, m
};

/// Plate-load test on an 11 x 11 terrain (0.5 m, cells s = 0.05 m) under a bed of 121 pistons: one small sphere
/// directly above each vertex, guided vertically (a Prismatic to the world), weighing p s^2. Each piston's one
/// contact point lands on its vertex, so every vertex carries exactly p s^2 - a uniform pressure p with no plate
/// edge and no statically indeterminate load sharing. Why not one wide box: the narrowphase reduces a box's
/// contact with a height field to four points at its corners, which would load four vertices only; and a rigid
/// plate on 121 points leaves the share of each point to the solver's convergence (PGS at 16 iterations puts
/// 0-900 N on points whose exact share is 52 N), while the yield law reads per-point forces.
/// Contact E = 1e5 N/m per point: the soil's elastic deflection under a piston (0.5 mm at 52 N), which is also
/// how far a vertex can yield in one step (terrain.h).
PlateResult pressPlate(Real pressureOverP0, Real deformability, Real seconds, Real* expected = nullptr,
                       Real dt = 1.0 / 60) {
  TestWorld w(dt);
  w.contactMaterial->setYoungsModulus(1e5);
  TerrainRef t = addFlatTerrain(w, 11, 0.5);
  TerrainDataInterface& di = t->getDataInterface();
  di.add(w.material, 0, 0.0, deformability);
  di.setMaxYoungsChangePerTimestep(std::numeric_limits<Real>::infinity());
  const Real s = 0.05, p = pressureOverP0 * di.getYieldPressure();
  if (expected) *expected = t->computeSettledSinkage(p, deformability);
  for (size_t j = 0; j < 11; ++j)
    for (size_t i = 0; i < 11; ++i) {
      Vec3 at = t->getHeightField()->getVertex(i, j);
      at.z() = 0.01;
      auto piston = w.addSphere(0.01, at, p * s * s / 9.81);
      w.sim->add(std::make_shared<Prismatic>(piston, nullptr, at, Vec3::UnitZ()));
    }
  stepCheckingLedger(w, *t, int(std::lround(seconds / w.dt)));
  PlateResult r;
  r.min = 1e9;
  r.max = -1e9;
  for (size_t y = 1; y < 10; ++y)
    for (size_t x = 1; x < 10; ++x) {
      const Real sink = 0.5 - t->getHeightField()->getHeight(x, y);
      r.mean += sink / 81;
      r.vertex.push_back(sink);
      r.min = std::min(r.min, sink);
      r.max = std::max(r.max, sink);
    }
  return r;
}

}  // namespace

TEST_SUITE("terrain") {
  TEST_CASE("a plate settles at the closed-form sinkage z* = D ln(p/p0) / ((d+1) ln M)") {
    // 2 % on the mean of the inner vertices: at rest each vertex meets the law exactly (p0 m = p s^2 / s^2); what
    // is left after 8 s is the approach from below (a vertex yields at most its elastic deflection per step,
    // and the piston must follow) and the pistons' settling impulses. The outer ring is left out: its
    // pistons touch the field's edge. Every inner vertex within 5 %.
    std::vector<std::vector<Real>> sink(2);
    const Real pressures[2] = {3.0, 10.0}, ds[2] = {1.0, 3.0};
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) {
        Real expected = 0;
        const PlateResult r = pressPlate(pressures[a], ds[b], 8.0, &expected);
        MESSAGE("p = " << pressures[a] << " p0, d = " << ds[b] << ": sinkage " << r.mean << " m (min " << r.min
                       << ", max " << r.max << "), closed form " << expected << " m, error "
                       << 100 * (r.mean - expected) / expected << " %");
        CHECK(std::abs(r.mean - expected) <= 0.02 * expected);
        CHECK(std::abs(r.max - expected) <= 0.05 * expected);
        CHECK(std::abs(r.min - expected) <= 0.05 * expected);
        sink[a].push_back(r.mean);
      }
    CHECK(sink[1][0] > sink[0][0]);  // grows with load
    CHECK(sink[1][1] > sink[0][1]);
    CHECK(sink[0][1] < sink[0][0]);  // falls with deformability
    CHECK(sink[1][1] < sink[1][0]);
  }

  TEST_CASE("below p0 nothing yields; above p0 M the ground keeps yielding (bearing failure)") {
    const PlateResult below = pressPlate(0.8, 1.0, 1.0);
    CHECK(below.max == 0);
    // 20 p0 > 16 p0 = p0 M: every loaded step sinks further, past D/(d+1) where the law's range ends.
    const Real end = TerrainDataInterface::defaultDepthForMaxCompression / 2;
    const PlateResult early = pressPlate(20.0, 1.0, 1.5), late = pressPlate(20.0, 1.0, 3.0);
    MESSAGE("20 p0: sinkage " << early.mean << " m after 1.5 s, " << late.mean << " m after 3 s (D/(d+1) = " << end
                              << " m)");
    CHECK(late.min > end);
    // Every vertex keeps sinking: each inner vertex at 3 s lies at least 5 mm below itself at 1.5 s (both runs
    // start from the same state, so the 3 s run passes through the 1.5 s one). Measured: 10.7 mm (PGS-only build)
    // and 13.3 mm (default build) for the least-sinking vertex, 48-52 mm for the most.
    Real leastSink = 1e9;
    for (size_t k = 0; k < late.vertex.size(); ++k) leastSink = std::min(leastSink, late.vertex[k] - early.vertex[k]);
    MESSAGE("least per-vertex sinkage from 1.5 s to 3 s: " << leastSink * 1e3 << " mm");
    CHECK(leastSink > 0.005);
    // The whole plate at 3 s also lies 5 mm below the whole plate at 1.5 s in the default build. This compares
    // two extremes of the plate, not one vertex over time: past D/(d+1) the plate turns into a bowl (3 s: centre
    // 139-147 mm, edges 100-107 mm, in both builds) and at 1.5 s its vertices spread by 9-11 mm, so the margin is
    // late.min - early.max - 5 mm = +5.1 mm (default build) and -1.0 mm (PGS-only build). That margin is noise, not
    // a solver defect: each piston is its own problem (one sphere, its prismatic joint and the static terrain;
    // no row couples two pistons), the iterative joints hold the pistons within 1.3 um of their axis (the direct
    // ones within 0.11 mm), and in the PGS-only build the margin moves between -3.2 and +3.9 mm with solver
    // settings unrelated to the soil (manifold block off or its operators assembled per visit: -1.1 / -1.0 mm;
    // 32 sweeps -3.2 mm, 64 sweeps +3.9 mm), so the PGS-only build checks the per-vertex sinkage above.
    if (kHasDirectSolver)
      CHECK(late.min > early.max + 0.005);
  }

  TEST_CASE("the settled plate sinkage holds at smaller time steps") {
    // 5 %: at 1/400 s a piston landing on ground that just yielded is stopped by a larger, shorter force
    // (~ m v / h); the load averaging time (0.1 s) takes most of it out (without it, measured: +133 % at
    // 3 p0 and a runaway at 10 p0), what remains is measured here.
    for (Real dt : {1.0 / 120, 1.0 / 400})
      for (Real ratio : {3.0, 10.0}) {
        Real expected = 0;
        const PlateResult r = pressPlate(ratio, 1.0, 8.0, &expected, dt);
        MESSAGE("dt = " << dt << ", p = " << ratio << " p0: sinkage " << r.mean << " m, closed form " << expected
                        << " m, error " << 100 * (r.mean - expected) / expected << " %");
        CHECK(std::abs(r.mean - expected) <= 0.05 * expected);
      }
  }

  TEST_CASE("a rolling wheel leaves a rut; its second pass sinks less than the first") {
    TestWorld w(1.0 / 120);
    w.contactMaterial->setYoungsModulus(1e5);
    // 8 m x 2 m of soft ground, 0.1 m cells.
    auto hf = std::make_shared<HeightField>(81, 21, 8.0, 2.0);
    hf->setHeights(std::vector<Real>(81 * 21, 0.5));
    auto t = std::make_shared<Terrain>(hf);
    t->getGeometry()->setMaterial(w.material);
    t->getGeometry()->setPosition(Vec3(0, 0, -0.5));
    w.sim->add(t);
    t->getDataInterface().add(w.material, 0, 0.0, 1.0);
    const Real r = 0.3, v = 1.0;
    auto wheel = std::make_shared<RigidBody>("wheel");
    auto g = std::make_shared<Geometry>(std::make_shared<Cylinder>(r, 0.2));  // axis along y
    g->setMaterial(w.material);
    wheel->add(g);
    wheel->setMass(100);
    w.sim->add(wheel);
    // The wheel is driven: its forward speed is held at v (as a hub on a carriage would), its height free.
    w.sim->add(std::make_shared<LambdaStepListener>([&](const TimeStamp&) {
      Vec3 vel = wheel->getVelocity();
      vel.x() = v;
      vel.y() = 0;
      wheel->setVelocity(vel);
    }));
    auto rutDepth = [&] {
      // Mean height lost along the wheel's centre line over x in [-2, 2] m (vertices 20..60, row 10).
      Real sum = 0;
      for (size_t i = 20; i <= 60; ++i) sum += 0.5 - hf->getHeight(i, 10);
      return sum / 41;
    };
    auto pass = [&] {
      wheel->setPosition(Vec3(-3.2, 0, r + 0.01));
      wheel->setRotation(Quat::Identity());
      wheel->setVelocity(Vec3(v, 0, 0));
      wheel->setAngularVelocity(Vec3(0, v / r, 0));
      stepCheckingLedger(w, *t, int(std::lround(6.2 / v / w.dt)));
    };
    pass();
    const Real first = rutDepth();
    pass();
    const Real second = rutDepth() - first;
    MESSAGE("rut depth after the first pass " << first << " m; the second pass added " << second << " m");
    CHECK(first > 0.005);
    CHECK(second < first);
    CHECK(second >= 0);
  }
}
