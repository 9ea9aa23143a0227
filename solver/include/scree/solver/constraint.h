// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Constraint base class (AGX: agx::Constraint). A constraint between body A and body B (B may be null: the
// world) contributes scalar rows per step. Each row (DOF) has its own SPOOK compliance and damping time
// (defaults 1e-8 and 2/60 s, see spook.h); the force each row applied in the last step is readable per DOF.
//
// The two bodies of a constraint do not collide with each other while it is in a simulation, unless
// setEnableCollisions(true) (AGX's default too).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "scree/core/material.h"
#include "scree/core/rigid_body.h"
#include "scree/solver/constraint_row.h"
#include "scree/solver/spook.h"

namespace scree {

class Simulation;

/// What a constraint needs to write its rows.
struct ConstraintContext {
  Real h = 1.0 / 60.0;
  int32_t indexA = -1, indexB = -1;  ///< solver body indices of getBodyAt(0/1); -1 = world or static
};

class Constraint {
 public:
  /// a must not be null; b may be null (the world). a and b must differ.
  Constraint(RigidBodyRef a, RigidBodyRef b, int numDofs, const char* typeName);
  virtual ~Constraint() = default;

  RigidBody* getBodyAt(size_t i) const { return i == 0 ? a_.get() : b_.get(); }
  const RigidBodyRef& getBodyRef(size_t i) const { return i == 0 ? a_ : b_; }
  const std::string& getName() const { return name_; }
  /// The class name given at construction ("BallJoint", "Hinge", "TwoBodyTireModel", ...).
  const char* getTypeName() const { return typeName_; }
  void setName(const std::string& n) { name_ = n; }

  void setEnable(bool e) { enabled_ = e; }
  bool getEnable() const { return enabled_; }
  /// Whether A and B collide with each other (default false).
  void setEnableCollisions(bool e) { collide_ = e; }
  bool getEnableCollisions() const { return collide_; }

  int getNumDofs() const { return int(compliance_.size()); }
  /// Compliance (m/N or rad/(N m)), >= 0, for every DOF or for one (dof in [0, getNumDofs())).
  void setCompliance(Real c);
  void setCompliance(Real c, int dof);
  Real getCompliance(int dof) const;
  /// SPOOK damping time, s, >= 0, for every DOF or for one.
  void setDamping(Real tau);
  void setDamping(Real tau, int dof);
  Real getDamping(int dof) const;
  void setSolveType(FrictionModel::SolveType t) { solveType_ = t; }
  FrictionModel::SolveType getSolveType() const { return solveType_; }

  /// Force (N) or torque (N m) each DOF applied in the last step, along the row's direction. Fills `out`
  /// with getNumDofs() values (0 for DOFs that were inactive).
  const std::vector<Real>& getLastForces() const { return lastForce_; }
  Real getCurrentForce(int dof) const;

  // ---- used by the simulation ----------------------------------------------------------------------------
  /// Appends this step's rows. Row k of the output must record its DOF in `outDofs` (same length).
  virtual void addRows(const ConstraintContext& ctx, std::vector<detail::ConstraintRow>& rows, std::vector<int>& outDofs) = 0;
  /// Receives the solved rows appended by addRows (same order) to keep warm-start impulses and forces.
  virtual void storeResult(const detail::ConstraintRow* rows, const int* dofs, size_t count, Real h);
  /// Called by Simulation::add / remove (AGX: addNotification / removeNotification): a model built on a
  /// constraint may register or unregister its listeners here. Default: nothing.
  virtual void addNotification(Simulation&) {}
  virtual void removeNotification(Simulation&) {}

 protected:
  void checkDof(const char* where, int dof) const;
  RigidBodyRef a_, b_;
  std::string name_;
  bool enabled_ = true;
  bool collide_ = false;
  std::vector<Real> compliance_, damping_;
  std::vector<Real> lastForce_;
  std::vector<Real> warm_;  ///< last impulse per DOF
  /// Default DIRECT_AND_ITERATIVE (AGX's default for constraints): the rows are solved by the direct solver and
  /// then swept by PGS with the iterative rows (contacts) of the step, which couples them; with no iterative
  /// rows it is a pure direct solve. See docs/speed-accuracy.md for the measurements.
  FrictionModel::SolveType solveType_ = FrictionModel::DIRECT_AND_ITERATIVE;
  const char* typeName_;
};
using ConstraintRef = std::shared_ptr<Constraint>;

}  // namespace scree
