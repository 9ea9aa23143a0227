// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// RigidBody (AGX: agx::RigidBody).
//
// Frames: the body (model) frame is what get/setPosition and get/setRotation place. The centre of mass sits
// at getCmLocal() in that frame; it follows from the geometries (or setCmLocal). Linear velocity is the
// velocity of the centre of mass; angular velocity is in world coordinates.
//
// Mass properties: add(geometry) sums volume x material density over the body's non-sensor geometries with
// the parallel-axis transfer; setMass/setInertiaTensor override (an explicit mass alone scales the computed
// inertia by newMass/computedMass so the radius of gyration is kept). A body with no massive geometry has 1 kg
// and unit inertia until set. STATIC and KINEMATICS bodies have infinite mass in the solver.
//
// Layering: RigidBody is core and knows a geometry only as a BodyPart (scree/core/body_part.h), the interface
// core declares and Geometry implements. add(geometry) is a template for that reason alone: the conversion of
// the caller's Geometry pointer to its BodyPart base needs Geometry's definition, which the caller has (it made
// or holds the geometry) and core does not. Calls read as before: body->add(geometry), body->add(nullptr).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "scree/core/body_part.h"
#include "scree/core/math.h"

namespace scree {

class Geometry;
using GeometryRef = std::shared_ptr<Geometry>;
namespace detail {
struct BodyAccess;
}

class RigidBody {
 public:
  enum MotionControl { STATIC = 0, KINEMATICS = 1, DYNAMICS = 2 };

  explicit RigidBody(const std::string& name = "");
  RigidBody(const RigidBody&) = delete;
  RigidBody& operator=(const RigidBody&) = delete;
  ~RigidBody();

  const std::string& getName() const { return name_; }
  void setName(const std::string& n) { name_ = n; }
  /// Unique per process, never reused.
  uint32_t getId() const { return id_; }

  void setMotionControl(MotionControl m);
  MotionControl getMotionControl() const { return motion_; }
  bool isDynamic() const { return motion_ == DYNAMICS; }

  // --- geometries and mass ------------------------------------------------------------------------------
  /// Attaches `geometry` (a GeometryRef; its local frame is relative to this body) and recomputes mass
  /// properties. Throws if geometry is null or already attached to a body.
  template <class G>
  void add(std::shared_ptr<G> geometry) {
    BodyPart* part = geometry.get();  // here, where G is complete (see the file comment)
    attach(GeometryRef(std::move(geometry)), part);
  }
  /// Null: throws std::invalid_argument, as any null geometry.
  void add(std::nullptr_t) { attach(nullptr, nullptr); }
  /// Detaches; returns false when it was not attached here.
  bool remove(const GeometryRef& geometry);
  const std::vector<GeometryRef>& getGeometries() const { return geometries_; }
  /// Recomputes mass, centre of mass and inertia from the geometries, keeping explicit overrides.
  void updateMassProperties();

  /// kg, > 0. Overrides the computed mass (see the file comment).
  void setMass(Real mass);
  Real getMass() const { return mass_; }
  /// 1/kg for a dynamic body, 0 for static and kinematic ones.
  Real getInvMass() const { return motion_ == DYNAMICS ? invMass_ : 0.0; }
  /// kg m^2 about the centre of mass in the body frame; symmetric positive definite.
  void setInertiaTensor(const Mat3& inertia);
  Mat3 getInertiaTensor() const { return inertia_; }
  /// Centre of mass in the body frame, m. Setting it marks it explicit (kept by updateMassProperties).
  void setCmLocal(const Vec3& cm);
  Vec3 getCmLocal() const { return cmLocal_; }
  /// Clears setMass/setInertiaTensor/setCmLocal overrides and recomputes from the geometries.
  void resetMassOverrides();

  // --- placement ---------------------------------------------------------------------------------------
  void setPosition(const Vec3& p);
  Vec3 getPosition() const { return x_ - q_ * cmLocal_; }
  /// Normalised on input. The body frame origin stays in place.
  void setRotation(const Quat& q);
  Quat getRotation() const { return q_; }
  /// Centre of mass in world coordinates.
  Vec3 getCmPosition() const { return x_; }
  /// World transform of the body frame.
  Transform getTransform() const { return {getPosition(), q_}; }

  // --- motion ------------------------------------------------------------------------------------------
  void setVelocity(const Vec3& v);
  Vec3 getVelocity() const { return v_; }
  void setAngularVelocity(const Vec3& w);
  Vec3 getAngularVelocity() const { return w_; }
  /// Velocity of the material point currently at `worldPoint`.
  Vec3 getVelocityAt(const Vec3& worldPoint) const { return v_ + w_.cross(worldPoint - x_); }
  /// World angular momentum about the centre of mass, kg m^2/s.
  Vec3 getAngularMomentum() const;
  /// Translational + rotational kinetic energy, J.
  Real getKineticEnergy() const;
  /// World inverse inertia R I^-1 R^T (zero for non-dynamic bodies).
  Mat3 getInvInertiaWorld() const;

  /// Linear / angular velocity damping, 1/s, >= 0: v <- v / (1 + h c) each step (AGX's definition).
  void setLinearVelocityDamping(Real c);
  Real getLinearVelocityDamping() const { return linDamping_; }
  void setAngularVelocityDamping(Real c);
  Real getAngularVelocityDamping() const { return angDamping_; }

  // --- forces: accumulated until the end of the next step, then cleared ---------------------------------
  void addForce(const Vec3& f);
  void addTorque(const Vec3& t);
  void addForceAtPosition(const Vec3& f, const Vec3& worldPoint);
  Vec3 getForce() const { return force_; }
  Vec3 getTorque() const { return torque_; }
  void clearForces() {
    force_.setZero();
    torque_.setZero();
  }

 private:
  friend struct detail::BodyAccess;
  void attach(GeometryRef geometry, BodyPart* part);
  void applyComputedMass(Real mass, const Vec3& cm, const Mat3& inertia);
  void setInertiaInternal(const Mat3& inertia);

  std::string name_;
  uint32_t id_;
  MotionControl motion_ = DYNAMICS;

  // State: centre of mass x_, orientation q_ of the body frame, COM velocity, world angular velocity.
  Vec3 x_ = Vec3::Zero();
  Quat q_ = Quat::Identity();
  Vec3 v_ = Vec3::Zero();
  Vec3 w_ = Vec3::Zero();
  Vec3 force_ = Vec3::Zero();
  Vec3 torque_ = Vec3::Zero();
  Real linDamping_ = 0;
  Real angDamping_ = 0;

  // Mass properties (body frame). Principal axes: inertia_ = P diag(principal_) P^T, used by the rotation
  // integrator.
  Real mass_ = 1;
  Real invMass_ = 1;
  Vec3 cmLocal_ = Vec3::Zero();
  Mat3 inertia_ = Mat3::Identity();
  Mat3 invInertia_ = Mat3::Identity();
  Vec3 principal_ = Vec3::Ones();
  Quat principalFrame_ = Quat::Identity();
  bool massExplicit_ = false, inertiaExplicit_ = false, cmExplicit_ = false;
  Real computedMass_ = 1;

  std::vector<GeometryRef> geometries_;
  std::vector<BodyPart*> parts_;  // parts_[i] is geometries_[i] seen as a BodyPart
  // Index in the simulation's body list, or -1.
  int simIndex_ = -1;
};
using RigidBodyRef = std::shared_ptr<RigidBody>;

}  // namespace scree
