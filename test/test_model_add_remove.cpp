// The models on the Model hook (scree/solver/model.h): TwoBodyTireModel and GranularFieldStepListener. For
// each: added, it installs exactly its items (counted in the simulation's lists); removed, the lists are as
// before the model came, the model is released, and a box dropped afterwards moves to the bit as in a twin
// simulation that never had the model (nothing left behind in the step's caches either).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "test_world.h"

using namespace scree;
using scree::test::TestWorld;

namespace {

struct Snapshot {
  size_t bodies, geometries, constraints, stepListeners, contactListeners, models;
  bool operator==(const Snapshot&) const = default;
};
Snapshot snapshot(const Simulation& sim) {
  return {sim.getRigidBodies().size(), sim.getStaticGeometries().size(), sim.getConstraints().size(),
          sim.getStepEventListeners().size(), sim.getContactEventListeners().size(), sim.getModels().size()};
}

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
