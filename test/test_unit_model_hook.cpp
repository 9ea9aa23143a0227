// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The Model hook (scree/solver/model.h): a model installs bodies, geometries, constraints and listeners when it
// is added, and removing it leaves the simulation as it was before, to the bit.
#include <doctest/doctest.h>

#include "test_world.h"

using namespace scree;

namespace {

struct CountingListener : StepEventListener {
  int steps = 0;
  void post(const TimeStamp&) override { ++steps; }
};

// A model with one of everything: a pendulum bob on a ball joint to the world, a static ledge, a step listener
// that counts steps and a contact listener that removes every contact of its ledge.
struct EverythingModel : Model {
  RigidBodyRef bob = std::make_shared<RigidBody>("bob");
  GeometryRef ledge = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.5, 0.5, 0.1)));
  ConstraintRef joint;
  std::shared_ptr<CountingListener> counter = std::make_shared<CountingListener>();
  ContactEventListenerRef remover = std::make_shared<ContactEventListener>();
  bool failInOnAdd = false;
  int removedCalls = 0;

  EverythingModel() : Model("everything") {
    bob->add(std::make_shared<Geometry>(std::make_shared<Sphere>(0.1)));
    bob->setPosition(Vec3(5, 0, 2));
    ledge->setPosition(Vec3(5, 3, 0.5));
    joint = std::make_shared<BallJoint>(bob, nullptr, Vec3(5.5, 0, 2.5));
    // PGS like the contacts: a direct-set row would change how the step splits its sweeps between the direct
    // and iterative rounds (Solver::setNumHybridRounds), and so the unrelated box's trajectory by rounding,
    // which this test must not confuse with a hook that leaves something behind.
    joint->setSolveType(FrictionModel::ITERATIVE);
  }
  void onAdd(Simulation&) override {
    addOwned(bob);
    addOwned(ledge);
    addOwned(joint);
    addOwned(StepEventListenerRef(counter));
    addOwned(remover);
    if (failInOnAdd) throw std::invalid_argument("EverythingModel: failInOnAdd");
  }
  void onRemove(Simulation&) override { ++removedCalls; }
};

using Snapshot = test::SimulationCounts;
inline Snapshot snapshot(const Simulation& sim) { return test::countsOf(sim); }

}  // namespace

TEST_SUITE("model hook") {
  TEST_CASE("a model added and removed leaves the simulation as it was, to the bit") {
    // Two identical worlds with a box falling onto the ground; one gets the model for 30 steps, then loses it.
    test::TestWorld a, b;
    a.addGround();
    b.addGround();
    auto boxA = a.addBox(Vec3(0.2, 0.2, 0.2), Vec3(0, 0, 1.0));
    auto boxB = b.addBox(Vec3(0.2, 0.2, 0.2), Vec3(0, 0, 1.0));
    const Snapshot before = snapshot(*a.sim);

    auto model = std::make_shared<EverythingModel>();
    a.sim->add(model);
    CHECK(model->getSimulation() == a.sim.get());
    CHECK(model->getNumOwned() == 5);
    const Snapshot with = snapshot(*a.sim);
    CHECK(with.bodies == before.bodies + 1);
    CHECK(with.geometries == before.geometries + 1);
    CHECK(with.constraints == before.constraints + 1);
    CHECK(with.stepListeners == before.stepListeners + 1);
    CHECK(with.contactListeners == before.contactListeners + 1);
    CHECK(with.models == before.models + 1);
    a.sim->add(model);  // twice: no-op
    CHECK(snapshot(*a.sim) == with);

    for (int i = 0; i < 30; ++i) {
      a.sim->stepForward();
      b.sim->stepForward();
    }
    CHECK(model->counter->steps == 30);
    // The model's pendulum swung: its bob moved away from where it was released.
    CHECK((model->bob->getPosition() - Vec3(5, 0, 2)).norm() > 1e-3);

    CHECK(a.sim->remove(model));
    CHECK(model->removedCalls == 1);
    CHECK(model->getSimulation() == nullptr);
    CHECK(model->getNumOwned() == 0);
    CHECK(snapshot(*a.sim) == before);
    CHECK(model->counter->getSimulation() == nullptr);
    CHECK_FALSE(a.sim->remove(model));

    for (int i = 0; i < 60; ++i) {
      a.sim->stepForward();
      b.sim->stepForward();
    }
    CHECK(model->counter->steps == 30);  // no longer called
    // The box never touched the model's items (other islands, all rows PGS), so both worlds agree exactly,
    // while the model was in and after it left.
    CHECK(boxA->getPosition() == boxB->getPosition());
    CHECK(boxA->getVelocity() == boxB->getVelocity());
    CHECK(boxA->getRotation().coeffs() == boxB->getRotation().coeffs());
  }

  TEST_CASE("a model re-added after removal installs everything again") {
    test::TestWorld w;
    auto model = std::make_shared<EverythingModel>();
    w.sim->add(model);
    w.sim->remove(model);
    w.sim->add(model);
    CHECK(model->getNumOwned() == 5);
    CHECK(w.sim->getConstraints().size() == 1);
    w.sim->stepForward();
    CHECK(model->counter->steps == 1);
  }

  TEST_CASE("a model in another simulation, a null model and a failing onAdd leave the simulation unchanged") {
    test::TestWorld a, b;
    auto model = std::make_shared<EverythingModel>();
    a.sim->add(model);
    const Snapshot sb = snapshot(*b.sim);
    CHECK_THROWS_AS(b.sim->add(model), std::invalid_argument);
    CHECK(snapshot(*b.sim) == sb);
    CHECK(model->getSimulation() == a.sim.get());
    CHECK_THROWS_AS(b.sim->add(ModelRef()), std::invalid_argument);

    auto failing = std::make_shared<EverythingModel>();
    failing->failInOnAdd = true;
    CHECK_THROWS_AS(b.sim->add(failing), std::invalid_argument);
    CHECK(snapshot(*b.sim) == sb);
    CHECK(failing->getSimulation() == nullptr);
    CHECK(failing->getNumOwned() == 0);
  }

  TEST_CASE("a simulation destroyed with a model in it releases the model") {
    auto model = std::make_shared<EverythingModel>();
    {
      test::TestWorld w;
      w.sim->add(model);
    }
    CHECK(model->getSimulation() == nullptr);
    CHECK(model->getNumOwned() == 0);
  }
}
