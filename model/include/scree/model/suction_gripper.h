// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// SuctionGripper (AGX: agxModel::SuctionGripper, manual section 25.4): a holder rigid body carrying suction cups
// that one VacuumSystem powers.
//
// Pieces (each can be subclassed as the manual shows):
//   SuctionGripper         a Model and a StepEventListener: `sim.add(gripper)` is all a user does. The Model hook
//                          (scree/solver/model.h) installs at once the gripper as a step listener, its contact
//                          listener, the holder and cup bodies not yet in the simulation, and the lock joints made
//                          by add(cup, pose); cups added later are installed as they come. All its geometries are
//                          in one collision group that does not collide with itself (sensors ignore the holder and
//                          the cups). `sim.remove(gripper)` takes out everything it installed.
//   SuctionCup             a rigid body (default: a cylinder of the lip radius and lip height, axis along the
//                          body's local z, lip at the body origin) with a Line sensor from the body origin along the
//                          line sensor vector and `sealResolution` sphere sensors of radius `sealSensorReach` on the
//                          lip circle in the local x-y plane. createInteraction() is the factory for interactions.
//   VacuumSystem           the pump: desired vacuum v in [0, 1) (fraction of the outside pressure removed), pump
//                          on/off, outside pressure P_a (Pa) and gas density rho (kg/m^3). step() sets the current
//                          vacuum (desired with the pump on, 0 with it off); calculateAvailableVacuumForce(cup)
//                          gives the force the cup's lip pressure can exert.
//   SuctionCupInteraction  one per dynamic body a cup's sensors touch in a step; updateVacuumForce() turns the
//                          cup's available force into the force on that body.
//
// Physics (default classes):
//   mount pressure  P_m = P_a (1 - v_current)
//   sealed cup      (every seal sensor touches the body, or sealResolution is 0) lip pressure P_l = P_m
//   leaking cup     Bernoulli with constant flow through mount (radius r_m) and lip (radius r_l), zero air
//                   speed far away:  P_a = P_m + rho v_m^2 / 2,  v_l = v_m a_m / a_l,  P_l = P_a - rho v_l^2 / 2,
//                   a = pi r^2, i.e. P_a - P_l = (P_a - P_m)(r_m / r_l)^4 (capped at P_a - P_m when r_m > r_l).
//   available force F = (P_a - P_l) pi r_l^2
//   on the body     F_body = F * fraction * fade along the cup normal (towards the cup, i.e. minus the line
//                   sensor direction), applied at the surface point the line sensor found. A leaking cup has
//                   fade = (r_l / (r_l + d))^2, d >= 0 the distance along the line sensor from the lip to that
//                   point: our reading of the manual's "pressure gradient decays quadratically relative to the
//                   distance from the suction cup center", 1 at the lip, ~ (r_l / d)^2 far away. The manual
//                   derives that gradient from the flow of a leaking cup; a sealed cup has no flow: fade = 1.
//   reaction        -F_body on the cup body at the same point. For a cup mounted by add(cup, pose) (an enabled
//                   LockJoint to the holder) the reaction goes straight to the holder at that point: the same wrench
//                   on the locked assembly, but it spares the solver a light cup body (20 g by default) loaded
//                   with ~100 N that the lock must cancel every step (PGS at 10 iterations leaves a few per cent of
//                   that as joint error, enough to tip a box held by two cups).
//   fraction        1 for the interaction whose body the line sensor meets first (the surface the cup faces), 0 for
//                   the others: a cup pulls on one surface. Interactions that only seal sensors touch get no force.
//
// Sharing the vacuum system: one VacuumSystem serves all cups of a gripper. The default system is an ideal pump
// that holds the mount pressure of every cup at P_a (1 - v) whatever the others do: a leaking cup loses force
// itself but does not lower the vacuum of the sealed cups. A subclass that models a limited pump can read all cups
// (and their interactions) in step(dt, gripper) and return less in calculateAvailableVacuumForce(cup).
//
// Timing: interactions are rebuilt every step after collision detection (read-outs "before the step" are valid
// from then on, e.g. in a pre-step listener and after the step); vacuum forces are applied in the pre stage; the
// contact read-outs (normal and friction force, relative speed between cup and body) are filled in the post stage.
//
// Adding and removing. Bodies that were already in the simulation when the gripper installed them (a holder the
// user added, a cup whose body is the holder) stay the user's: removing the gripper leaves them in. Removing it
// takes out its listeners, the lock joints and the bodies it added, turns a cup it made KINEMATICS back to
// DYNAMICS with its lock enabled, and re-enables collisions within its group. A gripper added as a plain
// StepEventListenerRef installs itself through the same hook at its first step; remove it with sim.remove(gripper).
//
// Limitations: light cup bodies locked to a *dynamic* holder (several cups on a robot-driven holder) are a hard
// case for PGS: a box pulled with hundreds of newtons against 20 g - 2 kg cups makes the cups wobble centimetres
// on their locks and the box slip out at 16 iterations. A dynamic holder can carry one cup whose body is the
// holder itself (examples/demo_suction.h), the arrangement the tests cover. The locks' default solve type
// (DIRECT_AND_ITERATIVE) gives them to the direct solver; several cups on a dynamic holder have not been measured
// with it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "scree/collide/geometry.h"
#include "scree/core/listeners.h"
#include "scree/core/math.h"
#include "scree/core/rigid_body.h"
#include "scree/solver/constraint.h"
#include "scree/solver/model.h"

namespace scree {

class SuctionCup;
class SuctionGripper;
class VacuumSystem;

/// What one cup's sensors found on one dynamic rigid body in this step, and the forces that followed.
class SuctionCupInteraction {
 public:
  SuctionCupInteraction() = default;
  virtual ~SuctionCupInteraction() = default;

  // --- valid after collision detection --------------------------------------------------------------------
  /// The interacting body that the vacuum force acts on.
  RigidBody* getRigidBody() const { return body_; }
  /// Number of seal sensors touching the body.
  size_t getSealCount() const { return sealCount_; }
  /// True when the line sensor (along the cup normal) meets the body.
  bool getCentered() const { return centered_; }
  /// m, >= 0: distance along the line sensor from the lip to the body's surface (0 if the line starts inside).
  Real getCenterDistance() const { return centerDistance_; }
  /// Unit outward surface normal of the body where the line sensor meets it (world).
  Vec3 getCenterNormalWorld() const { return centerNormal_; }
  /// World point where the vacuum force acts (the line sensor's entry point into the body).
  Vec3 getFoundSurfacePositionWorld() const { return surfacePosition_; }

  // --- valid after the step ------------------------------------------------------------------------------
  /// N: magnitude of the vacuum force applied to the body in the last step.
  Real getCalculatedScalarForce() const { return scalarForce_; }
  /// N, world: the vacuum force applied to the body (the cup body got the opposite).
  Vec3 getCalculatedForce() const { return force_; }
  /// N, world: sum of the friction forces the cup body's contacts exerted on the body.
  Vec3 getCurrentFrictionForce() const { return frictionForce_; }
  /// N, world: sum of the normal forces the cup body's contacts exerted on the body.
  Vec3 getCurrentContactNormalForce() const { return normalForce_; }
  /// m/s: largest relative speed between the cup body and the body over their contact points.
  Real getCurrentRelativeVelocity() const { return relativeVelocity_; }

  /// Computes the vacuum force on getRigidBody() from the cup's available force (cup->getAvailableVacuumForce(),
  /// set by the vacuum system this step) and this interaction's share `fraction` in [0, 1]; must call
  /// setCalculatedScalarForce and setCalculatedForce. Returns the scalar force, N. The default: see the file comment.
  virtual Real updateVacuumForce(const SuctionCup* cup, const VacuumSystem* vacuumSystem, const Real& fraction);

 protected:
  void setCalculatedScalarForce(Real f) { scalarForce_ = f; }
  void setCalculatedForce(const Vec3& f) { force_ = f; }

 private:
  friend class SuctionGripper;
  friend class SuctionCup;
  void reset(RigidBody* body);

  RigidBody* body_ = nullptr;
  size_t sealCount_ = 0;
  std::vector<uint8_t> sealSeen_;  // per seal sensor: touching this body this step
  bool centered_ = false;
  Real centerDistance_ = 0;
  Vec3 centerNormal_ = Vec3::Zero();
  Vec3 surfacePosition_ = Vec3::Zero();
  Real scalarForce_ = 0;
  Vec3 force_ = Vec3::Zero();
  Vec3 frictionForce_ = Vec3::Zero();
  Vec3 normalForce_ = Vec3::Zero();
  Real relativeVelocity_ = 0;
};
using SuctionCupInteractionRef = std::shared_ptr<SuctionCupInteraction>;

/// The pump of a gripper (see the file comment for the pressure model).
class VacuumSystem {
 public:
  /// desiredVacuum in [0, 1): fraction of the outside pressure the pump removes at the mount (0.2 = 80 % of the
  /// outside pressure left). Pump enabled, outside pressure 101325 Pa, gas density 1.225 kg/m^3.
  explicit VacuumSystem(Real desiredVacuum = 0.2);
  virtual ~VacuumSystem() = default;

  /// In [0, 1); 1 (perfect vacuum) is excluded.
  void setDesiredVacuum(Real vacuum);
  Real getDesiredVacuum() const { return desiredVacuum_; }
  void setEnablePump(bool enable) { pump_ = enable; }
  bool getEnablePump() const { return pump_; }
  /// Pa, finite and > 0 (Earth 101325, Mars ~610).
  void setOutsidePressure(Real pressure);
  Real getOutsidePressure() const { return outsidePressure_; }
  /// kg/m^3, finite and > 0 (air 1.225, Mars ~0.02).
  void setOutsideGasDensity(Real density);
  Real getOutsideGasDensity() const { return gasDensity_; }

  /// Vacuum the pump holds now (set by step()): the desired vacuum with the pump on, 0 with it off.
  Real getCurrentVacuum() const { return currentVacuum_; }
  /// Pa: pressure at every cup's mount, P_a (1 - current vacuum).
  Real getMountPressure() const { return outsidePressure_ * (1 - currentVacuum_); }

  /// Pa: lip pressure by Bernoulli (file comment) for outside pressure pa, mount pressure pm, gas density rho,
  /// lip radius rl and mounting radius rm. Equals pm when rm >= rl.
  static Real lipPressureUnderLeakage(Real pa, Real pm, Real rho, Real rl, Real rm);

  /// N: the force the cup's lip pressure can exert now: (P_a - P_l) pi r_l^2, with P_l = P_m when the cup is sealed
  /// and the Bernoulli lip pressure when it leaks. 0 when the cup faces no surface.
  virtual Real calculateAvailableVacuumForce(SuctionCup* cup);
  /// Updates the pump state once per step before forces are computed (default: toggles between the desired
  /// vacuum and 0 with the pump switch).
  virtual void step(const Real& dt, const SuctionGripper* gripper);

 protected:
  Real currentVacuum_ = 0;

 private:
  Real desiredVacuum_;
  bool pump_ = true;
  Real outsidePressure_ = 101325;
  Real gasDensity_ = 1.225;
};
using VacuumSystemRef = std::shared_ptr<VacuumSystem>;

/// One suction cup: its body, sensors and this step's interactions.
class SuctionCup {
 public:
  /// body: null creates a dynamic body with a cylinder of lipRadius and lipHeight (axis along local z, on the
  /// side of the lip opposite the line sensor). lipRadius, lipHeight > 0 (m); sealResolution seal sensors
  /// (spheres of radius sealSensorReach >= 0 m; 0 creates none, so the cup never counts as sealed) on the lip
  /// circle; lineSensorVector (m, body frame, finite and non-zero) from the body origin. Mounting radius =
  /// lipRadius / 2.
  explicit SuctionCup(RigidBodyRef body = nullptr, Real lipRadius = 0.025, Real lipHeight = 0.01,
                      size_t sealResolution = 4, const Vec3& lineSensorVector = Vec3(0, 0, -0.1),
                      Real sealSensorReach = 0.01);
  virtual ~SuctionCup() = default;
  SuctionCup(const SuctionCup&) = delete;
  SuctionCup& operator=(const SuctionCup&) = delete;

  const RigidBodyRef& getRigidBody() const { return body_; }
  Real getLipRadius() const { return lipRadius_; }
  Real getLipHeight() const { return lipHeight_; }
  /// m^2: pi r_l^2.
  Real getLipArea() const;
  size_t getSealResolution() const { return sealResolution_; }
  const Vec3& getLineSensorVector() const { return lineVector_; }
  Real getSealSensorReach() const { return sealReach_; }
  /// m, finite and > 0; default half the lip radius. Sets the leakage pressure drop (file comment).
  void setMountingRadius(Real radius);
  Real getMountingRadius() const { return mountingRadius_; }

  const GeometryRef& getLineSensor() const { return lineSensor_; }
  const std::vector<GeometryRef>& getSealSensors() const { return sealSensors_; }
  /// The LockJoint made by SuctionGripper::add(cup, pose), or null.
  const ConstraintRef& getMountJoint() const { return mount_; }
  /// Unit cup normal in the world: the direction the vacuum pulls a body (minus the line sensor direction).
  Vec3 getNormalWorld() const;

  /// This step's interactions, one per dynamic body the sensors touch.
  const std::vector<SuctionCupInteraction*>& getActiveInteractionsVector() const { return active_; }
  /// The interaction the vacuum acts on: the body the line sensor meets first (null when none).
  SuctionCupInteraction* getVacuumInteraction() const { return vacuumInteraction_; }
  /// True when the vacuum interaction is sealed: all sealResolution seal sensors touch its body (with
  /// sealResolution 0 the cup cannot detect leaks and counts as sealed whenever the line sensor finds a body).
  bool isSealed() const;
  /// N: what the vacuum system made available to this cup in the current step.
  Real getAvailableVacuumForce() const { return availableForce_; }
  SuctionGripper* getGripper() const { return gripper_; }

  /// Factory for interactions: override to use a SuctionCupInteraction subclass. Called only when the cup needs
  /// more interaction objects than it had before (they are reused from step to step).
  virtual SuctionCupInteractionRef createInteraction();

 private:
  friend class SuctionGripper;
  SuctionCupInteraction* interactionFor(RigidBody* body);

  RigidBodyRef body_;
  Real lipRadius_, lipHeight_;
  size_t sealResolution_;
  Vec3 lineVector_;
  Real sealReach_;
  Real mountingRadius_;
  GeometryRef lineSensor_;
  std::vector<GeometryRef> sealSensors_;
  std::vector<SuctionCupInteractionRef> pool_;
  std::vector<SuctionCupInteraction*> active_;
  SuctionCupInteraction* vacuumInteraction_ = nullptr;
  Real availableForce_ = 0;
  SuctionGripper* gripper_ = nullptr;
  ConstraintRef mount_;  // the gripper's lock joint for cups added with a pose
  Transform mountLocal_;  // cup body frame in the holder frame (cups added with a pose)
  bool kinematicMount_ = false;  // the gripper made the body KINEMATICS (non-dynamic holder)
};
using SuctionCupRef = std::shared_ptr<SuctionCup>;

/// Holder body + cups + vacuum system (an assembly in AGX). Add it to a simulation with sim.add(gripper) (a Model).
class SuctionGripper : public StepEventListener, public Model {
 public:
  /// A default VacuumSystem (desired vacuum 0.2) and no holder yet.
  SuctionGripper();
  ~SuctionGripper() override;

  /// The body cups are mounted on; not null. Must be set before the gripper's first step.
  void setHolderRigidBody(RigidBodyRef holder);
  const RigidBodyRef& getHolderRigidBody() const { return holder_; }
  /// Not null: replaces the vacuum system (e.g. a subclass).
  void setVacuumSystem(VacuumSystemRef vacuumSystem);
  VacuumSystem* getVacuumSystem() const { return vacuum_.get(); }

  /// Adds a cup as it is (the user constrains its body to the holder, as the manual expects). Not null, not in
  /// another gripper; adding twice is a no-op.
  void add(SuctionCupRef cup);
  /// Adds a cup and mounts it: places its body at holder pose * (localPosition, localRotation) and locks it to
  /// the holder with a LockJoint (returned by getMountJoints()). The holder must be set. While the holder is
  /// STATIC or KINEMATICS the mount is exact instead: the gripper makes the cup body KINEMATICS, moves it with
  /// the holder every step and disables the lock (PGS resolves a heavy box pulled against a 20 g cup on a lock
  /// poorly: the box sinks millimetres into the lip before the contact catches it). With a dynamic holder the
  /// cup is DYNAMICS on the enabled lock (see the limitation in the file comment).
  void add(SuctionCupRef cup, const Vec3& localPosition, const Quat& localRotation = Quat::Identity());
  const std::vector<SuctionCupRef>& getSuctionCups() const { return cups_; }
  const std::vector<ConstraintRef>& getMountJoints() const { return joints_; }
  /// Collision group of the holder, cup and sensor geometries (disabled against itself).
  uint32_t getCollisionGroup() const { return group_; }
  /// The simulation running the gripper, or nullptr. (Model has one too; they agree once it is installed.)
  using StepEventListener::getSimulation;

  void preCollide(const TimeStamp& t) override;
  void pre(const TimeStamp& t) override;
  void post(const TimeStamp& t) override;

 protected:
  /// Model hook (file comment): installs the listeners, bodies and lock joints / undoes the gripper's changes
  /// to its cups and collision group before the hook removes what it installed.
  void onAdd(Simulation& sim) override;
  void onRemove(Simulation& sim) override;

 private:
  class SensorListener;
  struct SensorInfo {
    SuctionCup* cup;
    int seal;  // -1: line sensor, else seal sensor index
  };
  void installBody(const RigidBodyRef& body);
  void registerCup(SuctionCup& cup);
  void updateMounts();
  void onSensorContact(const GeometryContact& contact);

  RigidBodyRef holder_;
  VacuumSystemRef vacuum_;
  std::vector<SuctionCupRef> cups_;
  std::vector<ConstraintRef> joints_;
  uint32_t group_;
  std::unordered_map<const Geometry*, SensorInfo> sensors_;
  std::unordered_map<const RigidBody*, SuctionCup*> cupBodies_;
  std::shared_ptr<SensorListener> listener_;
  bool anyInteraction_ = false;
};
using SuctionGripperRef = std::shared_ptr<SuctionGripper>;

}  // namespace scree
