// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scree/solver/solver.h"

#include "scree/core/errors.h"

namespace scree {

void Solver::setNumIterations(int n) {
  if (n < 1) detail::throwInvalid("Solver::setNumIterations", "numIterations", (long long)n, "must be >= 1");
  iterations_ = n;
}

void Solver::setNumShockIterations(int n) {
  if (n < 1) detail::throwInvalid("Solver::setNumShockIterations", "numShockIterations", (long long)n, "must be >= 1");
  shockIterations_ = n;
}

void Solver::setMaxPivots(int n) {
  if (n < 1) detail::throwInvalid("Solver::setMaxPivots", "maxPivots", (long long)n, "must be >= 1");
  maxPivots_ = n;
}

void Solver::setNumHybridRounds(int n) {
  if (n < 1) detail::throwInvalid("Solver::setNumHybridRounds", "numHybridRounds", (long long)n, "must be >= 1");
  hybridRounds_ = n;
}

void Solver::setNumProjectionIterations(int n) {
  if (n < 1)
    detail::throwInvalid("Solver::setNumProjectionIterations", "numProjectionIterations", (long long)n, "must be >= 1");
  projectionIterations_ = n;
}

void Solver::setPositionProjectionTolerance(Real tol) {
  detail::requirePositive("Solver::setPositionProjectionTolerance", "tolerance", tol);
  projectionTolerance_ = tol;
}

void Solver::setConstraintErrorThreshold(Real e) {
  if (!(e > 0)) detail::throwInvalid("Solver::setConstraintErrorThreshold", "threshold", e, "must be > 0 (may be infinite)");
  constraintErrorThreshold_ = e;
}

void Solver::setRestitutionThreshold(Real v) {
  detail::requireNonNegative("Solver::setRestitutionThreshold", "threshold", v);
  restitutionThreshold_ = v;
}

void Solver::setMaxPenetrationRecoverySpeed(Real v) {
  detail::requireNonNegative("Solver::setMaxPenetrationRecoverySpeed", "speed", v);
  maxRecovery_ = v;
}

}  // namespace scree
