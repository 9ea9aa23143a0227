// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scree/solver/constraint.h"

#include "scree/core/errors.h"

namespace scree {

using detail::ConstraintRow;  // the solver row type (scree/solver/constraint_row.h)

Constraint::Constraint(RigidBodyRef a, RigidBodyRef b, int numDofs, const char* typeName)
    : a_(std::move(a)), b_(std::move(b)), typeName_(typeName) {
  const std::string where = std::string(typeName) + "::" + typeName;
  detail::requireNonNull(where, "rigidBody1", a_.get());
  if (a_ == b_) throw std::invalid_argument(where + ": rigidBody2 is invalid (must differ from rigidBody1)");
  compliance_.assign(numDofs, SpookDefaults::compliance);
  damping_.assign(numDofs, SpookDefaults::damping);
  lastForce_.assign(numDofs, 0.0);
  warm_.assign(numDofs, 0.0);
}

void Constraint::checkDof(const char* where, int dof) const {
  if (dof < 0 || dof >= getNumDofs())
    detail::throwInvalid(std::string(typeName_) + "::" + where, "dof", (long long)dof,
                         "must be in [0, " + std::to_string(getNumDofs()) + ")");
}

void Constraint::setCompliance(Real c) {
  detail::requireNonNegative(std::string(typeName_) + "::setCompliance", "compliance", c);
  compliance_.assign(compliance_.size(), c);
}
void Constraint::setCompliance(Real c, int dof) {
  checkDof("setCompliance", dof);
  detail::requireNonNegative(std::string(typeName_) + "::setCompliance", "compliance", c);
  compliance_[dof] = c;
}
Real Constraint::getCompliance(int dof) const {
  checkDof("getCompliance", dof);
  return compliance_[dof];
}
void Constraint::setDamping(Real tau) {
  detail::requireNonNegative(std::string(typeName_) + "::setDamping", "damping", tau);
  damping_.assign(damping_.size(), tau);
}
void Constraint::setDamping(Real tau, int dof) {
  checkDof("setDamping", dof);
  detail::requireNonNegative(std::string(typeName_) + "::setDamping", "damping", tau);
  damping_[dof] = tau;
}
Real Constraint::getDamping(int dof) const {
  checkDof("getDamping", dof);
  return damping_[dof];
}
Real Constraint::getCurrentForce(int dof) const {
  checkDof("getCurrentForce", dof);
  return lastForce_[dof];
}

void Constraint::storeResult(const ConstraintRow* rows, const int* dofs, size_t count, Real h) {
  std::fill(lastForce_.begin(), lastForce_.end(), 0.0);
  std::fill(warm_.begin(), warm_.end(), 0.0);
  for (size_t k = 0; k < count; ++k) {
    lastForce_[dofs[k]] += rows[k].lambda / h;
    warm_[dofs[k]] += rows[k].lambda;
  }
}

}  // namespace scree
