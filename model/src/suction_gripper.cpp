// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// SuctionGripper, SuctionCup, VacuumSystem, SuctionCupInteraction (model layer; see suction_gripper.h).
//
// The gripper attaches through public hooks only: the Model hook installs (and removal takes out) its items;
// sensor geometries on the cup bodies, a ContactEventListener (filtered to the gripper's collision group) that
// turns sensor contacts into interactions, and its own StepEventListener stages: preCollide clears the
// interactions, pre runs the vacuum system and applies the forces (RigidBody::addForceAtPosition, consumed by
// this step's solve), post reads the cup-body contacts' forces.
#include "scree/model/suction_gripper.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include "scree/collide/shapes.h"
#include "scree/core/errors.h"
#include "scree/solver/joints.h"
#include "scree/solver/simulation.h"

namespace scree {

namespace {
constexpr Real kPi = 3.14159265358979323846;
// Atomic: simulations may be built on several threads at once (docs/solvers.md "Several simulations on several
// threads"), and two grippers must never share a group.
uint32_t nextGripperGroup() {
  static std::atomic<uint32_t> counter{0};
  return Geometry::groupId("scree.suction.gripper." + std::to_string(counter.fetch_add(1)));
}
}  // namespace

// ---- SuctionCupInteraction ---------------------------------------------------------------------------------

void SuctionCupInteraction::reset(RigidBody* body) {
  body_ = body;
  sealCount_ = 0;
  std::fill(sealSeen_.begin(), sealSeen_.end(), uint8_t(0));
  centered_ = false;
  centerDistance_ = 0;
  centerNormal_.setZero();
  surfacePosition_.setZero();
  scalarForce_ = 0;
  force_.setZero();
  frictionForce_.setZero();
  normalForce_.setZero();
  relativeVelocity_ = 0;
}

Real SuctionCupInteraction::updateVacuumForce(const SuctionCup* cup, const VacuumSystem*, const Real& fraction) {
  Real f = 0;
  if (centered_ && fraction > 0) {
    // The distance fade models the pressure gradient of the air flowing in under a leaking lip. A sealed cup
    // (every seal sensor touching) has no flow, so the full lip pressure difference acts: without this, a
    // sealed cup lifting a box at 0.1 m/s let the millimetre gap the lift opens cut its force below the weight.
    const Real rl = cup->getLipRadius();
    const Real fade = cup->isSealed() ? 1.0 : rl / (rl + std::max<Real>(centerDistance_, 0));
    f = cup->getAvailableVacuumForce() * fraction * fade * fade;
  }
  setCalculatedScalarForce(f);
  setCalculatedForce(f * cup->getNormalWorld());
  return f;
}

// ---- VacuumSystem ------------------------------------------------------------------------------------------

namespace {
void checkVacuum(const char* where, Real v) {
  if (!(std::isfinite(v) && v >= 0 && v < 1)) detail::throwInvalid(where, "desiredVacuum", v, "must be in [0, 1)");
}
}  // namespace

VacuumSystem::VacuumSystem(Real desiredVacuum) : desiredVacuum_(desiredVacuum) {
  checkVacuum("VacuumSystem::VacuumSystem", desiredVacuum);
  currentVacuum_ = desiredVacuum;
}

void VacuumSystem::setDesiredVacuum(Real vacuum) {
  checkVacuum("VacuumSystem::setDesiredVacuum", vacuum);
  desiredVacuum_ = vacuum;
}

void VacuumSystem::setOutsidePressure(Real pressure) {
  detail::requirePositive("VacuumSystem::setOutsidePressure", "pressure", pressure);
  outsidePressure_ = pressure;
}

void VacuumSystem::setOutsideGasDensity(Real density) {
  detail::requirePositive("VacuumSystem::setOutsideGasDensity", "density", density);
  gasDensity_ = density;
}

Real VacuumSystem::lipPressureUnderLeakage(Real pa, Real pm, Real rho, Real rl, Real rm) {
  if (pm >= pa) return pa;
  // Bernoulli between still air far away and the mount gives the mount air speed; continuity (equal volume flow
  // through mount and lip) gives the lip air speed; Bernoulli again gives the lip pressure.
  const Real vm = std::sqrt(2 * (pa - pm) / rho);
  const Real am = kPi * rm * rm, al = kPi * rl * rl;
  const Real vl = vm * am / al;
  const Real pl = pa - Real(0.5) * rho * vl * vl;
  return std::max(pl, pm);  // a mount wider than the lip cannot drop the lip below the mount pressure
}

Real VacuumSystem::calculateAvailableVacuumForce(SuctionCup* cup) {
  if (!cup || !cup->getVacuumInteraction()) return 0;
  const Real pa = outsidePressure_, pm = getMountPressure();
  const Real pl = cup->isSealed()
                      ? pm
                      : lipPressureUnderLeakage(pa, pm, gasDensity_, cup->getLipRadius(), cup->getMountingRadius());
  return (pa - pl) * cup->getLipArea();
}

void VacuumSystem::step(const Real&, const SuctionGripper*) { currentVacuum_ = pump_ ? desiredVacuum_ : 0; }

// ---- SuctionCup --------------------------------------------------------------------------------------------

SuctionCup::SuctionCup(RigidBodyRef body, Real lipRadius, Real lipHeight, size_t sealResolution,
                       const Vec3& lineSensorVector, Real sealSensorReach)
    : lipRadius_(lipRadius),
      lipHeight_(lipHeight),
      sealResolution_(sealResolution),
      lineVector_(lineSensorVector),
      sealReach_(sealSensorReach),
      mountingRadius_(0.5 * lipRadius) {
  const char* where = "SuctionCup::SuctionCup";
  detail::requirePositive(where, "lipRadius", lipRadius);
  detail::requirePositive(where, "lipHeight", lipHeight);
  detail::requireNonNegative(where, "sealSensorReach", sealSensorReach);
  detail::requireFinite(where, "lineSensorVector", lineSensorVector);
  if (!(lineSensorVector.norm() > 0))
    detail::throwInvalid(where, "lineSensorVector", lineSensorVector, "must be non-zero");
  if (sealResolution > 4096)
    detail::throwInvalid(where, "sealResolution", static_cast<long long>(sealResolution), "must be <= 4096");

  if (!body) {
    // Default body: a cylinder (Scree cylinders have their axis along local y: rotate it onto z) whose lip face
    // lies in the body's x-y plane, extending away from the line sensor.
    body = std::make_shared<RigidBody>("SuctionCup");
    auto geom = std::make_shared<Geometry>(std::make_shared<Cylinder>(lipRadius, lipHeight), "SuctionCupLip");
    geom->setLocalRotation(Quat(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitX())));
    const Real side = lineSensorVector.z() > 0 ? -1 : 1;
    geom->setLocalPosition(Vec3(0, 0, side * 0.5 * lipHeight));
    body->add(geom);
  }
  body_ = std::move(body);

  lineSensor_ = std::make_shared<Geometry>(std::make_shared<Line>(Vec3::Zero(), lineSensorVector), "SuctionCupLine");
  lineSensor_->setSensor(true);
  body_->add(lineSensor_);
  if (sealSensorReach > 0) {
    for (size_t k = 0; k < sealResolution; ++k) {
      const Real a = 2 * kPi * Real(k) / Real(sealResolution);
      auto s = std::make_shared<Geometry>(std::make_shared<Sphere>(sealSensorReach), "SuctionCupSeal");
      s->setSensor(true);
      s->setLocalPosition(Vec3(lipRadius * std::cos(a), lipRadius * std::sin(a), 0));
      body_->add(s);
      sealSensors_.push_back(std::move(s));
    }
  }
}

Real SuctionCup::getLipArea() const { return kPi * lipRadius_ * lipRadius_; }

void SuctionCup::setMountingRadius(Real radius) {
  detail::requirePositive("SuctionCup::setMountingRadius", "mountingRadius", radius);
  mountingRadius_ = radius;
}

Vec3 SuctionCup::getNormalWorld() const { return -(body_->getRotation() * lineVector_).normalized(); }

bool SuctionCup::isSealed() const {
  if (!vacuumInteraction_) return false;
  if (sealResolution_ == 0) return true;
  return vacuumInteraction_->getSealCount() == sealResolution_;
}

SuctionCupInteractionRef SuctionCup::createInteraction() { return std::make_shared<SuctionCupInteraction>(); }

SuctionCupInteraction* SuctionCup::interactionFor(RigidBody* body) {
  for (SuctionCupInteraction* it : active_)
    if (it->getRigidBody() == body) return it;
  if (pool_.size() == active_.size()) {
    SuctionCupInteractionRef made = createInteraction();
    if (!made) made = std::make_shared<SuctionCupInteraction>();  // a factory returning null gets the default
    pool_.push_back(std::move(made));
  }
  SuctionCupInteraction* it = pool_[active_.size()].get();
  it->sealSeen_.resize(sealSensors_.size());
  it->reset(body);
  active_.push_back(it);
  return it;
}

// ---- SuctionGripper ----------------------------------------------------------------------------------------

/// Forwards the gripper's sensor contacts (impact and contact events) to the gripper.
class SuctionGripper::SensorListener : public ContactEventListener {
 public:
  explicit SensorListener(SuctionGripper* g) : ContactEventListener(IMPACT | CONTACT), gripper_(g) {}
  KeepContactPolicy impact(const TimeStamp&, GeometryContact& c) override {
    if (gripper_) gripper_->onSensorContact(c);
    return KEEP_CONTACT;
  }
  KeepContactPolicy contact(const TimeStamp&, GeometryContact& c) override {
    if (gripper_) gripper_->onSensorContact(c);
    return KEEP_CONTACT;
  }
  /// Called by the gripper's destructor: should anything still hold the listener, it never calls a dead gripper.
  void detach() { gripper_ = nullptr; }

 private:
  SuctionGripper* gripper_;
};

namespace {
/// Matches pairs where one geometry is a sensor in the gripper's group.
class GroupSensorFilter : public ExecuteFilter {
 public:
  explicit GroupSensorFilter(uint32_t group) : group_(group) {}
  bool match(const Geometry* g0, const Geometry* g1) const override {
    return (g0->isSensor() && g0->hasGroup(group_)) || (g1->isSensor() && g1->hasGroup(group_));
  }

 private:
  uint32_t group_;
};
}  // namespace

SuctionGripper::SuctionGripper()
    : StepEventListener(ALL),
      Model("SuctionGripper"),
      vacuum_(std::make_shared<VacuumSystem>()),
      group_(nextGripperGroup()) {
  listener_ = std::make_shared<SensorListener>(this);
  listener_->setFilter(std::make_shared<GroupSensorFilter>(group_));
}

SuctionGripper::~SuctionGripper() { listener_->detach(); }

void SuctionGripper::setHolderRigidBody(RigidBodyRef holder) {
  detail::requireNonNull("SuctionGripper::setHolderRigidBody", "holder", holder.get());
  holder_ = std::move(holder);
  for (const GeometryRef& g : holder_->getGeometries()) g->addGroup(group_);
  // A replaced holder stays installed (cups may still be locked to it) and leaves with the gripper.
  installBody(holder_);
}

void SuctionGripper::setVacuumSystem(VacuumSystemRef vacuumSystem) {
  detail::requireNonNull("SuctionGripper::setVacuumSystem", "vacuumSystem", vacuumSystem.get());
  vacuum_ = std::move(vacuumSystem);
}

void SuctionGripper::add(SuctionCupRef cup) {
  detail::requireNonNull("SuctionGripper::add", "cup", cup.get());
  if (cup->gripper_ == this) return;
  if (cup->gripper_ != nullptr)
    throw std::invalid_argument("SuctionGripper::add: cup is invalid (it belongs to another gripper)");
  cup->gripper_ = this;
  registerCup(*cup);
  installBody(cup->getRigidBody());
  cups_.push_back(std::move(cup));
}

void SuctionGripper::add(SuctionCupRef cup, const Vec3& localPosition, const Quat& localRotation) {
  const char* where = "SuctionGripper::add";
  detail::requireNonNull(where, "cup", cup.get());
  detail::requireFinite(where, "localPosition", localPosition);
  detail::requireRotation(where, "localRotation", localRotation);
  if (!holder_)
    throw std::invalid_argument("SuctionGripper::add: holder = null is invalid (set the holder before mounting cups)");
  if (cup->gripper_ != nullptr)
    throw std::invalid_argument("SuctionGripper::add: cup is invalid (it already belongs to a gripper)");
  const Transform h = holder_->getTransform();
  RigidBody& b = *cup->getRigidBody();
  b.setPosition(h.apply(localPosition));
  b.setRotation(h.q * localRotation.normalized());
  auto joint = std::make_shared<LockJoint>(cup->getRigidBody(), holder_);
  joint->setEnableCollisions(false);
  joints_.push_back(joint);
  cup->mount_ = joint;
  cup->mountLocal_ = {localPosition, localRotation.normalized()};
  add(std::move(cup));
  addOwned(joints_.back());  // after its body: no joint in the simulation to a body that is not
}

void SuctionGripper::registerCup(SuctionCup& cup) {
  for (const GeometryRef& g : cup.getRigidBody()->getGeometries()) g->addGroup(group_);
  sensors_[cup.getLineSensor().get()] = {&cup, -1};
  for (size_t k = 0; k < cup.getSealSensors().size(); ++k) sensors_[cup.getSealSensors()[k].get()] = {&cup, int(k)};
  cupBodies_[cup.getRigidBody().get()] = &cup;
}

void SuctionGripper::installBody(const RigidBodyRef& body) {
  Simulation* sim = Model::getSimulation();
  if (!sim) return;  // onAdd installs it when the gripper is added
  // A body already in the simulation was put there by the user (or is owned already): not ours to remove.
  const auto& bodies = sim->getRigidBodies();
  if (std::find(bodies.begin(), bodies.end(), body) != bodies.end()) return;
  addOwned(body);
}

void SuctionGripper::onAdd(Simulation& sim) {
  addOwned(selfAs<StepEventListener>());
  addOwned(ContactEventListenerRef(listener_));
  sim.setEnableCollisions(group_, group_, false);
  if (holder_) installBody(holder_);
  for (const auto& cup : cups_) installBody(cup->getRigidBody());
  for (const auto& j : joints_) addOwned(j);
}

void SuctionGripper::onRemove(Simulation& sim) {
  // Group ids are unique per gripper, so nothing else had changed this pair: back to the default.
  sim.setEnableCollisions(group_, group_, true);
  for (const auto& cup : cups_) {
    if (cup->kinematicMount_) {  // undo updateMounts(): a body the user keeps must move on its own again
      cup->getRigidBody()->setMotionControl(RigidBody::DYNAMICS);
      cup->mount_->setEnable(true);
      cup->kinematicMount_ = false;
    }
    cup->active_.clear();
    cup->vacuumInteraction_ = nullptr;
    cup->availableForce_ = 0;
  }
  anyInteraction_ = false;
}

void SuctionGripper::updateMounts() {
  if (!holder_) return;
  const bool holderMoves = holder_->isDynamic();
  for (const auto& cupRef : cups_) {
    SuctionCup& cup = *cupRef;
    if (!cup.mount_) continue;
    RigidBody& b = *cup.getRigidBody();
    if (holderMoves) {
      if (cup.kinematicMount_) {
        b.setMotionControl(RigidBody::DYNAMICS);
        cup.mount_->setEnable(true);
        cup.kinematicMount_ = false;
      }
      continue;
    }
    if (!cup.kinematicMount_) {
      if (!b.isDynamic() && b.getMotionControl() != RigidBody::KINEMATICS) continue;  // the user's choice
      b.setMotionControl(RigidBody::KINEMATICS);
      cup.mount_->setEnable(false);
      cup.kinematicMount_ = true;
    }
    // Rigidly attached: pose from the holder, velocity of the holder's material point at the cup's centre of mass.
    const Transform t = holder_->getTransform() * cup.mountLocal_;
    b.setRotation(t.q);
    b.setPosition(t.p);
    b.setVelocity(holder_->getVelocityAt(b.getCmPosition()));
    b.setAngularVelocity(holder_->getAngularVelocity());
  }
}

void SuctionGripper::preCollide(const TimeStamp&) {
  Simulation* sim = StepEventListener::getSimulation();
  if (!sim) return;
  // Added as a plain StepEventListenerRef: install the rest through the Model hook now (the gripper is already
  // in the listener list, so the list this stage walks does not grow).
  if (!Model::getSimulation()) sim->add(selfAs<Model>());
  updateMounts();
  for (const auto& cup : cups_) {
    cup->active_.clear();
    cup->vacuumInteraction_ = nullptr;
    cup->availableForce_ = 0;
  }
  anyInteraction_ = false;
}

void SuctionGripper::onSensorContact(const GeometryContact& c) {
  const int si = sensors_.count(c.geometry(0)) ? 0 : (sensors_.count(c.geometry(1)) ? 1 : -1);
  if (si < 0 || c.points().empty()) return;
  const SensorInfo info = sensors_.at(c.geometry(si));
  RigidBody* other = c.rigidBody(1 - si);
  // Vacuum acts on dynamic bodies only; the gripper's own bodies are excluded by the collision group already.
  if (!other || !other->isDynamic() || cupBodies_.count(other) || other == holder_.get()) return;
  SuctionCup& cup = *info.cup;
  SuctionCupInteraction& it = *cup.interactionFor(other);
  anyInteraction_ = true;
  if (info.seal >= 0) {
    if (!it.sealSeen_[size_t(info.seal)]) {
      it.sealSeen_[size_t(info.seal)] = 1;
      ++it.sealCount_;
    }
    return;
  }
  // Line sensor: one entry point; its normal points from geometry 1 towards geometry 0, i.e. out of the body when
  // the line is geometry 0.
  const ContactPoint& p = c.points().front();
  const Vec3 outward = si == 0 ? p.normal : Vec3(-p.normal);
  const Vec3 start = c.geometry(si)->getTransform().apply(Vec3::Zero());
  const Vec3 dir = (cup.getRigidBody()->getRotation() * cup.getLineSensorVector()).normalized();
  const Real dist = std::max<Real>(0, (p.point - start).dot(dir));
  if (!it.centered_ || dist < it.centerDistance_) {
    it.centered_ = true;
    it.centerDistance_ = dist;
    it.centerNormal_ = outward;
    it.surfacePosition_ = p.point;
  }
}

void SuctionGripper::pre(const TimeStamp&) {
  Simulation* sim = getSimulation();
  const Real h = sim ? sim->getTimeStep() : 0;
  vacuum_->step(h, this);
  if (!anyInteraction_) return;
  for (const auto& cupRef : cups_) {
    SuctionCup& cup = *cupRef;
    if (cup.active_.empty()) continue;
    // The vacuum pulls on the first surface the line sensor meets.
    SuctionCupInteraction* best = nullptr;
    for (SuctionCupInteraction* it : cup.active_)
      if (it->getCentered() && (!best || it->getCenterDistance() < best->getCenterDistance())) best = it;
    cup.vacuumInteraction_ = best;
    cup.availableForce_ = vacuum_->calculateAvailableVacuumForce(&cup);
    // Reaction: on the cup body, or on the holder through an enabled mount lock (see the header).
    RigidBody& reactionBody = (cup.mount_ && cup.mount_->getEnable() && holder_) ? *holder_ : *cup.getRigidBody();
    for (SuctionCupInteraction* it : cup.active_) {
      it->updateVacuumForce(&cup, vacuum_.get(), it == best ? Real(1) : Real(0));
      const Vec3 f = it->getCalculatedForce();
      if (!f.allFinite() || f.isZero(0)) continue;
      const Vec3 x = it->getFoundSurfacePositionWorld();
      it->getRigidBody()->addForceAtPosition(f, x);
      reactionBody.addForceAtPosition(-f, x);
    }
  }
}

void SuctionGripper::post(const TimeStamp&) {
  Simulation* sim = getSimulation();
  if (!sim || !anyInteraction_) return;
  for (const GeometryContact& c : sim->getContacts()) {
    if (c.isSensor() || !c.isEnabled()) continue;
    for (int i = 0; i < 2; ++i) {
      auto found = cupBodies_.find(c.rigidBody(i));
      if (found == cupBodies_.end()) continue;
      SuctionCup& cup = *found->second;
      RigidBody* other = c.rigidBody(1 - i);
      SuctionCupInteraction* it = nullptr;
      for (SuctionCupInteraction* a : cup.active_)
        if (a->getRigidBody() == other) it = a;
      if (!it) continue;
      // Forces on geometry 0 are normal * normalForce + frictionForce; the body is geometry 1 - i.
      const Real sign = (1 - i) == 0 ? 1 : -1;
      const RigidBody& cb = *c.rigidBody(i);
      for (const ContactPoint& p : c.points()) {
        if (!p.enabled) continue;
        it->normalForce_ += sign * p.normalForce * p.normal;
        it->frictionForce_ += sign * p.frictionForce;
        const Real rel = (other->getVelocityAt(p.point) - cb.getVelocityAt(p.point)).norm();
        it->relativeVelocity_ = std::max(it->relativeVelocity_, rel);
      }
    }
  }
}

}  // namespace scree
