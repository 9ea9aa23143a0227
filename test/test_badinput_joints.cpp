// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Bad input for constraints, controllers, materials and the simulation: std::invalid_argument naming the
// parameter and the value, object unchanged.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

#include <scree/scree.h>

#include "test_badinput.h"

using namespace scree;
using namespace scree::test;

namespace {


RigidBodyRef body() {
  auto b = std::make_shared<RigidBody>();
  b->add(std::make_shared<Geometry>(std::make_shared<Sphere>(0.1)));
  return b;
}
}  // namespace

TEST_SUITE("badinput joints") {
  TEST_CASE("joint constructors refuse null, identical bodies and non-finite frames") {
    auto a = body(), b = body();
    expectInvalid([&] { Hinge(nullptr, b, Vec3::Zero(), Vec3::UnitZ()); }, "rigidBody1", "null");
    expectInvalid([&] { Hinge(a, a, Vec3::Zero(), Vec3::UnitZ()); }, "rigidBody2", "must differ");
    expectInvalid([&] { Hinge(a, b, Vec3(kNaN, 0, 0), Vec3::UnitZ()); }, "worldPoint", "nan");
    expectInvalid([&] { Hinge(a, b, Vec3::Zero(), Vec3::Zero()); }, "worldAxis", "(0, 0, 0)");
    expectInvalid([&] { Prismatic(a, b, Vec3::Zero(), Vec3(kInf, 0, 0)); }, "worldAxis", "inf");
    expectInvalid([&] { CylindricalJoint(a, b, Vec3::Zero(), Vec3::Zero()); }, "worldAxis", "(0, 0, 0)");
    expectInvalid([&] { BallJoint(a, b, Vec3(0, kInf, 0)); }, "worldPoint", "inf");
    expectInvalid([&] { DistanceJoint(a, b, Vec3::Zero(), Vec3::Zero()); }, "distance", "0");
    expectInvalid([&] { LockJoint(nullptr, b); }, "rigidBody1", "null");
  }

  TEST_CASE("constraint setters refuse bad values and keep the old ones") {
    auto a = body();
    Hinge h(a, nullptr, Vec3::Zero(), Vec3::UnitZ());
    h.setCompliance(1e-6);
    expectInvalid([&] { h.setCompliance(-1.0); }, "compliance", "-1");
    expectInvalid([&] { h.setCompliance(kNaN, 0); }, "compliance", "nan");
    expectInvalid([&] { h.setCompliance(1e-3, 99); }, "dof", "99");
    expectInvalid([&] { h.setDamping(-0.5); }, "damping", "-0.5");
    CHECK(h.getCompliance(0) == 1e-6);
    CHECK(h.getDamping(0) == doctest::Approx(2.0 / 60));

    h.getMotor1D().setSpeed(1.0);
    expectInvalid([&] { h.getMotor1D().setSpeed(kNaN); }, "speed", "nan");
    CHECK(h.getMotor1D().getSpeed() == 1.0);
    expectInvalid([&] { h.getMotor1D().setForceRange(5, -5); }, "lower", "5");
    expectInvalid([&] { h.getMotor1D().setForceRange(kNaN, 1); }, "lower", "nan");
    expectInvalid([&] { h.getMotor1D().setCompliance(-1); }, "compliance", "-1");
    expectInvalid([&] { h.getRange1D().setRange(1, 0); }, "lower", "1");
    expectInvalid([&] { h.getRange1D().setCompliance(kInf); }, "compliance", "inf");
    expectInvalid([&] { h.getLock1D().setPosition(kInf); }, "position", "inf");
    expectInvalid([&] { h.getLock1D().setDamping(-1); }, "damping", "-1");

    Generic6DofJoint g(a, nullptr, Vec3::Zero());
    expectInvalid([&] { g.setStiffness(Generic6DofJoint::ROTATIONAL_1, 0.0, 1.0); }, "stiffness", "0");
    expectInvalid([&] { g.setStiffness(Generic6DofJoint::ROTATIONAL_1, 10.0, -1.0); }, "dampingCoefficient", "-1");
    expectInvalid([&] { g.setStiffness(6, 10.0, 1.0); }, "dof", "6");
    CHECK(g.getMode(Generic6DofJoint::ROTATIONAL_1) == Generic6DofJoint::LOCKED);

    DistanceJoint d(a, nullptr, Vec3::Zero(), Vec3(1, 0, 0));
    expectInvalid([&] { d.setRestLength(-2); }, "length", "-2");
    CHECK(d.getRestLength() == doctest::Approx(1.0));
  }

  TEST_CASE("materials, solver and simulation refuse bad values") {
    Material m("m");
    expectInvalid([&] { m.setDensity(-1); }, "density", "-1");
    expectInvalid([&] { m.setYoungsModulus(0); }, "youngsModulus", "0");
    expectInvalid([&] { m.setRestitution(1.5); }, "restitution", "1.5");
    expectInvalid([&] { m.setFrictionCoefficient(kNaN); }, "frictionCoefficient", "nan");
    expectInvalid([&] { m.setAdhesion(-1, 0); }, "adhesiveForce", "-1");
    expectInvalid([&] { m.setAdhesion(1, -0.1); }, "adhesiveOverlap", "-0.1");
    expectInvalid([&] { m.setSurfaceViscosity(-1e-9); }, "surfaceViscosity", "-1e-09");
    expectInvalid([&] { m.setRollingResistanceCoefficient(kNaN); }, "rollingResistanceCoefficient", "nan");
    expectInvalid([&] { m.setDamping(kInf); }, "damping", "inf");
    CHECK(m.getDensity() == 1000);
    CHECK(m.getYoungsModulus() == 4e8);
    CHECK(m.getRestitution() == 0.5);

    Simulation sim;
    expectInvalid([&] { sim.setTimeStep(0); }, "timeStep", "0");
    expectInvalid([&] { sim.setTimeStep(kNaN); }, "timeStep", "nan");
    expectInvalid([&] { sim.setUniformGravity(Vec3(0, kInf, 0)); }, "gravity", "inf");
    expectInvalid([&] { sim.getSolver().setNumIterations(0); }, "numIterations", "0");
    CHECK(sim.getTimeStep() == doctest::Approx(1.0 / 60));
    CHECK(sim.getSolver().getNumIterations() == 16);
    expectInvalid([&] { sim.add(RigidBodyRef()); }, "rigidBody", "null");
    expectInvalid([&] { sim.add(ConstraintRef()); }, "constraint", "null");

    RigidBody b("b");
    expectInvalid([&] { b.setMass(0); }, "mass", "0");
    expectInvalid([&] { b.setPosition(Vec3(kNaN, 0, 0)); }, "position", "nan");
    expectInvalid([&] { b.setVelocity(Vec3(0, 0, kInf)); }, "velocity", "inf");
    expectInvalid([&] { b.setRotation(Quat(0, 0, 0, 0)); }, "rotation", "w=0");
    expectInvalid([&] { b.setInertiaTensor(Vec3(1, 1, 5).asDiagonal()); }, "inertia", "triangle");
    expectInvalid([&] { b.setInertiaTensor(-Mat3::Identity()); }, "inertia", "positive");
    expectInvalid([&] { b.addForce(Vec3(kNaN, 0, 0)); }, "force", "nan");
    expectInvalid([&] { b.setLinearVelocityDamping(-1); }, "damping", "-1");
    CHECK(b.getMass() == 1);
    CHECK(b.getPosition() == Vec3::Zero());
  }

  TEST_CASE("a step that goes non-finite names the body and does not spread NaN") {
    Simulation sim;
    auto b = std::make_shared<RigidBody>("victim");
    b->add(std::make_shared<Geometry>(std::make_shared<Sphere>(0.1)));
    sim.add(b);
    // A force that overflows to inf after multiplication by h / m: finite on input, infinite in the step.
    b->addForce(Vec3(1e308, 0, 0));
    b->addForce(Vec3(1e308, 0, 0));
    sim.stepForward();
    const auto& rep = sim.getLastStepReport();
    REQUIRE(rep.nonFiniteBodies.size() == 1);
    CHECK(rep.nonFiniteBodies[0] == b->getId());
    CHECK(rep.messages[0].find("victim") != std::string::npos);
    CHECK(b->getPosition().allFinite());
    CHECK(b->getVelocity().allFinite());
  }
}
