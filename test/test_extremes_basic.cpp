// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Extreme parameters: the state must stay finite, the energy must not grow, and the bodies stay bounded.
// "Energy not growing": kinetic + gravitational potential energy never exceeds its initial value by more than
// 1e-6 J per kg plus 1e-9 relative (round-off); contact springs may store energy while compressed, which only
// lowers K + U, so K + U <= K0 + U0 holds for a passive contact model.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "test_world.h"

using namespace scree;
using scree::test::TestWorld;
using scree::test::mechanicalEnergy;

namespace {
constexpr Real kG = 9.81;

Real totalEnergy(const std::vector<RigidBodyRef>& bodies) {
  Real e = 0;
  for (const auto& b : bodies) e += mechanicalEnergy(*b, kG);
  return e;
}
Real energyTolerance(const std::vector<RigidBodyRef>& bodies, Real e0) {
  Real m = 0;
  for (const auto& b : bodies) m += b->getMass();
  return 1e-6 * m + 1e-9 * std::abs(e0);
}
}  // namespace

TEST_SUITE("solver") {

TEST_CASE("a resting box stays finite and passive for Young's modulus 1e3 .. 1e12 N/m") {
  for (Real E : {1e3, 1e5, 1e7, 1e9, 1e12}) {
    CAPTURE(E);
    TestWorld w(1.0 / 60.0, kG);
    w.contactMaterial->setYoungsModulus(E);
    w.addGround();
    auto box = w.addBox(Vec3(0.5, 0.5, 0.5), Vec3(0, 0, 0.5), 1.0);
    const Real e0 = mechanicalEnergy(*box, kG), tol = energyTolerance({box}, e0);
    Real worstGain = -1e300;
    for (int i = 0; i < 120; ++i) {
      w.sim->stepForward();
      worstGain = std::max(worstGain, mechanicalEnergy(*box, kG) - e0);
    }
    // Depth m g / (4 E): 2.5 mm at E = 1e3; the box must stay on the ground and upright.
    MESSAGE("E " << E << ": z " << box->getPosition().z() << ", worst energy gain " << worstGain << " J");
    CHECK(w.finite());
    CHECK(w.sim->getLastStepReport().ok());
    CHECK(worstGain <= tol);
    CHECK(box->getPosition().z() > 0.49);
    CHECK(box->getPosition().z() < 0.51);
  }
}

TEST_CASE("a resting box stays finite and passive for time steps 1e-5 .. 0.1 s") {
  for (Real h : {1e-5, 1e-4, 1e-3, 1.0 / 60.0, 0.1}) {
    CAPTURE(h);
    TestWorld w(h, kG);
    w.addGround();
    auto box = w.addBox(Vec3(0.5, 0.5, 0.5), Vec3(0, 0, 0.5), 1.0);
    // Besides round-off: the first step sinks the box by the PGS residual (a few 1e-4 of the step's gravity
    // displacement g h^2 on the statically indeterminate 4-point manifold, measured), and the contact's
    // stabilisation pushes it back within a few steps; at h = 0.1 (d = tau/h = 0.75 < 1) the push-back
    // overshoots once by up to the same amount. That one-off transient is bounded by m g (1e-3 g h^2)
    // (1e-3 J at h = 0.1, 3e-5 J at 1/60); growth is excluded separately by the final-value check below.
    const Real e0 = mechanicalEnergy(*box, kG);
    const Real tol = energyTolerance({box}, e0) + 1e-3 * box->getMass() * kG * kG * h * h;
    Real worstGain = -1e300;
    const int n = 200;  // short runs: 2 ms at 1e-5, 20 s at 0.1
    for (int i = 0; i < n; ++i) {
      w.sim->stepForward();
      worstGain = std::max(worstGain, mechanicalEnergy(*box, kG) - e0);
    }
    MESSAGE("h " << h << ": z " << box->getPosition().z() << ", worst energy gain " << worstGain << " J");
    CHECK(w.finite());
    CHECK(worstGain <= tol);
    // No growth: at the end of the run the energy is back at or below its start (round-off only).
    CHECK(mechanicalEnergy(*box, kG) - e0 <= energyTolerance({box}, e0));
    CHECK(box->getPosition().z() > 0.45);
    CHECK(box->getPosition().z() < 0.55);
  }
}

TEST_CASE("100 m/s impacts on the ground: finite, no energy gain, the body stays above the ground") {
  for (bool sphere : {true, false}) {
    CAPTURE(sphere);
    TestWorld w(1.0 / 60.0, kG, 0.5, 0.5);
    w.addGround();
    auto b = sphere ? w.addSphere(0.1, Vec3(0, 0, 3.0), 1.0) : w.addBox(Vec3(0.2, 0.2, 0.2), Vec3(0, 0, 3.0), 1.0);
    b->setVelocity(Vec3(0, 0, -100));
    const Real e0 = mechanicalEnergy(*b, kG), tol = energyTolerance({b}, e0);
    Real worstGain = -1e300, minZ = 1e300;
    for (int i = 0; i < 180; ++i) {
      w.sim->stepForward();
      worstGain = std::max(worstGain, mechanicalEnergy(*b, kG) - e0);
      minZ = std::min(minZ, b->getPosition().z());
    }
    MESSAGE(std::string(sphere ? "sphere" : "box") << ": lowest centre z " << minZ << ", final z " << b->getPosition().z()
                                        << ", worst energy gain " << worstGain << " J (E0 " << e0 << ")");
    CHECK(w.finite());
    CHECK(worstGain <= tol);
    CHECK(minZ > 0);  // the centre never goes below the ground's top face
  }
}

// 1e5 : 1 with PGS at the scene's 10 iterations. (1e6 : 1 still squeezes the light box out with PGS at 10
// iterations; test_extremes_solvers.cpp holds it with DIRECT contacts.)
TEST_CASE("a 1e5 kg box on a 1 kg box: finite and bounded") {
  TestWorld w(1.0 / 60.0, kG);
  w.addGround();
  auto light = w.addBox(Vec3(0.5, 0.5, 0.5), Vec3(0, 0, 0.5), 1.0);
  auto heavy = w.addBox(Vec3(0.5, 0.5, 0.5), Vec3(0, 0, 1.5), 1e5);
  const Real e0 = totalEnergy({light, heavy}), tol = energyTolerance({light, heavy}, e0);
  Real worstGain = -1e300, maxSpeed = 0, maxDist = 0;
  for (int i = 0; i < 300; ++i) {
    w.sim->stepForward();
    worstGain = std::max(worstGain, totalEnergy({light, heavy}) - e0);
    maxSpeed = std::max({maxSpeed, light->getVelocity().norm(), heavy->getVelocity().norm()});
    maxDist = std::max({maxDist, (light->getPosition() - Vec3(0, 0, 0.5)).norm(),
                        (heavy->getPosition() - Vec3(0, 0, 1.5)).norm()});
  }
  MESSAGE("1e5 : 1 stack: heavy z " << heavy->getPosition().z() << ", light at "
                                    << light->getPosition().transpose() << ", max speed " << maxSpeed
                                    << " m/s, max displacement " << maxDist << " m, worst energy gain " << worstGain
                                    << " J");
  CHECK(w.finite());
  CHECK(w.sim->getLastStepReport().ok());
  // Held: the two contacts are springs in series, each 4 points x 4e8 N/m, so the static sink of the heavy
  // box is 2 M g / 1.6e9 = 1.2 mm; the settling transient of the soft landing may double it. Bound: 4x the
  // static sink. Nothing is launched (speed below 0.1 m/s; measured 0.014) and the light box stays within 1 cm.
  const Real sink = 2 * 1e5 * kG / 1.6e9;
  CHECK(std::abs(heavy->getPosition().z() - 1.5) < 4 * sink);
  CHECK(maxSpeed < 0.1);
  CHECK(maxDist < 4 * sink + 0.01);
  CHECK(worstGain <= tol);
}

}  // TEST_SUITE
