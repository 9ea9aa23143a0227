// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// DIRECT solver on SuiteSparse CHOLMOD (docs/design.md §4). Reads only core types and rows, like PGS, so tests can
// feed hand-built systems.
//
// The rows of the direct set D are solved together with every other row's impulse held fixed (their effect is
// already in the body velocities). With v_f the velocities without D's impulses, the system is the mixed LCP
//   A lambda = b,  A = G M^-1 G^T + E,  b = rhs - G v_f,   lo <= lambda <= hi  (complementary to w = A lambda - b)
// Kinematic bodies (invMass 0, prescribed velocity) are not unknowns: their part of G v is moved into b.
// solved in one of two forms:
//   SCHUR  A itself (symmetric positive definite since E > 0): CHOLMOD LL^T.
//   KKT    [M  -G^T; -G  -E] [v+; lambda] = [M v_f; -rhs], quasi-definite (M > 0, E > 0): CHOLMOD simplicial
//          LDL^T without pivoting (quasi-definite matrices factor stably in any symmetric order, Vanderbei 1995).
//          Body blocks stay 6x6 however many rows a body carries; the Schur form fills in deg^2 entries per body.
// Rows with e = 0 (speculative contacts, friction without surface viscosity) get e = 1e-9 * (G M^-1 G^T)_ii so
// both forms stay definite; the change in lambda is of that relative size.
//
// Bounds: block pivoting over an active set (Judice & Pires 1994 for box-constrained LCPs). A row is free or held
// at its lower or upper bound; a held row's line of the matrix is replaced by the identity (diagonal kept), so the
// sparsity pattern -- and CHOLMOD's symbolic analysis -- stays the same across pivots and across steps. After each
// numeric factorisation and solve, free rows outside their bounds are moved to the bound and held rows whose
// w has the wrong sign are freed, all at once; if the number of infeasible rows has not dropped for three
// iterations only the worst one changes per iteration (Murty's single principal pivot, finite for P-matrices).
// Friction rows whose normal is in the set take the bounds +-mu * lambda_n (a box per direction: projected-cone
// pairs are solved as scaled boxes here) in an outer loop: bounds frozen from the last pass's normals, the box LCP
// solved by pivoting, until the bounds stop moving. Past `maxPivots` factorisations in all (pivoting and passes)
// the solve reports failure (the caller finishes the set with PGS and logs it).
//
// Equality systems (every row unbounded: joints, a particle lump with infinite friction and adhesion and zero
// adhesive overlap -- the manual's DIRECT particle mode) need one factorisation and no pivot.
//
// Symbolic analysis (AMD ordering, elimination tree) is kept while the pattern (column pointers and row indices)
// is unchanged, per form.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "scree/solver/constraint_row.h"
#include "scree/solver/pgs.h"
#include "scree/solver/solver.h"

namespace scree::detail {

class DirectSolver {
 public:
  struct Settings {
    Solver::DirectForm form = Solver::AUTO;
    int maxPivots = 50;
  };
  struct Result {
    bool converged = true;         ///< false: pivot cap hit or not definite (impulses and velocities unchanged)
    int factorisations = 0;
    int pivots = 0;                ///< active-set changes
    int symbolicAnalyses = 0;      ///< 0 when the cached analysis was reused
    Solver::DirectForm form = Solver::SCHUR;
    Real residual = 0;             ///< complementarity residual (see SolverStats), N s
    double factorSeconds = 0;
  };
  /// AUTO picks KKT when nnz(Schur) > kktRatio * nnz(KKT) (upper triangles).
  static constexpr Real kktRatio = 1.0;

  DirectSolver();
  ~DirectSolver();
  DirectSolver(const DirectSolver&) = delete;
  DirectSolver& operator=(const DirectSolver&) = delete;

  /// Whether the build has SuiteSparse (SCREE_WITH_SUITESPARSE); without it solve() returns converged = false.
  static bool available();

  /// Solves rows[set[k]] (ascending indices) with all other rows held. `rows` must have been through
  /// PgsSolver::prepare (M^-1 J^T, diagonals) and `bodies` must hold the velocities with every row's current
  /// impulse applied. On return the set's lambdas are the solution and the bodies' velocities include them.
  Result solve(std::vector<ConstraintRow>& rows, const std::vector<uint32_t>& set,
               std::vector<SolverBodyState>& bodies, const Settings& settings);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace scree::detail
