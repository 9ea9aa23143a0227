// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Bad input for TwoBodyTireModel (issue 6): std::invalid_argument naming the parameter and the value, and the
// model unchanged after a refused setter.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

#include <scree/scree.h>

#include "test_badinput.h"

using namespace scree;
using namespace scree::test;

namespace {


RigidBodyRef body(const std::string& name) {
  auto b = std::make_shared<RigidBody>(name);
  b->setMass(10);
  return b;
}
}  // namespace

TEST_SUITE("badinput tire") {
  TEST_CASE("TwoBodyTireModel refuses null or identical bodies, non-positive radii and a bad axis") {
    auto tire = body("tire"), rim = body("rim");
    expectInvalid([&] { TwoBodyTireModel(nullptr, 0.5, rim, 0.3); }, "tireBody", "null");
    expectInvalid([&] { TwoBodyTireModel(tire, 0.5, nullptr, 0.3); }, "rimBody", "null");
    expectInvalid([&] { TwoBodyTireModel(tire, 0.5, tire, 0.3); }, "rimBody", "tire");
    expectInvalid([&] { TwoBodyTireModel(tire, 0, rim, 0.3); }, "tireRadius", "0");
    expectInvalid([&] { TwoBodyTireModel(tire, -0.5, rim, 0.3); }, "tireRadius", "-0.5");
    expectInvalid([&] { TwoBodyTireModel(tire, kNaN, rim, 0.3); }, "tireRadius", "nan");
    expectInvalid([&] { TwoBodyTireModel(tire, kInf, rim, 0.3); }, "tireRadius", "inf");
    expectInvalid([&] { TwoBodyTireModel(tire, 0.5, rim, 0); }, "rimRadius", "0");
    expectInvalid([&] { TwoBodyTireModel(tire, 0.5, rim, -2); }, "rimRadius", "-2");
    expectInvalid([&] { TwoBodyTireModel(tire, 0.5, rim, 0.3, Vec3::Zero()); }, "localRotationAxis", "(0, 0, 0)");
    expectInvalid([&] { TwoBodyTireModel(tire, 0.5, rim, 0.3, Vec3(kNaN, 1, 0)); }, "localRotationAxis", "nan");
    CHECK_NOTHROW(TwoBodyTireModel(tire, 0.5, rim, 0.3, Vec3(0, 0, 2)));
  }

  TEST_CASE("setStiffness and setDamping refuse negative, zero stiffness, non-finite values and bad modes") {
    auto tire = body("tire"), rim = body("rim");
    TwoBodyTireModel m(tire, 0.5, rim, 0.3);
    using M = TwoBodyTireModel;
    for (M::DeformationMode mode : {M::RADIAL, M::LATERAL, M::BENDING, M::TORSIONAL}) {
      CAPTURE(int(mode));
      const Real k0 = m.getStiffness(mode), d0 = m.getDamping(mode);
      expectInvalid([&] { m.setStiffness(-1e5, mode); }, "stiffness", "-1e+05");
      expectInvalid([&] { m.setStiffness(0, mode); }, "stiffness", "0");
      expectInvalid([&] { m.setStiffness(kNaN, mode); }, "stiffness", "nan");
      expectInvalid([&] { m.setStiffness(kInf, mode); }, "stiffness", "inf");
      expectInvalid([&] { m.setDamping(-3, mode); }, "damping", "-3");
      expectInvalid([&] { m.setDamping(kNaN, mode); }, "damping", "nan");
      CHECK(m.getStiffness(mode) == k0);
      CHECK(m.getDamping(mode) == d0);
      CHECK_NOTHROW(m.setDamping(0, mode));  // an undamped spring is allowed
    }
    expectInvalid([&] { m.setStiffness(1e5, M::DeformationMode(7)); }, "mode", "7");
    expectInvalid([&] { m.setDamping(1e3, M::DeformationMode(5)); }, "mode", "5");
    expectInvalid([&] { (void)m.getDeformation(M::NUM_MODES); }, "mode", "4");
    CHECK(m.getStiffness(M::RADIAL) == 3.5e5);
  }
}
