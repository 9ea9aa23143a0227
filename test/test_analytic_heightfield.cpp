// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Bodies on a height field behave as on flat ground when the field is flat: same resting depth, same Coulomb
// sliding distance (the discrete closed form of the slide scene), no sideways drift across triangle seams.
#include <doctest/doctest.h>

#include <cmath>

#include "test_world.h"

using namespace scree;
using namespace scree::test;

namespace {
// A flat 40 x 40 m height field with 0.5 m cells (diagonal seams under the box all the way), top at z = 0.
GeometryRef addFlatField(TestWorld& w) {
  auto hf = std::make_shared<HeightField>(81, 81, 40.0, 40.0);
  auto g = std::make_shared<Geometry>(hf);
  g->setMaterial(w.material);
  w.sim->add(g);
  return g;
}
}  // namespace

TEST_SUITE("height field") {
  TEST_CASE("a box sliding on a flat height field stops where it stops on flat ground") {
    // Discrete floor as in test_analytic_friction: x = 4.2056 m for v0 = 5, mu = 0.3, h = 1/60 (-0.98 % of
    // v^2/(2 mu g)); the field must not add anything: 0.5 % (one step of travel near the stop is 0.5 mm).
    TestWorld w(1.0 / 60, 9.81, 0.3);
    addFlatField(w);
    auto box = w.addBox(Vec3(0.5, 0.5, 0.5), Vec3(-10, 0.25, 0.5), 1.0);
    box->setVelocity(Vec3(5, 0, 0));
    w.stepSeconds(3.0);
    const Real slid = box->getPosition().x() + 10;
    const Real expected = 25.0 / (2 * 0.3 * 9.81);
    MESSAGE("slid " << slid << " m on the height field (continuous " << expected << " m)");
    CHECK(std::abs(slid - expected) / expected < 0.02);
    CHECK(std::abs(box->getPosition().y() - 0.25) < 1e-3);
    CHECK(std::abs(box->getPosition().z() - 0.5) < 1e-3);
  }

  TEST_CASE("a sphere resting on a height field sinks m g / E") {
    TestWorld w(1.0 / 60, 9.81);
    w.contactMaterial->setYoungsModulus(1e5);
    addFlatField(w);
    // On a vertex, on a seam and inside a triangle.
    for (const Vec3& at : {Vec3(0, 0, 0), Vec3(0.25, 0.25, 0), Vec3(0.3, 0.1, 0)}) {
      auto ball = w.addSphere(0.1, at + Vec3(0, 0, 0.1), 1.0);
      w.stepSeconds(2.0);
      const Real depth = 0.1 - ball->getPosition().z();
      CAPTURE(at);
      // 2 %: SPOOK at rest gives exactly m g / E; the damped settling is complete after 2 s (tau = 0.075 s).
      CHECK(std::abs(depth - 9.81 / 1e5) / (9.81 / 1e5) < 0.02);
      CHECK(std::abs(ball->getPosition().x() - at.x()) < 1e-6);
      w.sim->remove(ball);
    }
  }
}
