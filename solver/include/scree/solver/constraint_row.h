// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// One scalar constraint row as the PGS and DIRECT solvers see it. Joints, contacts and models fill rows of
// this form; solvers read only these and the body arrays (core types), so tests can feed hand-built rows.
//
// Row:  J = [jLinA, jAngA, jLinB, jAngB] acting on (v_a, w_a, v_b, w_b); body index -1 = world/static.
// Solve: find lambda in [lo, hi] with (J M^-1 J^T + e) lambda = rhs - J v (PGS: one row at a time).
#pragma once

#include <cstdint>

#include "scree/core/material.h"
#include "scree/core/math.h"

namespace scree::detail {

struct ConstraintRow {
  int32_t bodyA = -1, bodyB = -1;  ///< indices into the solver body array, -1 = none
  Vec3 jLinA = Vec3::Zero(), jAngA = Vec3::Zero();
  Vec3 jLinB = Vec3::Zero(), jAngB = Vec3::Zero();
  Real rhs = 0;     ///< target of J v+ + e lambda (velocity units)
  Real e = 0;       ///< SPOOK regularisation
  Real lo = -1e300, hi = 1e300;  ///< impulse bounds, N s
  Real lambda = 0;  ///< accumulated impulse (warm start in, result out)
  /// Friction rows: index of the normal row their bounds scale with (-1: fixed bounds), and mu.
  int32_t normalRow = -1;
  Real mu = 0;
  /// Projected-cone friction: index of the partner tangent row (solved as a 2x2 block), or -1.
  int32_t pairedRow = -1;
  FrictionModel::SolveType solveType = FrictionModel::ITERATIVE;
  /// Tangential (friction or rolling) row of a contact: SPLIT and DIRECT_AND_ITERATIVE send it to PGS.
  bool friction = false;
  /// Lever arms |r| from each body's centre of mass to the point the row acts at (joints' linear rows), m; used
  /// for the geometric-stiffness term of the direct solve (Simulation::solve). 0: none.
  Real leverA = 0, leverB = 0;
  /// Holonomic equality rows of a joint's own DOFs (not controllers): the position drift g + eps * f, the part of the position
  /// error g that the elastic stretch of the last force f (compliance eps) does not account for, in m or rad.
  /// Read by the post-step position projection (Solver::setUsePositionProjection). 0 for other rows.
  Real drift = 0;
  bool holonomic = false;

  // ---- Contact manifolds (issue 18: resting stacks; built by solver/src/contact_rows.cpp, solved in pgs.cpp) ----
  /// Friction rows: the number of consecutive normal rows from normalRow whose impulses sum into the bound.
  /// Manifold friction (one tangent pair at the manifold's centre and one twist row) is bounded by
  /// mu * sum(lambda_n) (twist: mu * r_eff * sum(lambda_n)); per-point friction has 1.
  int32_t normalCount = 1;
  /// Normal rows of a planar manifold solved as one block (PgsSolver: solveNormalBlock): every row of the block
  /// holds the first row's index and the count (0: solved alone), and its point's coordinates along the
  /// manifold's principal axes from its centre, scaled so that sum(u^2) = sum(v^2) = count (0 on a degenerate
  /// axis: collinear or coincident points).
  int32_t blockBegin = -1, blockCount = 0;
  Real blockU = 0, blockV = 0;
  /// The block's precomputed operators in PgsBlocks (set by PgsSolver::prepare on a block's first row when a
  /// PgsBlocks is given; -1: none, the block is then assembled on every visit).
  int32_t blockSlot = -1;

  // Filled by the solver's prepare step.
  Vec3 mJLinA = Vec3::Zero(), mJAngA = Vec3::Zero(), mJLinB = Vec3::Zero(), mJAngB = Vec3::Zero();  ///< M^-1 J^T
  Real invDiag = 0;                      ///< 1 / (J M^-1 J^T + e)
  Real diag = 0;                         ///< J M^-1 J^T + e
};

/// The default row, for appending new rows as copies: block moves, where value-initialising each ~350-byte row
/// field by field cost pyramid20 2.4 % of its step (issue 18; contact_rows.cpp, joints.cpp).
inline const ConstraintRow& defaultConstraintRow() {
  static const ConstraintRow kDefault{};
  return kDefault;
}

}  // namespace scree::detail
