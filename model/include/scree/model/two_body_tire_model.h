// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// TwoBodyTireModel (AGX manual 25.2, agxModel::TwoBodyTireModel): a tire body and a rim body joined by a
// compliant 6-DOF constraint, so that the tire deflects against the rim under load.
//
// Frames. At construction a frame is placed at the rim's model origin with its z axis along the rotation axis
// (given in the rim's model frame, default local y: the axis of a Cylinder) and attached to both bodies, so
// the configuration at construction is the undeformed one. Every deformation is the tire (body A) relative to
// the rim (body B), in the rim's frame:
//   RADIAL     two translations in the wheel plane (rim frame x, y)          stiffness N/m,     damping N s/m
//   LATERAL    translation along the axle (rim frame z)                      stiffness N/m,     damping N s/m
//   BENDING    two rotations about the in-plane axes (x, y; log map)         stiffness N m/rad, damping N m s/rad
//   TORSIONAL  rotation about the axle relative to the rim (z; log map)      stiffness N m/rad, damping N m s/rad
// Nothing else is constrained: the rim (and the tire with it) spins freely about the axle; drive it with a
// Hinge motor between chassis and rim. Tire and rim do not collide with each other (Constraint default).
//
// SPOOK mapping (spook.h, docs/design.md §3): a stiffness K and damping coefficient D (the manual's units) become
// compliance 1/K and damping time D/K per row, i.e. a spring K in parallel with a damper D. Defaults are the
// ones AGX ships: RADIAL 3.5e5 N/m with 7e3 N s/m; LATERAL 3e5 N/m, BENDING and TORSIONAL 3e5 N m/rad, each
// with damping 5e3.
//
// The rows along the rim's in-plane axes rotate with the spinning rim; their warm-start impulses are kept as
// world vectors and projected on this step's axes, so a rolling loaded wheel starts each solve from last
// step's load instead of a rotated, stale one.
//
// Friction: while in a simulation the model registers a contact listener that sets, on every contact point of
// the tire body, the primary friction direction (ContactPoint::frictionDirection) to the rolling direction
// axle x normal; the second friction row is then along the axle's projection on the contact plane (the
// lateral, slip-angle direction), as AGX orients a tire's friction frame. setEnableFrictionAlignment(false)
// turns it off.
//
// Adding and removing (the Model hook, scree/solver/model.h). The tire is both a Joint and a Model:
// `sim.add(tire)` / `sim.remove(tire)` take the Model path (Simulation's template for Model types), and onAdd
// installs the tire as a constraint and its friction listener with addOwned, so removing the model takes out
// both. The tire and rim bodies are the user's: add them to the simulation yourself; the model never removes
// them. The friction listener follows the constraint -- it is in the simulation exactly while the tire's
// constraint is (Constraint::addNotification / removeNotification) -- so a tire added as a plain constraint,
// `sim.add(ConstraintRef(tire))`, behaves as before (constraint and listener, no model recorded in
// getModels()) and is removed with `sim.remove(ConstraintRef(tire))`. The listener is never installed twice.
// Remove a tire the way it was added: after `sim.add(tire)`, removing only its ConstraintRef takes out the
// constraint and the listener but leaves the model listed in getModels() until `sim.remove(tire)`.
#pragma once

#include <memory>

#include "scree/core/listeners.h"
#include "scree/solver/joints.h"
#include "scree/solver/model.h"

namespace scree {

class TwoBodyTireModel : public Joint, public Model {
 public:
  enum DeformationMode { RADIAL = 0, LATERAL, BENDING, TORSIONAL, NUM_MODES };
  /// Constraint DOFs (getCurrentForce(dof), getLastForces()).
  enum Dof { RADIAL_1 = 0, RADIAL_2, LATERAL_DOF, BENDING_1, BENDING_2, TORSIONAL_DOF, NUM_DOFS };

  static constexpr Real defaultRadialStiffness = 3.5e5;   ///< N/m
  static constexpr Real defaultRadialDamping = 7e3;       ///< N s/m
  static constexpr Real defaultStiffness = 3e5;           ///< LATERAL N/m; BENDING, TORSIONAL N m/rad
  static constexpr Real defaultDamping = 5e3;             ///< LATERAL N s/m; BENDING, TORSIONAL N m s/rad

  /// Both bodies non-null and different; radii (m) finite and > 0; localRotationAxis (rim model frame) finite
  /// and non-zero. The bodies must be placed (rest configuration) before construction.
  TwoBodyTireModel(RigidBodyRef tireBody, Real tireRadius, RigidBodyRef rimBody, Real rimRadius,
                   const Vec3& localRotationAxis = Vec3::UnitY());
  ~TwoBodyTireModel() override;

  /// Stiffness of a mode, finite and > 0: N/m (RADIAL, LATERAL) or N m/rad (BENDING, TORSIONAL).
  void setStiffness(Real stiffness, DeformationMode mode);
  Real getStiffness(DeformationMode mode) const;
  /// Damping coefficient of a mode, finite and >= 0: N s/m or N m s/rad. (Hides Constraint::setDamping, whose
  /// SPOOK damping times the tire does not use.)
  void setDamping(Real dampingCoefficient, DeformationMode mode);
  Real getDamping(DeformationMode mode) const;

  RigidBody* getTireBody() const { return a_.get(); }
  RigidBody* getRimBody() const { return b_.get(); }
  Real getTireRadius() const { return tireRadius_; }
  Real getRimRadius() const { return rimRadius_; }
  /// Rotation axis in the rim's model frame (unit) and in the world (the rim frame's current axle).
  Vec3 getLocalRotationAxis() const { return localAxis_; }
  Vec3 getRotationAxis() const;

  // ---- read-outs (current state, i.e. after the last step) ------------------------------------------------
  /// Deformation of a mode: RADIAL in-plane offset of the tire from the rim, >= 0 (m); LATERAL signed offset
  /// along the axle (m); BENDING magnitude of the tilt of the tire against the rim (rad); TORSIONAL signed
  /// wind-up of the tire about the axle relative to the rim (rad, right hand about getRotationAxis()).
  Real getDeformation(DeformationMode mode) const;
  Real getRadialDeflection() const { return getDeformation(RADIAL); }
  Real getLateralOffset() const { return getDeformation(LATERAL); }
  Real getBendingAngle() const { return getDeformation(BENDING); }
  Real getTorsionAngle() const { return getDeformation(TORSIONAL); }
  /// The tire centre's in-plane offset from the rim centre, world (m).
  Vec3 getRadialDeflectionVector() const;
  /// Force (N) or torque (N m) the mode applied on the tire in the last step (the rim got the opposite):
  /// world vector, and its magnitude (RADIAL, BENDING) or signed component along the axle (LATERAL, TORSIONAL).
  Vec3 getForceVector(DeformationMode mode) const;
  Real getForce(DeformationMode mode) const;

  /// Whether tire contacts get their primary friction direction along the rolling direction (default true).
  void setEnableFrictionAlignment(bool e) { alignFriction_ = e; }
  bool getEnableFrictionAlignment() const { return alignFriction_; }

  // ---- used by the simulation -------------------------------------------------------------------------------
  void addRows(const ConstraintContext& ctx, std::vector<detail::ConstraintRow>& rows, std::vector<int>& outDofs) override;
  void storeResult(const detail::ConstraintRow* rows, const int* dofs, size_t count, Real h) override;
  /// Install / uninstall the friction listener together with the constraint (file comment).
  void addNotification(Simulation& sim) override;
  void removeNotification(Simulation& sim) override;
  /// Sets the friction direction of the tire's points in `contact` (what the listener calls).
  void alignFriction(GeometryContact& contact) const;

 protected:
  /// Model hook: the tire as a constraint, then its friction listener.
  void onAdd(Simulation& sim) override;

 private:
  static void checkMode(const char* where, DeformationMode mode);
  Real tireRadius_, rimRadius_;
  Vec3 localAxis_;
  Real stiffness_[NUM_MODES];
  Real dampingCoef_[NUM_MODES];
  bool alignFriction_ = true;
  // World axes of the last step's in-plane rows (radial, bending) and their impulses as world vectors.
  Vec3 axisX_ = Vec3::UnitX(), axisY_ = Vec3::UnitY(), axisZ_ = Vec3::UnitZ();
  Vec3 radialWarm_ = Vec3::Zero(), bendingWarm_ = Vec3::Zero();
  ContactEventListenerRef listener_;
};
using TwoBodyTireModelRef = std::shared_ptr<TwoBodyTireModel>;

}  // namespace scree
