// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Tunnelling: at 100 m/s and h = 1/60 a sphere of radius 0.1 m moves 1.67 m per step, 8x its diameter and 83x
// the 2 cm wall's thickness. Discrete collision detection alone would miss the wall entirely; speculative
// contacts (AABBs grown by the motion over the step, solved as non-penetration of the gap) must stop it.
// "Does not pass": the centre never reaches the wall's mid-plane and ends on the near side. The bound on how
// deep the sphere may sink into the wall face (2 cm, the wall's thickness) only keeps the check meaningful;
// with speculative contacts the expected overlap is ~0.
#include <doctest/doctest.h>

#include <cmath>

#include "test_world.h"

using namespace scree;
using scree::test::TestWorld;

TEST_SUITE("solver") {

TEST_CASE("a sphere at 100 m/s does not pass a 2 cm static wall at dt 1/60") {
  for (Real e : {0.0, 0.5}) {
    CAPTURE(e);
    TestWorld w(1.0 / 60.0, 0.0, 0.5, e);  // no gravity: the sphere flies straight at the wall
    const Real r = 0.1, wallX = 5.0, halfT = 0.01;
    w.addStaticBox(Vec3(halfT, 2.0, 2.0), Vec3(wallX, 0, 0));
    auto ball = w.addSphere(r, Vec3(0, 0, 0), 1.0);
    ball->setVelocity(Vec3(100, 0, 0));
    Real maxX = -1e9;
    for (int i = 0; i < 120; ++i) {
      w.sim->stepForward();
      maxX = std::max(maxX, ball->getPosition().x());
    }
    const Real nearFace = wallX - halfT;
    MESSAGE("restitution " << e << ": largest centre x " << maxX << " (near face at " << nearFace
                           << "), deepest overlap " << maxX + r - nearFace << " m, final x "
                           << ball->getPosition().x() << ", final vx " << ball->getVelocity().x());
    CHECK(w.finite());
    CHECK(maxX < wallX);                          // never past the mid-plane
    CHECK(maxX + r - nearFace < 2 * halfT);       // never sunk a wall thickness into the face
    CHECK(ball->getPosition().x() < nearFace);    // ends on the near side
    CHECK(ball->getVelocity().x() <= 1e-6);       // not moving through it
  }
}

}  // TEST_SUITE
