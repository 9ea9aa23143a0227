// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Suction gripper pick-and-place for the demo (issue 8): a carriage slides along x on a prismatic joint to the
// world, a holder slides along z on a prismatic joint to the carriage and carries one suction cup (lip radius
// 6 cm, 16 seal sensors, the holder itself as the cup body) on a vacuum system at 20 % vacuum (226 N available
// for a 39 N box). A motor script lowers the holder onto a 4 kg box until the cup is sealed, switches the pump
// on, lifts the box 0.4 m, carries it 1 m along x, lowers it and
// releases it by switching the pump off.
//
// Use: auto demo = SuctionPickPlace::build(sim, material, origin); step the simulation; demo->printSummary().
#pragma once

#include <algorithm>
#include <cstdio>
#include <memory>

#include <scree/scree.h>

class SuctionPickPlace : public scree::StepEventListener {
 public:
  static std::shared_ptr<SuctionPickPlace> build(scree::Simulation& sim, const scree::MaterialRef& material,
                                                 const scree::Vec3& origin) {
    using namespace scree;
    auto d = std::shared_ptr<SuctionPickPlace>(new SuctionPickPlace());
    d->origin_ = origin;
    // The box to pick, resting on the ground (top face at z = 0) at the origin.
    d->box_ = std::make_shared<RigidBody>("suction box");
    auto boxGeom = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.15, 0.15, 0.1)));
    boxGeom->setMaterial(material);
    d->box_->add(boxGeom);
    d->box_->setMass(4.0);
    d->box_->setPosition(origin + Vec3(0, 0, 0.1));
    sim.add(d->box_);
    // Carriage at 1.2 m (no geometry).
    auto carriage = std::make_shared<RigidBody>("carriage");
    carriage->setMass(10.0);
    carriage->setPosition(origin + Vec3(0, 0, 1.2));
    sim.add(carriage);
    // The holder is also the cup's body: its x-y plane at the body origin is the lip plane, and its pad (a
    // 16 x 16 x 4 cm box) sits above it. One cup of lip radius 6 cm with 16 seal sensors.
    auto holder = std::make_shared<RigidBody>("holder");
    auto pad = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.08, 0.08, 0.02)));
    pad->setMaterial(material);
    pad->setLocalPosition(Vec3(0, 0, 0.02));
    holder->add(pad);
    holder->setMass(5.0);
    holder->setPosition(origin + Vec3(0, 0, 0.3));
    sim.add(holder);
    d->xJoint_ = std::make_shared<Prismatic>(carriage, nullptr, carriage->getPosition(), Vec3::UnitX());
    d->zJoint_ = std::make_shared<Prismatic>(holder, carriage, holder->getPosition(), Vec3::UnitZ());
    for (auto* j : {d->xJoint_.get(), d->zJoint_.get()}) {
      j->getMotor1D().setEnable(true);
      j->getMotor1D().setSpeed(0);
      j->getMotor1D().setForceRange(-3000, 3000);
    }
    sim.add(d->xJoint_);
    sim.add(d->zJoint_);

    d->gripper_ = std::make_shared<SuctionGripper>();
    d->gripper_->setHolderRigidBody(holder);
    d->gripper_->getVacuumSystem()->setDesiredVacuum(0.2);
    d->gripper_->getVacuumSystem()->setEnablePump(false);
    d->gripper_->add(std::make_shared<SuctionCup>(holder, 0.06, 0.01, 16, Vec3(0, 0, -0.1), 0.01));
    sim.add(d->gripper_);
    sim.add(std::static_pointer_cast<StepEventListener>(d));
    return d;
  }

  void pre(const scree::TimeStamp& t) override {
    // The holder stops and the pump starts once every cup is sealed a few millimetres above the box (line sensor
    // distance under 8 mm): pressing the lips onto the box with the holder motor would jam the lock joints.
    bool allSealed = true;
    for (const auto& c : gripper_->getSuctionCups()) {
      const scree::SuctionCupInteraction* it = c->getActiveInteractionsVector().empty()
                                                   ? nullptr
                                                   : c->getActiveInteractionsVector().front();
      allSealed &= it && it->getCentered() && it->getSealCount() == c->getSealResolution() &&
                   it->getCenterDistance() < 0.008;
    }
    const double since = t - phaseStart_;
    auto next = [&](int p) {
      phase_ = p;
      phaseStart_ = t;
    };
    double vx = 0, vz = 0;
    switch (phase_) {
      case DESCEND:
        vz = -0.2;
        if (allSealed) {
          gripper_->getVacuumSystem()->setEnablePump(true);
          pickTime_ = t;
          next(SETTLE);
        } else if (since > 2.0) {
          next(FAILED);
        }
        break;
      case SETTLE: if (since > 0.2) next(LIFT); break;
      // Speeds ramp up over 0.5 s: a sudden jerk would ask more of the vacuum than it can pull.
      case LIFT: vz = 0.4 * std::min(1.0, 2 * since); if (since > 1.25) next(CARRY); break;
      case CARRY:
        vx = 1.0 * std::min(1.0, 2 * since) * std::min(1.0, 2 * (1.5 - since));
        minCarryHeight_ = std::min(minCarryHeight_, box_->getPosition().z() - 0.1);
        if (since > 1.5) next(LOWER);
        break;
      case LOWER: vz = -0.4 * std::min(1.0, 2 * since); if (since > 1.0) { releaseTime_ = t; next(RELEASE); } break;
      case RELEASE:
        gripper_->getVacuumSystem()->setEnablePump(false);
        vz = 0.4;
        if (since > 1.0) next(DONE);
        break;
      default: break;
    }
    xJoint_->getMotor1D().setSpeed(vx);
    zJoint_->getMotor1D().setSpeed(vz);
  }

  void printSummary() const {
    const scree::Vec3 p = box_->getPosition() - origin_;
    std::printf("suction: %s; picked at t = %.2f s, lowest box bottom while carried %.3f m, %s, box now at "
                "(%.3f, %.3f, %.3f) m from its start\n",
                phase_ == FAILED ? "FAILED to seal" : "sealed", pickTime_, minCarryHeight_,
                releaseTime_ > 0 ? "released by switching the pump off" : "not released yet", p.x(), p.y(), p.z());
  }

  double getReleaseTime() const { return releaseTime_; }
  const scree::RigidBodyRef& getBox() const { return box_; }
  const scree::SuctionGripperRef& getGripper() const { return gripper_; }

 private:
  enum Phase { DESCEND, SETTLE, LIFT, CARRY, LOWER, RELEASE, DONE, FAILED };
  SuctionPickPlace() : scree::StepEventListener(PRE_STEP) {}

  scree::Vec3 origin_ = scree::Vec3::Zero();
  scree::RigidBodyRef box_;
  scree::SuctionGripperRef gripper_;
  scree::PrismaticRef xJoint_, zJoint_;
  int phase_ = DESCEND;
  double phaseStart_ = 0, pickTime_ = -1, releaseTime_ = -1, minCarryHeight_ = 1e9;
};
