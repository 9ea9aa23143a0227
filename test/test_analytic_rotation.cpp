// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Torque-free rotation: the Dzhanibekov (intermediate-axis) effect.
//
// A box with half extents (0.5, 0.2, 0.05) has principal moments I_x : I_y : I_z = 0.17 : 1.01 : 1.16 (x m/12),
// so y is the intermediate axis. Spun about y at 5 rad/s with a 1e-3 rad/s perturbation about x and z, the
// perturbation grows at lambda = w sqrt((I_z - I_y)(I_y - I_x)/(I_x I_z)) = 4.0 /s: the first flip comes after
// roughly ln(5000)/4 = 2 s (plus the time to reach the separatrix; 3.4 s measured) and then repeats.
//
// Invariants of the exact flow: the world angular momentum L and the kinetic energy T = sum L_k^2 / (2 I_k)
// (body frame). Both are quadratic in L, so an integrator of Euler's equations that preserves quadratic
// invariants (the implicit midpoint rule on L' = L x I^-1 L, or the discrete Moser-Veselov map) keeps both to
// round-off and to its nonlinear-solve tolerance; those are the bounds used here.
//  - |L| within 1e-4 relative over 20 s (1200 steps at 1/60, h w = 0.083 rad per step). A rotation update that
//    does not conserve L (first-order exp(h w) with the gyroscopic term as a torque) drifts ~1e-2 per flip.
//  - T never above T0 by more than 1e-6 relative. An explicit gyroscopic torque (w += h I^-1 (-w x I w))
//    pumps energy in by O((h w)^2) per step (~1e-3 here) and fails by orders of magnitude; a splitting
//    scheme that conserves L but not T shows a bounded O((h w)^2) oscillation, which this bound also flags.
//    1e-6 is far above round-off (1200 steps x 1e-16) and leaves room for an iterative midpoint solve.
#include <doctest/doctest.h>

#include <cmath>

#include "test_world.h"

using namespace scree;
using scree::test::TestWorld;

TEST_SUITE("solver") {

TEST_CASE("Dzhanibekov: a box spun about its intermediate axis flips, conserving |L| and not gaining energy") {
  TestWorld w(1.0 / 60.0, 0.0);  // no gravity, no ground
  auto box = w.addBox(Vec3(0.5, 0.2, 0.05), Vec3(0, 0, 0), 1.0);
  const Mat3 Ib = box->getInertiaTensor();
  REQUIRE(Ib(0, 0) < Ib(1, 1));
  REQUIRE(Ib(1, 1) < Ib(2, 2));
  box->setAngularVelocity(Vec3(1e-3, 5.0, 1e-3));

  auto angularMomentum = [&]() {
    const Mat3 R = box->getRotation().toRotationMatrix();
    return Vec3(R * Ib * R.transpose() * box->getAngularVelocity());
  };
  auto energy = [&]() {
    const Mat3 R = box->getRotation().toRotationMatrix();
    const Vec3 wv = box->getAngularVelocity();
    return 0.5 * wv.dot(R * Ib * R.transpose() * wv);
  };
  const Vec3 L0 = angularMomentum();
  const Real T0 = energy();
  const Vec3 axis0 = box->getRotation() * Vec3::UnitY();

  Real minDot = 1, worstL = 0, worstLvec = 0, worstTup = 0, firstFlip = -1;
  int flips = 0;
  bool flipped = false;
  const int steps = int(std::lround(20.0 / w.dt));
  for (int i = 0; i < steps; ++i) {
    w.sim->stepForward();
    const Real d = (box->getRotation() * Vec3::UnitY()).dot(axis0);
    minDot = std::min(minDot, d);
    if (!flipped && d < -0.9) {
      flipped = true;
      ++flips;
      if (firstFlip < 0) firstFlip = w.time();
    } else if (flipped && d > 0.9) {
      flipped = false;
    }
    const Vec3 L = angularMomentum();
    worstL = std::max(worstL, std::abs(L.norm() - L0.norm()) / L0.norm());
    worstLvec = std::max(worstLvec, (L - L0).norm() / L0.norm());
    worstTup = std::max(worstTup, (energy() - T0) / T0);
  }
  const Vec3 Lapi = box->getAngularMomentum();
  MESSAGE("Dzhanibekov, 20 s at 1/60: min axis dot " << minDot << ", reversals " << flips << " (first at "
                                                     << firstFlip << " s), worst | |L| - |L0| |/|L0| " << worstL
                                                     << ", worst |L - L0|/|L0| " << worstLvec
                                                     << ", worst (T - T0)/T0 " << worstTup << ", final T/T0 "
                                                     << energy() / T0);
  CHECK(w.finite());
  CHECK(flips >= 1);
  CHECK(worstL <= 1e-4);
  CHECK(worstTup <= 1e-6);
  // RigidBody::getAngularMomentum() agrees with R I R^T w.
  CHECK((Lapi - angularMomentum()).norm() <= 1e-9 * L0.norm());
}

TEST_CASE("a box spun about its major or minor axis keeps spinning about it") {
  // The stable axes: the axis stays within 0.01 rad-equivalent (dot > 0.9999) with the same perturbation.
  for (int ax : {0, 2}) {
    CAPTURE(ax);
    TestWorld w(1.0 / 60.0, 0.0);
    auto box = w.addBox(Vec3(0.5, 0.2, 0.05), Vec3(0, 0, 0), 1.0);
    Vec3 wv = Vec3::Constant(1e-3);
    wv[ax] = 5.0;
    box->setAngularVelocity(wv);
    Vec3 e = Vec3::Zero();
    e[ax] = 1;
    Real minDot = 1;
    for (int i = 0; i < 1200; ++i) {
      w.sim->stepForward();
      minDot = std::min(minDot, (box->getRotation() * e).dot(e));
    }
    MESSAGE("axis " << ax << ": min dot " << minDot);
    CHECK(minDot > 0.9999);
  }
}

}  // TEST_SUITE
