// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Resting stacks of upright cylinders at default settings (issue 20): the stack sweep of
// test_extremes_stacks.cpp (issue 18) with Cylinders (diameter = height = size) in place of boxes.
//
// Same 81 towers: sizes 0.1 / 0.6 / 2 m, densities 10 / 1000 / 10,000 kg/m^3, 5 / 10 / 20 cylinders, mu 0.3 or
// 1.0 (alternating), placements exactly aligned and touching, shifted by millimetres (the fixed +-1 mm / +-0.5 mm
// pattern) and dropped through 1 mm gaps; 30 s at h = 1/60 with the Simulation's default solver settings, on a
// box ground. The cap-cap contacts come from the support-feature manifold (collide/src/convex_manifold.cpp: the
// cap clipped as its true circle, reduced to 4 points), the bottom cap on the ground box from cylinder_box.cpp
// (disc-rectangle candidates, reduced to 4). The first test reads those manifolds at rest; the closed forms of
// the sweep (compliance sink, buckling) use what it reads. docs/solver-internals.md "Stack sweep: compliance
// sink and buckling" has the figures.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <scree/scree.h>

#include "stack_column.h"

using namespace scree;
using stack_column::blockPosition;
using stack_column::name;
using stack_column::observe;
using stack_column::pairStiffness;
using stack_column::Placement;
using stack_column::TowerResult;

namespace {

constexpr Real kPi = 3.14159265358979323846;

Quat upright() { return Quat(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitX())); }  // cylinder axis y -> world z

struct Tower {
  Simulation sim;
  std::vector<RigidBodyRef> bodies;
  std::vector<Vec3> start;
  GeometryRef ground;
};

/// A tower of `count` upright cylinders of diameter and height `size` on a 100 x 100 x 1 m box ground.
std::unique_ptr<Tower> makeTower(Real size, Real density, int count, Real mu, Placement placement) {
  auto t = std::make_unique<Tower>();
  const Real h = 1.0 / 60;
  t->sim.setTimeStep(h);
  t->sim.setUniformGravity(Vec3(0, 0, -9.81));
  auto mat = std::make_shared<Material>("stack");
  mat->setDensity(density);
  mat->setRestitution(0);
  mat->setFrictionCoefficient(mu);
  t->ground = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(50, 50, 0.5)));
  t->ground->setPosition(Vec3(0, 0, -0.5));
  t->ground->setMaterial(mat);
  t->sim.add(t->ground);
  const Real half = size / 2;
  for (int i = 0; i < count; ++i) {
    auto g = std::make_shared<Geometry>(std::make_shared<Cylinder>(half, size));
    g->setMaterial(mat);
    auto b = std::make_shared<RigidBody>();
    b->add(g);
    const Vec3 p = blockPosition(size, i, placement);
    b->setPosition(p);
    b->setRotation(upright());
    t->sim.add(b);
    t->bodies.push_back(b);
    t->start.push_back(p);
  }
  return t;
}

TowerResult runTower(Real size, Real density, int count, Real mu, Placement placement, Real seconds) {
  auto t = makeTower(size, density, count, mu, placement);
  TowerResult r;
  const int steps = int(std::lround(seconds / t->sim.getTimeStep()));
  for (int s = 0; s < steps; ++s) {
    t->sim.stepForward();
    observe(r, t->bodies, t->start);
  }
  r.topDrop = t->start.back().z() - t->bodies.back()->getPosition().z();
  return r;
}

// ---- Closed forms of a column of n equal upright cylinders (diameter = height = s, radius R = s/2, mass
// m = rho pi R^2 s) on compliant contacts ------------------------------------------------------------------------
// Every joint (cap on cap, bottom cap on the ground box) rests on kPoints = 4 rim points 90 degrees apart (the
// first test reads them), each a linear spring of stiffness k = E^2 / (2 E) = E / 2 (two equal materials in
// series, core/src/material.cpp; N/m per point, solver/src/contact_law.h). SPOOK's rest state is that of the
// springs (docs/design.md §3), so the box sweep's closed forms hold with the cylinder's mass and joint.
constexpr int kPoints = 4;

Real cylinderMass(Real size, Real density) { return density * kPi * (size / 2) * (size / 2) * size; }

/// Static sink of the top cylinder: joint j (0 = ground) carries the n - j cylinders above it on kPoints springs.
Real complianceSink(Real size, Real density, int count, Real g, Real k) {
  return stack_column::complianceSink(cylinderMass(size, density), count, g, k, kPoints);
}

/// Rotational stiffness per unit point stiffness of a joint about its weakest horizontal axis: sum r_i^2 over the
/// 4 rim points at radius R, 90 degrees apart, is 2 R^2 about every horizontal axis through the centre (half the
/// box's 4 a^2 with a = R: the box's corners sit at distance a from both face axes, the rim points at R from one
/// only).
Real jointStiffnessPerK(Real size) { return 2 * (size / 2) * (size / 2); }

/// The box sweep's criterion (stack_column.h) with the cylinder's joint and mass (its centre is still s/2 above
/// its joint).
bool columnStands(Real size, Real density, int count, Real g, Real k) {
  return stack_column::columnStands(cylinderMass(size, density), size, count, g, jointStiffnessPerK(size) * k);
}

Real bucklingStiffness(Real size, Real density, int count, Real g) {
  return stack_column::bucklingStiffness(cylinderMass(size, density), size, count, g, jointStiffnessPerK(size));
}

}  // namespace

TEST_SUITE("stacks") {

// The closed forms below count on 4 loaded rim points per joint, 90 degrees apart: check that on an aligned
// 5 x 0.6 m tower after 2 s. For each joint (ground-cap and cap-cap): the number of points carrying force, each
// point's distance from the axis (R = 0.3 m), and the smallest eigenvalue of the points' horizontal second
// moment sum (r_i r_i^T) about the axis -- the rotational stiffness per k about the weakest axis -- against 2 R^2.
// Measured: 4 points at R, weakest sum 0.18 m^2 = 2 R^2 on every joint, at 2 s and at 6 s. Which 4 of the
// cap's equally deep rim points are kept was not stable at first: the kept square turned from step to step (0,
// 15, 30, 45 degrees ... with new feature ids each time, so no warm start); reduceManifold's depth tie tolerance
// now keeps the first of them in the cylinder frame's order. This test checks only the geometry.
TEST_CASE("an upright cylinder's cap-cap and cap-box manifolds at rest are 4 rim points 90 degrees apart") {
  const Real size = 0.6, R = size / 2;
  auto t = makeTower(size, 1000, 5, 0.3, Placement::ALIGNED);
  for (int s = 0; s < 120; ++s) t->sim.stepForward();
  for (int j = 0; j < 5; ++j) {
    const RigidBody* upper = t->bodies[j].get();
    const RigidBody* lower = j == 0 ? nullptr : t->bodies[j - 1].get();
    const Vec3 axis = upper->getPosition();
    int loaded = 0;
    Eigen::Matrix<Real, 2, 2> second = Eigen::Matrix<Real, 2, 2>::Zero();
    Real force = 0;
    for (const GeometryContact& c : t->sim.getContacts()) {
      const bool pair = (c.rigidBody(0) == upper && c.rigidBody(1) == lower) ||
                        (c.rigidBody(1) == upper && c.rigidBody(0) == lower);
      if (!pair) continue;
      for (const ContactPoint& p : c.points()) {
        if (p.normalForce <= 0) continue;
        ++loaded;
        force += p.normalForce;
        const Eigen::Matrix<Real, 2, 1> r = (p.point - axis).head<2>();
        CHECK(r.norm() == doctest::Approx(R).epsilon(1e-6));
        second += r * r.transpose();
      }
    }
    // Smaller eigenvalue of the symmetric 2 x 2 second moment.
    const Real mean = (second(0, 0) + second(1, 1)) / 2, dev = (second(0, 0) - second(1, 1)) / 2;
    const Real weakest = mean - std::sqrt(dev * dev + second(0, 1) * second(0, 1));
    MESSAGE("joint " << j << std::string(j == 0 ? " (cap on ground box)" : " (cap on cap)") << ": " << loaded
                     << " loaded points, force " << force << " N, weakest sum r^2 " << weakest << " m^2 (2 R^2 = "
                     << 2 * R * R << ")");
    CHECK(loaded == kPoints);
    CHECK(weakest == doctest::Approx(2 * R * R).epsilon(1e-6));
  }
}

// The box sweep's case "stack sweep: stable towers stand ..." with cylinders; the assertions and bounds are the
// box sweep's (test_extremes_stacks.cpp explains them): every tower stable by columnStands stays within 1 cm
// horizontally for 30 s, its top sinks by the gaps plus complianceSink within 1 um + 1e-6 of the sink, an
// aligned one keeps every horizontal speed below 1e-9 m/s; a tower past its buckling load with mm offsets must
// lean over (> 1 cm). By columnStands only 20 x 2 m x 10,000 kg/m^3 is past its buckling load (k = 2e8 against
// k_crit = 6.8e8 N/m per point; the box's is 4.3e8); as in the box sweep its aligned and gapped towers count among
// those that must stand within 1 cm (an unstable equilibrium nothing disturbs much in 30 s).
//
// One departure from the box sweep, by the same closed form: the aligned tower past its buckling load is not held
// to the 1e-9 m/s bound. A box tower at the identity rotation is exactly symmetric; an upright cylinder is turned
// by a quaternion whose rim points carry roundoff of ~1e-17 m, and past the buckling load that seed grows
// exponentially (measured: drift 1.4e-12 m at 5 s, then x7 every 5 s, 1.4e-6 m and 4e-7 m/s at 30 s), while every
// stable aligned tower stays below 3.2e-10 m/s. It still has to stand within 1 cm and sink by the closed form.
//
// What it took (measured before the fixes: 69 of 80 standing, 15 missing the sink bound, 6 of 27 aligned above
// 1e-9 m/s): (1) a cap on a cap kept, step by step, whichever copy of a doubled rim point roundoff chose (P's rim
// vertex, an edge crossing at t = 0 or 1, or D's rim point), so a point got a new feature id and, while the tower
// still settled faster than the warm start's 1e-5 m position fallback, started from zero while the others kept
// their impulse: the unequal start tipped the heavy towers (first sideways motion at step 8 of 10 x 2 m x 1000,
// at the top joint's re-labelled point). The cap-on-cap branch of convex_manifold.cpp now gives the boundary band
// to the reference cap. (2) the 2 m cylinders' bottom caps rested on the ground at a depth of -2.8e-17 m
// (rotation roundoff): speculative rows, i.e. a rigid support that never sank (the sink was exactly the closed
// form without the ground joint's term); levelDepths now sets a level depth within roundoff of 0 to 0.
// Measured now (30 s, ~10 s of CPU for all 81): 80 of 80 stand (worst drift 1.4 mm), worst sink error 4.0e-7 m,
// the 26 stable aligned towers below 1e-9 m/s (worst 3.1e-10 m/s, 10 x 2 m x 10,000; below 4e-13 m/s under
// 10,000 kg/m^3), and the offset tower past its buckling load leans over (54 m).
TEST_CASE("cylinder stack sweep: stable towers stand 30 s within 1 cm and sink by their contact compliance; "
          "aligned towers move sideways below 1e-9 m/s; towers past their buckling load lean over") {
  const Real seconds = 30, g = 9.81;
  const Real k = pairStiffness(Material("default").getYoungsModulus());
  int index = 0, standing = 0, leaning = 0, total = 0, stableTotal = 0;
  Real worstSinkError = 0, worstDrift = 0, worstSinkErrorStanding = 0;
  int sinkFailures = 0, speedFailures = 0;
  for (Real size : {0.1, 0.6, 2.0})
    for (Real density : {10.0, 1000.0, 10000.0})
      for (int count : {5, 10, 20}) {
        const Real mu = index++ % 2 ? 1.0 : 0.3;
        const bool stable = columnStands(size, density, count, g, k);
        for (Placement placement : {Placement::ALIGNED, Placement::OFFSET, Placement::GAP}) {
          CAPTURE(size);
          CAPTURE(density);
          CAPTURE(count);
          CAPTURE(mu);
          CAPTURE(int(placement));
          const TowerResult r = runTower(size, density, count, mu, placement, seconds);
          const Real gaps = placement == Placement::GAP ? count * 1e-3 : 0.0;
          const Real sink = complianceSink(size, density, count, g, k);
          const Real sinkError = std::abs(r.topDrop - gaps - sink);
          ++total;
          CHECK(r.finite);
          if (!stable && placement == Placement::OFFSET) {
            MESSAGE("past its buckling load (k = " << k << " < k_crit = " << bucklingStiffness(size, density, count, g)
                                                   << " N/m per point): " << count << " x " << size << " m, "
                                                   << density << " kg/m^3, " << name(placement) << ": drift "
                                                   << r.maxHorizontalDrift << " m");
            leaning += r.maxHorizontalDrift > 0.01;
            CHECK(r.maxHorizontalDrift > 0.01);
            continue;
          }
          ++stableTotal;
          worstSinkError = std::max(worstSinkError, sinkError);
          worstDrift = std::max(worstDrift, r.maxHorizontalDrift);
          const bool stands = r.finite && r.maxHorizontalDrift < 0.01;
          standing += stands;
          if (stands) worstSinkErrorStanding = std::max(worstSinkErrorStanding, sinkError);
          sinkFailures += !(sinkError < 1e-6 + 1e-6 * sink);
          // Aligned and stable by the closed form: symmetric, so nothing may move it (see above for the other).
          const bool speedBound = placement == Placement::ALIGNED && stable;
          speedFailures += speedBound && !(r.maxHorizontalSpeed < 1e-9);
          if (!stands || placement == Placement::ALIGNED || sinkError >= 1e-6 + 1e-6 * sink)
            MESSAGE(std::string(stands ? "stands: " : "falls: ")
                    << count << " x " << size << " m, " << density << " kg/m^3, mu " << mu << ", " << name(placement)
                    << ": drift " << r.maxHorizontalDrift << " m, max horizontal speed " << r.maxHorizontalSpeed
                    << " m/s, sink " << r.topDrop - gaps << " m (closed form " << sink << ")");
          CHECK(r.maxHorizontalDrift < 0.01);
          CHECK(sinkError < 1e-6 + 1e-6 * sink);
          if (speedBound) CHECK(r.maxHorizontalSpeed < 1e-9);
        }
      }
  MESSAGE(standing << " of " << stableTotal << " towers that must stand stand 30 s within 1 cm (worst drift "
                   << worstDrift << " m, worst top-sink error " << worstSinkError << " m, among those standing "
                   << worstSinkErrorStanding << " m); " << sinkFailures << " miss the sink bound, " << speedFailures
                   << " of 26 stable aligned the 1e-9 m/s bound; " << leaning << " of " << total - stableTotal
                   << " past their buckling load lean over");
  CHECK(total == 81);
}

}  // TEST_SUITE
