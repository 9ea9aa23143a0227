// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Free fall and projectile motion against the integrator's discrete closed form.
//
// Scree integrates with semi-implicit (symplectic) Euler:
//   v_{n+1} = v_n + h g,   x_{n+1} = x_n + h v_{n+1}
// so after n steps   v_n = v0 + n h g,   x_n = x0 + n h v0 + h^2 g n(n+1)/2   exactly (in exact arithmetic).
// Tolerance 1e-9 relative: the only error left is floating-point round-off. Each step adds a relative error of
// ~1e-16 to x; after 1200 steps the accumulated error is ~1e-13 of the position scale, four orders below 1e-9.
// Any modelling difference (explicit Euler, midpoint, velocity Verlet, a gravity applied as a force with a
// different mass, damping) changes x by O(h) relative and fails by many orders.
#include <doctest/doctest.h>

#include <cmath>

#include "test_world.h"

using namespace scree;
using scree::test::TestWorld;

namespace {

struct Expect {
  Vec3 x, v;
};
Expect closedForm(const Vec3& x0, const Vec3& v0, const Vec3& g, Real h, int n) {
  return {x0 + Real(n) * h * v0 + h * h * g * (Real(n) * Real(n + 1) / 2), v0 + Real(n) * h * g};
}

/// Steps `body` n times and checks every step against the closed form; returns the worst relative errors.
void checkTrajectory(TestWorld& w, const RigidBodyRef& body, const Vec3& x0, const Vec3& v0, int n,
                     Real& worstX, Real& worstV) {
  const Vec3 g = w.sim->getUniformGravity();
  worstX = worstV = 0;
  for (int i = 1; i <= n; ++i) {
    w.sim->stepForward();
    const Expect e = closedForm(x0, v0, g, w.dt, i);
    // Scale: the position magnitude plus the distance travelled (never zero: x0 is away from the origin).
    const Real scaleX = x0.norm() + (e.x - x0).norm();
    const Real scaleV = v0.norm() + (e.v - v0).norm();
    worstX = std::max(worstX, (body->getCmPosition() - e.x).norm() / scaleX);
    worstV = std::max(worstV, (body->getVelocity() - e.v).norm() / scaleV);
  }
}

}  // namespace

TEST_SUITE("solver") {

TEST_CASE("free fall follows the semi-implicit Euler closed form to 1e-9") {
  TestWorld w(1.0 / 60.0);  // no ground: nothing to collide with
  const Vec3 x0(0.3, -0.2, 100.0), v0 = Vec3::Zero();
  auto ball = w.addSphere(0.1, x0, 2.0);
  Real ex = 0, ev = 0;
  checkTrajectory(w, ball, x0, v0, 600, ex, ev);
  MESSAGE("free fall, 600 steps at 1/60: worst relative error x " << ex << ", v " << ev);
  CHECK(ex <= 1e-9);
  CHECK(ev <= 1e-9);
  CHECK(w.time() == doctest::Approx(10.0).epsilon(1e-12));
}

TEST_CASE("projectile follows the semi-implicit Euler closed form to 1e-9") {
  TestWorld w(1.0 / 100.0);
  const Vec3 x0(1.0, 2.0, 3.0), v0(3.0, 1.0, 8.0);
  auto ball = w.addSphere(0.1, x0, 0.5);
  ball->setVelocity(v0);
  Real ex = 0, ev = 0;
  checkTrajectory(w, ball, x0, v0, 1200, ex, ev);
  MESSAGE("projectile, 1200 steps at 1/100: worst relative error x " << ex << ", v " << ev);
  CHECK(ex <= 1e-9);
  CHECK(ev <= 1e-9);
}

TEST_CASE("a spinning box's centre of mass follows the same closed form") {
  // Rotation must not leak into the translation: the COM of a tumbling box is a projectile too.
  TestWorld w(1.0 / 60.0);
  const Vec3 x0(-4.0, 0.5, 20.0), v0(-2.0, 0.0, 12.0);
  auto box = w.addBox(Vec3(0.5, 0.2, 0.1), x0, 3.0);
  box->setVelocity(v0);
  box->setAngularVelocity(Vec3(1.0, 7.0, -3.0));
  Real ex = 0, ev = 0;
  checkTrajectory(w, box, x0, v0, 300, ex, ev);
  MESSAGE("tumbling box, 300 steps: worst relative error x " << ex << ", v " << ev);
  CHECK(ex <= 1e-9);
  CHECK(ev <= 1e-9);
}

}  // TEST_SUITE
