// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The three models on the Model hook (scree/solver/model.h): TwoBodyTireModel, SuctionGripper and
// GranularFieldStepListener. For each: added, it installs exactly its items (counted in the simulation's lists);
// removed, the lists are as before the model came, the model is released, and a box dropped afterwards moves to
// the bit as in a twin simulation that never had the model (nothing left behind in the step's caches either).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "test_world.h"

using namespace scree;
using scree::test::TestWorld;

namespace {

using Snapshot = test::SimulationCounts;
inline Snapshot snapshot(const Simulation& sim) { return test::countsOf(sim); }

bool contains(const std::vector<RigidBodyRef>& list, const RigidBodyRef& b) {
  return std::find(list.begin(), list.end(), b) != list.end();
}

/// Steps both worlds n times.
void stepBoth(TestWorld& a, TestWorld& b, int n) {
  for (int i = 0; i < n; ++i) {
    a.sim->stepForward();
    b.sim->stepForward();
  }
}

/// Drops the same fresh box onto the ground of both worlds, away from everything else, and requires that its
/// motion agrees exactly: the world that had the model must step like the one that never had it.
void checkBystanderAgrees(TestWorld& had, TestWorld& never) {
  auto boxA = had.addBox(Vec3(0.2, 0.2, 0.2), Vec3(20, 20, 0.6));
  auto boxB = never.addBox(Vec3(0.2, 0.2, 0.2), Vec3(20, 20, 0.6));
  boxA->setAngularVelocity(Vec3(0.3, -0.2, 0.1));  // lands on an edge: several contact points, friction
  boxB->setAngularVelocity(Vec3(0.3, -0.2, 0.1));
  stepBoth(had, never, 90);
  CHECK(boxA->getPosition().z() < 0.25);  // it landed (rests at 0.2)
  CHECK(boxA->getPosition() == boxB->getPosition());
  CHECK(boxA->getVelocity() == boxB->getVelocity());
  CHECK(boxA->getRotation().coeffs() == boxB->getRotation().coeffs());
  CHECK(boxA->getAngularVelocity() == boxB->getAngularVelocity());
}

/// Tire and rim bodies (cylinders, axle along y) standing on the ground of `w`, added by the user.
struct Wheel {
  RigidBodyRef tire, rim;
  TwoBodyTireModelRef model;
  explicit Wheel(TestWorld& w) {
    auto body = [&](Real radius, Real mass) {
      auto b = std::make_shared<RigidBody>();
      auto g = std::make_shared<Geometry>(std::make_shared<Cylinder>(radius, 0.25));
      g->setMaterial(w.material);
      b->add(g);
      b->setMass(mass);
      b->setPosition(Vec3(0, 0, 0.45));
      w.sim->add(b);
      return b;
    };
    tire = body(0.45, 20);
    rim = body(0.3, 10);
    model = std::make_shared<TwoBodyTireModel>(tire, 0.45, rim, 0.3);
  }
};

constexpr Real kG = 9.81;
constexpr Real kLipZ = 0.95;  // lip plane of a cup mounted 5 cm below a holder at z = 1

/// A gripper whose static holder (not added by the user) carries one sealed cup 5 cm below it; vacuum 0.6
/// holds up to 0.6 * 101325 Pa * pi (2.5 cm)^2 / g = 12.2 kg.
struct GripperRig {
  SuctionGripperRef gripper = std::make_shared<SuctionGripper>();
  RigidBodyRef holder = std::make_shared<RigidBody>("holder");
  SuctionCupRef cup = std::make_shared<SuctionCup>(nullptr, 0.025, 0.01, 8, Vec3(0, 0, -0.1), 0.01);
  GripperRig() {
    holder->setMotionControl(RigidBody::STATIC);
    holder->setPosition(Vec3(0, 0, 1));
    gripper->setHolderRigidBody(holder);
    gripper->getVacuumSystem()->setDesiredVacuum(0.6);
    gripper->add(cup, Vec3(0, 0, -0.05));
  }
};

}  // namespace

TEST_SUITE("model add/remove") {
  TEST_CASE("TwoBodyTireModel: sim.add(tire) installs its constraint and one listener, sim.remove(tire) all of it") {
    TestWorld a, b;
    a.addGround();
    b.addGround();
    Wheel wheel(a);
    const Snapshot before = snapshot(*a.sim);

    a.sim->add(wheel.model);  // the Model path (Simulation's template for Model types)
    Snapshot with = before;
    ++with.constraints;
    ++with.contactListeners;
    ++with.models;
    CHECK(snapshot(*a.sim) == with);
    CHECK(wheel.model->getSimulation() == a.sim.get());
    CHECK(wheel.model->getNumOwned() == 2);  // the constraint and its friction listener
    // Adding it again, by either path, installs nothing twice.
    a.sim->add(wheel.model);
    a.sim->add(ConstraintRef(wheel.model));
    CHECK(snapshot(*a.sim) == with);

    stepBoth(a, b, 30);
    CHECK(wheel.model->getRadialDeflection() > 1e-5);  // the tire carries the rim's weight

    CHECK(a.sim->remove(wheel.model));
    CHECK(snapshot(*a.sim) == before);
    CHECK(wheel.model->getSimulation() == nullptr);
    CHECK(wheel.model->getNumOwned() == 0);
    CHECK(contains(a.sim->getRigidBodies(), wheel.tire));  // the user's bodies stay
    CHECK(contains(a.sim->getRigidBodies(), wheel.rim));
    CHECK_FALSE(a.sim->remove(wheel.model));

    // Without its bodies the world is the twin's again.
    a.sim->remove(wheel.tire);
    a.sim->remove(wheel.rim);
    stepBoth(a, b, 1);
    checkBystanderAgrees(a, b);
  }

  TEST_CASE("TwoBodyTireModel added as a plain ConstraintRef: constraint and listener, no model; mixing adds no copy") {
    TestWorld w;
    w.addGround();
    Wheel wheel(w);
    const Snapshot before = snapshot(*w.sim);
    const ConstraintRef asConstraint = wheel.model;

    w.sim->add(asConstraint);
    Snapshot plain = before;
    ++plain.constraints;
    ++plain.contactListeners;
    CHECK(snapshot(*w.sim) == plain);
    CHECK(wheel.model->getSimulation() == nullptr);  // not recorded as a model
    CHECK(w.sim->remove(asConstraint));
    CHECK(snapshot(*w.sim) == before);

    // Plain first, then as a model: the model is recorded, the listener is still there once.
    w.sim->add(asConstraint);
    w.sim->add(wheel.model);
    ++plain.models;
    CHECK(snapshot(*w.sim) == plain);
    w.steps(2);
    CHECK(w.sim->remove(wheel.model));
    CHECK(snapshot(*w.sim) == before);
  }

  TEST_CASE("SuctionGripper: removing it takes out its bodies, lock joint and listeners; the held box falls freely") {
    TestWorld a(1.0 / 60, kG), b(1.0 / 60, kG);
    a.addGround();  // 85 cm below the box: 20 steps of free fall (57 cm) do not reach it
    b.addGround();
    auto box = a.addBox(Vec3(0.1, 0.1, 0.05), Vec3(0, 0, kLipZ - 0.05), 6.0);  // half the payload: held
    const Snapshot before = snapshot(*a.sim);

    GripperRig rig;
    a.sim->add(rig.gripper);  // installed at once, not at the next step
    Snapshot with = before;
    with.bodies += 2;        // holder and cup
    with.constraints += 1;   // the cup's lock to the holder
    with.stepListeners += 1;  // the gripper
    with.contactListeners += 1;  // its sensor listener
    with.models += 1;
    CHECK(snapshot(*a.sim) == with);
    CHECK(rig.gripper->getSimulation() == a.sim.get());

    stepBoth(a, b, 60);
    CHECK(std::abs(box->getPosition().z() - (kLipZ - 0.05)) < 1e-3);  // held against the lip
    CHECK(rig.cup->isSealed());
    CHECK(rig.cup->getRigidBody()->getMotionControl() == RigidBody::KINEMATICS);  // exact mount on a static holder

    CHECK(a.sim->remove(rig.gripper));
    CHECK(snapshot(*a.sim) == before);
    CHECK_FALSE(contains(a.sim->getRigidBodies(), rig.holder));
    CHECK_FALSE(contains(a.sim->getRigidBodies(), rig.cup->getRigidBody()));
    CHECK(rig.gripper->getSimulation() == nullptr);
    CHECK(rig.gripper->getNumOwned() == 0);
    // Its changes to its own cup are undone: a dynamic body on an enabled lock again.
    CHECK(rig.cup->getRigidBody()->getMotionControl() == RigidBody::DYNAMICS);
    CHECK(rig.cup->getMountJoint()->getEnable());
    CHECK(rig.cup->getActiveInteractionsVector().empty());

    // Free fall from the state at removal. The step integrates v += g h, then x += v h (the integrator's
    // semi-implicit Euler), so after n steps: v_n = v0 - n g h, z_n = z0 + n h v0 - g h^2 n (n + 1) / 2. The box
    // was at rest against the lip, so v0 is tiny; the closed form holds to rounding.
    const Real h = a.sim->getTimeStep(), z0 = box->getPosition().z(), v0 = box->getVelocity().z();
    const int n = 20;
    for (int i = 0; i < n; ++i) a.sim->stepForward();
    const Real vn = v0 - n * kG * h, zn = z0 + n * h * v0 - kG * h * h * n * (n + 1) / 2;
    CHECK(box->getVelocity().z() == doctest::Approx(vn).epsilon(1e-12));
    CHECK(box->getPosition().z() == doctest::Approx(zn).epsilon(1e-12));
    CHECK(z0 - zn > 0.5);  // fell more than half a metre: nothing holds it any more
    CHECK(a.sim->getContacts().empty());

    for (int i = 0; i < n; ++i) b.sim->stepForward();  // keep the twins' step counts equal
    a.sim->remove(box);
    checkBystanderAgrees(a, b);
  }

  TEST_CASE("SuctionGripper: bodies the user added stay when the gripper is removed; it can be added again") {
    TestWorld w(1.0 / 60, kG);
    GripperRig rig;
    w.sim->add(rig.holder);  // the user's holder
    const Snapshot before = snapshot(*w.sim);
    w.sim->add(rig.gripper);
    CHECK(snapshot(*w.sim).bodies == before.bodies + 1);  // only the cup
    // A cup added while the gripper is in the simulation goes in at once, and out with the gripper.
    auto late = std::make_shared<SuctionCup>(nullptr, 0.025, 0.01, 8, Vec3(0, 0, -0.1), 0.01);
    rig.gripper->add(late, Vec3(0.2, 0, -0.05));
    CHECK(contains(w.sim->getRigidBodies(), late->getRigidBody()));
    CHECK(snapshot(*w.sim).constraints == before.constraints + 2);
    w.steps(3);

    CHECK(w.sim->remove(rig.gripper));
    CHECK(snapshot(*w.sim) == before);
    CHECK(contains(w.sim->getRigidBodies(), rig.holder));

    w.sim->add(rig.gripper);
    CHECK(snapshot(*w.sim).bodies == before.bodies + 2);
    CHECK(snapshot(*w.sim).constraints == before.constraints + 2);
    w.steps(1);
    CHECK(late->getRigidBody()->getMotionControl() == RigidBody::KINEMATICS);
    CHECK(w.sim->remove(rig.gripper));
    CHECK(snapshot(*w.sim) == before);
  }

  TEST_CASE("SuctionGripper added as a plain StepEventListenerRef installs itself through the hook at its first step") {
    TestWorld w(1.0 / 60, kG);
    const Snapshot before = snapshot(*w.sim);
    GripperRig rig;
    w.sim->add(StepEventListenerRef(rig.gripper));
    CHECK(snapshot(*w.sim).models == before.models);
    w.steps(1);
    CHECK(snapshot(*w.sim).models == before.models + 1);
    CHECK(snapshot(*w.sim).bodies == before.bodies + 2);
    CHECK(snapshot(*w.sim).stepListeners == before.stepListeners + 1);  // not twice
    CHECK(w.sim->remove(rig.gripper));
    CHECK(snapshot(*w.sim) == before);
  }

  TEST_CASE("GranularFieldStepListener: sim.add installs one step listener, sim.remove takes it out") {
    TestWorld a, b;
    a.addGround();
    b.addGround();
    GranularBodySystem& gbs = a.sim->getGranularBodySystem();
    auto gpp = std::make_shared<GranularFieldPostProcessor>(gbs, GranularFieldPostProcessor::Shape{4, 4, 4},
                                                            Vec3(1, 1, 1));
    gpp->addField(GranularField::MASS);
    size_t callbacks = 0;
    auto fields = std::make_shared<GranularFieldStepListener>(
        gpp, 2, [&](const GranularFieldPostProcessor&, size_t) { ++callbacks; });
    const Snapshot before = snapshot(*a.sim);

    a.sim->add(fields);
    Snapshot with = before;
    ++with.stepListeners;
    ++with.models;
    CHECK(snapshot(*a.sim) == with);
    CHECK(fields->getSimulation() == a.sim.get());
    stepBoth(a, b, 6);
    CHECK(fields->getNumSteps() == 6);
    CHECK(gpp->getNumCalculations() == 3);
    CHECK(callbacks == 3);

    CHECK(a.sim->remove(fields));
    CHECK(snapshot(*a.sim) == before);
    CHECK(fields->getSimulation() == nullptr);
    stepBoth(a, b, 4);
    CHECK(fields->getNumSteps() == 6);  // no longer called
    CHECK(gpp->getNumCalculations() == 3);
    checkBystanderAgrees(a, b);

    // As a plain StepEventListenerRef it is a listener as before: no model recorded.
    const Snapshot withBystander = snapshot(*a.sim);
    a.sim->add(StepEventListenerRef(fields));
    CHECK(snapshot(*a.sim).models == withBystander.models);
    CHECK(snapshot(*a.sim).stepListeners == withBystander.stepListeners + 1);
    a.sim->stepForward();
    CHECK(fields->getNumSteps() == 7);
    CHECK(a.sim->remove(StepEventListenerRef(fields)));
    CHECK(snapshot(*a.sim) == withBystander);
  }
}
