// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// TwoBodyTireModel in contact (issue 6): a loaded wheel rolling at constant speed on flat ground, torsional
// wind-up of a wheel driven by a hinge motor against a load, and the friction frame on the tire's contacts.
//
// Rig: a kinematic carriage moving at constant speed along x; a carrier body on a vertical Prismatic under it
// (so the carrier's and rim's weight is the wheel load); the rim on a Hinge (axle y) in the carrier, optionally
// motor driven; the tire (a Cylinder, axis local y) joined to the rim by the tire model, on a ground plane.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "test_world.h"

using namespace scree;
using namespace scree::test;

namespace {
constexpr Real kR = 0.4;        // tire radius, m
constexpr Real kTireMass = 20;  // kg
constexpr Real kRimMass = 10;
constexpr Real kCarrierMass = 90;

struct Rig {
  TestWorld w;
  RigidBodyRef carriage, carrier, rim, tire;
  HingeRef axle;
  TwoBodyTireModelRef model;

  /// yaw: the whole rig turned about z (axle along q y, travel along q x).
  Rig(Real h, Real v, Real mu, Real yaw = 0) : w(h, 9.81, mu) {
    const Quat q(Eigen::AngleAxis<Real>(yaw, Vec3::UnitZ()));
    const Vec3 vel = q * Vec3(v, 0, 0), spin = q * Vec3(0, v / kR, 0);
    w.sim->getSolver().setNumIterations(40);
    auto plane = std::make_shared<Geometry>(std::make_shared<Plane>(Vec3::UnitZ(), 0.0));
    plane->setMaterial(w.material);
    w.sim->add(plane);

    const Vec3 c(0, 0, kR);
    auto make = [&](Real mass, const Vec3& inertia, RigidBody::MotionControl mc) {
      auto b = std::make_shared<RigidBody>();
      b->setMotionControl(mc);
      if (mc == RigidBody::DYNAMICS) {
        b->setMass(mass);
        b->setInertiaTensor(inertia.asDiagonal());
      }
      b->setPosition(c);
      b->setRotation(q);
      b->setVelocity(vel);
      w.sim->add(b);
      return b;
    };
    carriage = make(0, Vec3::Zero(), RigidBody::KINEMATICS);
    carrier = make(kCarrierMass, Vec3(5, 5, 5), RigidBody::DYNAMICS);
    rim = make(kRimMass, Vec3(0.3, 0.5, 0.3), RigidBody::DYNAMICS);

    tire = std::make_shared<RigidBody>("tire");
    auto geom = std::make_shared<Geometry>(std::make_shared<Cylinder>(kR, 0.25));
    geom->setMaterial(w.material);
    tire->add(geom);
    tire->setMass(kTireMass);
    tire->setPosition(c);
    tire->setRotation(q);
    tire->setVelocity(vel);
    w.sim->add(tire);
    for (auto& b : {rim, tire}) b->setAngularVelocity(spin);  // rolling without slip

    w.sim->add(std::make_shared<Prismatic>(carrier, carriage, c, Vec3::UnitZ()));
    axle = std::make_shared<Hinge>(rim, carrier, c, q * Vec3::UnitY());
    w.sim->add(axle);
    model = std::make_shared<TwoBodyTireModel>(tire, kR, rim, 0.25);
    w.sim->add(model);
  }
};

struct Averages {
  Real radial = 0, torsion = 0, torsionForce = 0, spin = 0, vx = 0;
};
// Steps `seconds`, then averages the read-outs over `window` seconds.
Averages run(Rig& r, Real seconds, Real window) {
  r.w.stepSeconds(seconds);
  Averages a;
  const int n = int(std::lround(window / r.w.dt));
  for (int i = 0; i < n; ++i) {
    r.w.sim->stepForward();
    a.radial += r.model->getRadialDeflection() / n;
    a.torsion += r.model->getTorsionAngle() / n;
    a.torsionForce += r.model->getForce(TwoBodyTireModel::TORSIONAL) / n;
    a.spin += r.tire->getAngularVelocity().y() / n;
    a.vx += r.tire->getVelocity().x() / n;
  }
  return a;
}
}  // namespace

TEST_SUITE("tire") {
  TEST_CASE("a loaded wheel rolling at constant speed: radial deflection = load / k, v = omega r") {
    // The load through the tire model is the carrier's and rim's weight (the tire's own weight goes straight
    // to the ground). Rolling freely at constant speed there is no traction, so the radial force is that
    // weight; contact compliance (4e8 N/m per point) changes the rolling radius by ~1e-6 m. 2 % is the issue's
    // bound; averaged over 0.5 s (several tire-contact periods) the result is within ~1e-3.
    const Real v = 2.0, h = 1.0 / 400;
    Rig r(h, v, 0.8);
    const Averages a = run(r, 1.5, 0.5);
    const Real load = (kCarrierMass + kRimMass) * 9.81;
    const Real expect = load / r.model->getStiffness(TwoBodyTireModel::RADIAL);
    MESSAGE("rolling: radial deflection " << a.radial << " m, load/k " << expect << ", rel err "
                                          << (a.radial - expect) / expect << "; omega r / v = " << a.spin * kR / v);
    CHECK(std::abs(a.radial - expect) / expect < 0.02);
    CHECK(std::abs(a.spin * kR - v) / v < 0.005);
    CHECK(std::abs(a.vx - v) / v < 1e-3);
    CHECK(std::abs(a.torsion) < 1e-3 * 500 / r.model->getStiffness(TwoBodyTireModel::TORSIONAL));
    CHECK(r.w.finite());
  }

  TEST_CASE("a wheel driven by a hinge motor against a load: torsional wind-up = transmitted torque / k") {
    // The motor asks for more spin than rolling at the carriage's speed allows, so it saturates at its torque
    // limit M; traction M / r = 250 N stays far below mu N = 0.8 * 1177 N, so the tire rolls without slip and
    // the whole torque goes through the torsional spring: wind-up = -M / k (the tire lags the rim).
    // Every solve type of the tire and axle rows (the default is DIRECT_AND_ITERATIVE; the hybrid split once got
    // this 4.7 % off when the direct rows left out the kinematic carriage's velocity) meets the same closed form.
    const Real h = 1.0 / 400, M = 100, kt = 2e4;
    for (const auto type : {FrictionModel::DIRECT_AND_ITERATIVE, FrictionModel::DIRECT, FrictionModel::ITERATIVE,
                            FrictionModel::SPLIT})
    for (const Real v : {0.0, 2.0}) {
      CAPTURE(v);
      CAPTURE(int(type));
      Rig r(h, v, 0.8);
      CHECK(r.model->getSolveType() == FrictionModel::DIRECT_AND_ITERATIVE);  // the default
      r.model->setSolveType(type);
      r.axle->setSolveType(type);
      r.model->setStiffness(kt, TwoBodyTireModel::TORSIONAL);
      r.model->setDamping(500, TwoBodyTireModel::TORSIONAL);
      Motor1D& motor = r.axle->getMotor1D();
      motor.setEnable(true);
      motor.setSpeed(v / kR + 5.0);
      motor.setForceRange(-M, M);
      const Averages a = run(r, 1.5, 0.5);
      MESSAGE("v " << v << ": motor torque " << motor.getCurrentForce() << " N m, wind-up " << a.torsion
                   << " rad, -M/k " << -M / kt << ", rel err " << (a.torsion + M / kt) / (M / kt)
                   << ", torsional torque " << a.torsionForce);
      CHECK(std::abs(motor.getCurrentForce() - M) / M < 1e-6);
      CHECK(std::abs(a.torsion + M / kt) / (M / kt) < 0.02);
      CHECK(std::abs(a.torsionForce - M) / M < 0.02);  // the spring pulls the tire forward
      CHECK(std::abs(a.spin * kR - v) < 0.01 + 0.005 * v);
    }
  }

  TEST_CASE("tire contacts get their primary friction direction along the rolling direction") {
    // Axle turned 30 degrees about z: the rolling direction is axle x normal = (cos 30, sin 30, 0) up to sign.
    const Real yaw = M_PI / 6;
    Rig r(1.0 / 400, 1.0, 0.8, yaw);
    r.w.steps(40);
    std::vector<ContactPoint> pts;
    for (const GeometryContact& c : r.w.sim->getContacts())
      if (c.rigidBody(0) == r.tire.get() || c.rigidBody(1) == r.tire.get())
        for (const ContactPoint& p : c.points()) pts.push_back(p);
    REQUIRE(!pts.empty());
    for (const ContactPoint& p : pts) {
      const Vec3 d = p.frictionDirection.normalized();
      CHECK(std::abs(std::abs(d.dot(Vec3(std::cos(yaw), std::sin(yaw), 0))) - 1) < 1e-9);
    }
    r.model->setEnableFrictionAlignment(false);
    r.w.steps(1);
    for (const GeometryContact& c : r.w.sim->getContacts())
      for (const ContactPoint& p : c.points()) CHECK(p.frictionDirection == Vec3::Zero());
  }

  TEST_CASE("the solver's first friction row follows ContactPoint::frictionDirection (box friction)") {
    // A box sliding diagonally at 45 degrees on a plane with BOX friction (each row bounded by mu N on its own):
    // in the default basis (x, y for a z normal) both rows saturate and the box decelerates at sqrt(2) mu g;
    // with the primary direction along the velocity one row carries mu N and the other none, so it decelerates
    // at mu g and stops after v0^2 / (2 mu g). Tolerance 1 %: stepping error of the stopping distance at
    // h = 1/1000 over 0.7 s is O(v0 h) = 3e-3 m of 1.5 m; the contact's surface viscosity adds < 1e-6.
    struct Align : ContactEventListener {
      Vec3 dir;
      KeepContactPolicy contact(const TimeStamp&, GeometryContact& c) override {
        for (ContactPoint& p : c.points()) p.frictionDirection = dir;
        return KEEP_CONTACT;
      }
      KeepContactPolicy impact(const TimeStamp& t, GeometryContact& c) override { return contact(t, c); }
    };
    const Real mu = 0.3, v0 = 3.0, g = 9.81;
    const Vec3 u = Vec3(1, 1, 0).normalized();
    for (const bool aligned : {false, true}) {
      CAPTURE(aligned);
      TestWorld w(1.0 / 1000, g, mu);
      w.contactMaterial->setFrictionModel(std::make_shared<FrictionModel>(FrictionModel::BOX));
      w.addGround();
      auto box = w.addBox(Vec3(0.2, 0.2, 0.2), Vec3(0, 0, 0.2), 1.0);
      auto l = std::make_shared<Align>();
      l->dir = aligned ? u : Vec3::Zero();
      w.sim->add(l);
      w.steps(20);  // settle on the ground
      box->setVelocity(v0 * u);
      const Vec3 p0 = box->getPosition();
      w.stepSeconds(2.0);
      const Vec3 d = box->getPosition() - p0;
      const Real expect = v0 * v0 / (2 * mu * g * (aligned ? 1.0 : std::sqrt(2.0)));
      MESSAGE((aligned ? "aligned" : "default") << " basis: slid " << d.norm() << " m, expected " << expect);
      CHECK(std::abs(d.norm() - expect) / expect < 0.01);
      CHECK(std::abs(d.normalized().dot(u) - 1) < 1e-6);
    }
  }

  TEST_CASE("tire and rim do not collide while the model is simulated; removing it restores collisions") {
    TestWorld w(1.0 / 60, 0.0);
    auto body = [&](Real radius) {
      auto b = std::make_shared<RigidBody>();
      auto g = std::make_shared<Geometry>(std::make_shared<Cylinder>(radius, 0.25));
      g->setMaterial(w.material);
      b->add(g);
      w.sim->add(b);
      return b;
    };
    auto tire = body(0.4), rim = body(0.3);  // overlapping at the origin
    auto model = std::make_shared<TwoBodyTireModel>(tire, 0.4, rim, 0.3);
    w.sim->add(model);
    w.steps(2);
    CHECK(w.sim->getContacts().empty());
    CHECK(w.sim->remove(model));
    w.steps(1);
    CHECK_FALSE(w.sim->getContacts().empty());
    for (const GeometryContact& c : w.sim->getContacts())
      for (const ContactPoint& p : c.points()) CHECK(p.frictionDirection == Vec3::Zero());  // listener gone
  }
}
