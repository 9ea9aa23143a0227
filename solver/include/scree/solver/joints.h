// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Joints (AGX: agx::BallJoint, Hinge, Prismatic, LockJoint, DistanceJoint, CylindricalJoint) and a generic
// 6-DOF constraint whose DOFs can each be FREE, LOCKED or COMPLIANT (the tire model is built on it).
//
// Frames: a joint is defined by an attachment frame on each body, both coinciding at construction (so the
// configuration at construction is the rest state). The frame's z axis is the joint axis (hinge, prismatic,
// cylindrical). With body B null the second frame is fixed in the world. Every DOF measures body A relative to
// body B, in B's frame (the world's when B is null): a hinge angle is A's rotation about B's z axis, a
// prismatic position is A's displacement along it. Rows (SPOOK, spook.h) per DOF:
//   translational DOF along frame-B axis u:  g = u . (pA - pB),  J = [u, (rA x u), -u, -(rB x u)]
//   rotational DOF about frame-B axis a:      g = theta_a (log map of qB_frame^-1 qA_frame), J = [0, a, 0, -a]
//   hinge/cylindrical bending rows keep A's axis n_A orthogonal to B's x/y axes p:
//                                             g = n_A . p, J = [0, (n_A x p), 0, -(n_A x p)]
// so a hinge's free angle may grow without bound (no small-angle assumption on it).
//
// Forces: getLastForces()[dof] is the force (N) or torque (N m) the row applied to body A along +axis in the
// last step (body B got the opposite). DOF indices are given by each class's enum.
//
// Controllers on Hinge, Prismatic and CylindricalJoint (AGX: Motor1D, Range1D, Lock1D), each with its own row:
//   Motor1D: velocity row, target speed (rad/s or m/s) within a force range (N m or N).
//   Range1D: unilateral rows keeping the joint position in [lower, upper], SPOOK compliance/damping.
//   Lock1D:  a holonomic row pulling the position to a target: with compliance 1/K and damping D/K it is a
//            spring K with damper D.
#pragma once

#include <memory>

#include "scree/solver/constraint.h"

namespace scree {

/// Frame attached to a body: point and rotation in the body's model frame (or the world when no body).
struct Attachment {
  Vec3 point = Vec3::Zero();
  Quat rotation = Quat::Identity();
};

/// Common frame logic of all joints.
class Joint : public Constraint {
 public:
  /// Attachment frames (in each body's model frame, or world for a null B).
  const Attachment& getAttachment(int i) const { return att_[i]; }
  /// World transform of attachment frame i.
  Transform getFrame(int i) const;

 protected:
  Joint(RigidBodyRef a, RigidBodyRef b, const Vec3& worldPoint, const Quat& worldFrame, int numDofs, const char* type);
  struct FrameState {
    Vec3 pA, pB;  ///< world anchor points
    Vec3 rA, rB;  ///< from each body's centre of mass to its anchor
    Mat3 RA, RB;  ///< world frame axes (columns x, y, z)
    Quat qA, qB;
  };
  FrameState state() const;
  /// state() without the frames' orientations (RA, RB, qA, qB left unset): the anchors and arms, the same values
  /// bit for bit. For joints whose rows need no frame axes (BallJoint).
  FrameState anchors() const;
  /// Holonomic row for `dof`: translational along u (world), angular about a (world), or a custom Jacobian.
  void pushLinear(const ConstraintContext& ctx, std::vector<detail::ConstraintRow>& rows, std::vector<int>& dofs, int dof,
                  const FrameState& f, const Vec3& u, Real g, Real compliance, Real damping) const;
  void pushAngular(const ConstraintContext& ctx, std::vector<detail::ConstraintRow>& rows, std::vector<int>& dofs, int dof,
                   const Vec3& a, Real g, Real compliance, Real damping) const;
  /// Finishes a row whose Jacobian is set: SPOOK holonomic rhs from g (or velocity row when `velocityRow`).
  void finishRow(const ConstraintContext& ctx, detail::ConstraintRow& r, int dof, Real g, Real compliance, Real damping) const;
  /// Bending rows (two DOFs from firstDof) of hinge and cylindrical joints.
  void pushBending(const ConstraintContext& ctx, std::vector<detail::ConstraintRow>& rows, std::vector<int>& dofs,
                   const FrameState& f, int firstDof) const;
  /// Displacement of A along B's z axis (m) and its rate (m/s): the free DOF of slider joints.
  Real slidePosition() const;
  Real slideSpeed() const;
  /// Relative rotation vector of frame A in frame B coordinates (log map).
  static Vec3 rotationError(const FrameState& f);

  Attachment att_[2];
};

// ---- controllers -------------------------------------------------------------------------------------------

class Motor1D {
 public:
  void setEnable(bool e) { enabled_ = e; }
  bool getEnable() const { return enabled_; }
  /// Target speed (rad/s or m/s), finite.
  void setSpeed(Real v);
  Real getSpeed() const { return speed_; }
  /// Force range (N or N m), lower <= upper, lower <= 0 <= upper not required. Default (-inf, inf).
  void setForceRange(Real lower, Real upper);
  Real getForceRangeLower() const { return lo_; }
  Real getForceRangeUpper() const { return hi_; }
  /// Viscous compliance of the motor (m/s per N or rad/s per N m), >= 0. Default 1e-10.
  void setCompliance(Real c);
  Real getCompliance() const { return compliance_; }
  /// Force the motor applied in the last step.
  Real getCurrentForce() const { return force_; }

 private:
  friend class Controlled1DJoint;
  bool enabled_ = false;
  Real speed_ = 0, lo_ = -INFINITY, hi_ = INFINITY, compliance_ = 1e-10, force_ = 0, warm_ = 0;
};

class Range1D {
 public:
  void setEnable(bool e) { enabled_ = e; }
  bool getEnable() const { return enabled_; }
  /// lower <= upper (may be infinite).
  void setRange(Real lower, Real upper);
  Real getLower() const { return lo_; }
  Real getUpper() const { return hi_; }
  void setCompliance(Real c);
  Real getCompliance() const { return compliance_; }
  void setDamping(Real tau);
  Real getDamping() const { return damping_; }
  Real getCurrentForce() const { return force_; }

 private:
  friend class Controlled1DJoint;
  bool enabled_ = false;
  Real lo_ = -INFINITY, hi_ = INFINITY, compliance_ = SpookDefaults::compliance, damping_ = SpookDefaults::damping;
  Real force_ = 0, warm_ = 0;
};

class Lock1D {
 public:
  void setEnable(bool e) { enabled_ = e; }
  bool getEnable() const { return enabled_; }
  void setPosition(Real p);
  Real getPosition() const { return pos_; }
  void setCompliance(Real c);
  Real getCompliance() const { return compliance_; }
  void setDamping(Real tau);
  Real getDamping() const { return damping_; }
  Real getCurrentForce() const { return force_; }

 private:
  friend class Controlled1DJoint;
  bool enabled_ = false;
  Real pos_ = 0, compliance_ = SpookDefaults::compliance, damping_ = SpookDefaults::damping, force_ = 0, warm_ = 0;
};

/// A joint with one free DOF (angle or slide) that carries the three controllers.
class Controlled1DJoint : public Joint {
 public:
  Motor1D& getMotor1D() { return motor_; }
  Range1D& getRange1D() { return range_; }
  Lock1D& getLock1D() { return lock_; }
  /// Current position of the free DOF: hinge angle (rad, continuous across turns) or slide (m).
  virtual Real getAngle() const = 0;
  /// Its rate (rad/s or m/s).
  virtual Real getCurrentSpeed() const = 0;

  void storeResult(const detail::ConstraintRow* rows, const int* dofs, size_t count, Real h) override;

 protected:
  using Joint::Joint;
  /// Appends the controller rows for the free DOF with Jacobian (linA, angA, linB, angB).
  void addControllerRows(const ConstraintContext& ctx, std::vector<detail::ConstraintRow>& rows, std::vector<int>& dofs,
                         int firstDof, const Vec3& linA, const Vec3& angA, const Vec3& linB, const Vec3& angB,
                         Real position) const;
  int controllerDof_ = 0;  ///< DOF index of the motor; range = +1, lock = +2
  Motor1D motor_;
  Range1D range_;
  Lock1D lock_;
};

class BallJoint : public Joint {
 public:
  enum Dof { TRANSLATIONAL_1 = 0, TRANSLATIONAL_2, TRANSLATIONAL_3, NUM_DOFS };
  BallJoint(RigidBodyRef a, RigidBodyRef b, const Vec3& worldPoint);
  void addRows(const ConstraintContext& ctx, std::vector<detail::ConstraintRow>& rows, std::vector<int>& outDofs) override;
};

class Hinge : public Controlled1DJoint {
 public:
  enum Dof { TRANSLATIONAL_1 = 0, TRANSLATIONAL_2, TRANSLATIONAL_3, ROTATIONAL_1, ROTATIONAL_2, MOTOR, RANGE, LOCK, NUM_DOFS };
  /// worldAxis must be finite and non-zero.
  Hinge(RigidBodyRef a, RigidBodyRef b, const Vec3& worldPoint, const Vec3& worldAxis);
  void addRows(const ConstraintContext& ctx, std::vector<detail::ConstraintRow>& rows, std::vector<int>& outDofs) override;
  Real getAngle() const override;
  Real getCurrentSpeed() const override;

 private:
  mutable Real lastAngle_ = 0;
};

class Prismatic : public Controlled1DJoint {
 public:
  enum Dof { TRANSLATIONAL_1 = 0, TRANSLATIONAL_2, ROTATIONAL_1, ROTATIONAL_2, ROTATIONAL_3, MOTOR, RANGE, LOCK, NUM_DOFS };
  Prismatic(RigidBodyRef a, RigidBodyRef b, const Vec3& worldPoint, const Vec3& worldAxis);
  void addRows(const ConstraintContext& ctx, std::vector<detail::ConstraintRow>& rows, std::vector<int>& outDofs) override;
  Real getAngle() const override;
  Real getCurrentSpeed() const override;
};

/// Free translation along and rotation about one axis; controllers act on the translation.
class CylindricalJoint : public Controlled1DJoint {
 public:
  enum Dof { TRANSLATIONAL_1 = 0, TRANSLATIONAL_2, ROTATIONAL_1, ROTATIONAL_2, MOTOR, RANGE, LOCK, NUM_DOFS };
  CylindricalJoint(RigidBodyRef a, RigidBodyRef b, const Vec3& worldPoint, const Vec3& worldAxis);
  void addRows(const ConstraintContext& ctx, std::vector<detail::ConstraintRow>& rows, std::vector<int>& outDofs) override;
  Real getAngle() const override;
  Real getCurrentSpeed() const override;
};

/// Keeps the distance between two anchor points at its initial value.
class DistanceJoint : public Joint {
 public:
  enum Dof { DISTANCE = 0, NUM_DOFS };
  DistanceJoint(RigidBodyRef a, RigidBodyRef b, const Vec3& worldPointA, const Vec3& worldPointB);
  Real getRestLength() const { return length_; }
  /// m, > 0.
  void setRestLength(Real l);
  Real getCurrentLength() const;
  void addRows(const ConstraintContext& ctx, std::vector<detail::ConstraintRow>& rows, std::vector<int>& outDofs) override;

 private:
  Vec3 localB_ = Vec3::Zero();
  Real length_ = 0;
};

/// Six DOFs in the attachment frame of B (world when B is null), each FREE, LOCKED or COMPLIANT.
class Generic6DofJoint : public Joint {
 public:
  enum Dof { TRANSLATIONAL_1 = 0, TRANSLATIONAL_2, TRANSLATIONAL_3, ROTATIONAL_1, ROTATIONAL_2, ROTATIONAL_3, NUM_DOFS };
  enum Mode { FREE = 0, LOCKED, COMPLIANT };
  /// Frame at worldPoint with rotation worldFrame (its axes are the DOF axes). All DOFs LOCKED.
  Generic6DofJoint(RigidBodyRef a, RigidBodyRef b, const Vec3& worldPoint, const Quat& worldFrame = Quat::Identity());
  void setMode(int dof, Mode m);
  Mode getMode(int dof) const;
  /// COMPLIANT with stiffness K (N/m or N m/rad, > 0) and damping coefficient D (N s/m or N m s/rad, >= 0):
  /// SPOOK compliance 1/K, damping time D/K.
  void setStiffness(int dof, Real stiffness, Real dampingCoefficient);
  Real getStiffness(int dof) const;
  Real getDampingCoefficient(int dof) const;
  /// Current deviation of each DOF (A relative to B, in B's frame): translations (m), rotation vector (rad).
  Vec3 getTranslationError() const;
  Vec3 getRotationError() const;
  void addRows(const ConstraintContext& ctx, std::vector<detail::ConstraintRow>& rows, std::vector<int>& outDofs) override;

 private:
  Mode modes_[NUM_DOFS];
  Real stiffness_[NUM_DOFS];
  Real dampingCoef_[NUM_DOFS];
};

/// All six DOFs locked (a Generic6DofJoint at A's model frame).
class LockJoint : public Generic6DofJoint {
 public:
  LockJoint(RigidBodyRef a, RigidBodyRef b);
};

using BallJointRef = std::shared_ptr<BallJoint>;
using HingeRef = std::shared_ptr<Hinge>;
using PrismaticRef = std::shared_ptr<Prismatic>;
using CylindricalJointRef = std::shared_ptr<CylindricalJoint>;
using DistanceJointRef = std::shared_ptr<DistanceJoint>;
using Generic6DofJointRef = std::shared_ptr<Generic6DofJoint>;
using LockJointRef = std::shared_ptr<LockJoint>;

}  // namespace scree
