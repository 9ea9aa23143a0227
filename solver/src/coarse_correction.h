// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Two-level (coarse) correction of contact loads between PGS sweeps (Solver::setUseCoarseCorrection; issue 18,
// docs/solver-internals.md "Coarse correction").
//
// DESIGN. On a stack of N bodies Gauss-Seidel shrinks the slowest load mode (the whole stack's weight moving
// down one level per sweep) by about cos^2(pi / (N + 1)) per sweep: 0.977 for N = 20, so 10 sweeps leave 79 %
// of it, and a tall pyramid without the shock pass sags and rattles. The correction gives the sweeps a coarse
// space, as two-level (multigrid-like) methods do. Its unknowns, per contact manifold carrying load (sum of its
// normal impulses > 0):
//   - the manifold's load: one unknown added equally to all its normal rows;
//   - its tilt: one unknown added to the normal rows in proportion to the point's offset along the manifold's
//     long principal axis (both axes when the points' spread is nearly square, ratio < 1.5). The tilt carries
//     the moment about the short axis. Without it the out-of-plane rocking of a one-box-deep wall (pyramid20
//     seen from the side) grows from round-off by about 10x per second (measured: 1e-14 m/s to 1e-5 m/s in
//     9 s) whatever the number of sweeps, because no sweep moves a moment down twenty levels either. The other
//     axis is left out on elongated manifolds: a body on two supports side by side already carries that moment
//     by the two loads, and the extra unknowns would only add internal (self-equilibrated) load modes, which
//     the coarse system cannot pin down (below);
//   - each sticking manifold friction row (tangent pair, inside 99.9 % of its cone; the twist row is left out).
// The coarse operator P^T (J M^-1 J^T + E) P is assembled per body from the groups' summed Jacobians (E: the
// rows' SPOOK compliance), solved by a sparse LDL^T (Eigen's SimplicialLDLT; its symbolic analysis is kept
// while the pattern holds), and the correction P mu is added to the impulses and the body velocities.
//
// Three guards, each needed (measured on pyramid20 without the shock pass, docs page):
//   - Regularisation. Stacked supports and sticking friction are redundant: internal, self-equilibrated impulse
//     sets are the near-null space of the coarse operator, held only by the compliance (down to 1.5e-7 on the
//     friction rows). A relative diagonal regularisation of 1e-5 (1 + 1e-5 times each diagonal) bounds them.
//     Window measured with friction anchors on: 1e-6 to 1e-4 rest 30 s; 1e-3 lets the rocking grow.
//   - Bounds by refinement. A coarse group whose update would drive a normal row below its bound or a friction
//     row out of its cone is fixed (by a 1e8 diagonal) and the system factored again, up to three rounds: a
//     separating manifold (its load group's residual < 0) is released to zero load first, other violated
//     manifolds are held at no change (tilts before the load), friction groups out of their cone are held.
//     Without this, one friction row near its cone was clamped, the guard below then threw away the whole
//     correction, and the stack fell after 10 s. When groups still leave their bounds after three rounds, the
//     correction is skipped (Result::skipped): on a collapsing pile (pyramid30, which it does not hold) applying
//     it anyway threw boxes at 28 m/s.
//   - Descent guard. After clamping what is left, the step is scaled by alpha = min(1, d^T r / d^T A d) (0 when
//     d^T r <= 0), d the applied change of impulses and r the residual before it, so the quadratic that the
//     sweeps minimise never rises.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include "scree/core/math.h"
#include "scree/solver/constraint_row.h"
#include "scree/solver/pgs.h"

namespace scree::detail {

struct CouplingRange;

/// The coarse correction's storage, kept across steps (no per-step allocation once sizes settle).
class CoarseCorrection {
 public:
  struct Result {
    int unknowns = 0;        ///< coarse unknowns of this correction
    int refinements = 0;     ///< re-factorisations for held groups
    bool analysed = false;   ///< a fresh symbolic analysis was needed
    bool factorised = false; ///< A was factored (false: the same A as the factor kept from the last call)
    Real alpha = 0;          ///< descent guard's step (1: the full correction)
    bool skipped = false;    ///< groups still left their bounds after kRounds refinements: nothing applied
  };
  /// Relative diagonal regularisation (see the header's DESIGN). Default 1e-5.
  static constexpr Real kRegularisation = 1e-5;
  /// Refinement rounds for groups that hit their bounds.
  static constexpr int kRounds = 3;

  /// One correction of rows' impulses and sb's velocities (consistent: v changes by M^-1 J^T dlambda).
  Result apply(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& sb,
               const std::vector<CouplingRange>& couplings);

 private:
  enum Kind : uint8_t { LOAD, TILT, FRICTION };
  void addGroup(const std::vector<ConstraintRow>& rows, const std::vector<SolverBodyState>& sb, uint32_t coupling,
                Kind kind);
  /// A_ from triplets_ for m unknowns, each diagonal times 1 + kRegularisation: the values added straight into
  /// the kept matrix while the triplets' (row, column) sequence is last call's (the same sums in the same order),
  /// else setFromTriplets and a new kept pattern (coarse_correction.cpp).
  void assemble(int m);

  // Groups: entries [entryBegin[g], entryBegin[g + 1]) of (row, weight).
  std::vector<uint32_t> entryBegin_;
  std::vector<std::pair<uint32_t, Real>> entries_;
  std::vector<uint32_t> coupling_;
  std::vector<Kind> kind_;
  std::vector<Vec3> linA_, angA_, linB_, angB_;
  std::vector<int32_t> bodyA_, bodyB_;
  std::vector<Real> residual_;
  std::vector<std::vector<std::pair<int, int>>> byBody_;
  std::vector<Eigen::Triplet<Real>> triplets_;
  // The kept assembly (assemble): last call's triplet (row, column) sequence, each triplet's and each diagonal's
  // index in A_'s value array, and A_'s size (-1: none kept).
  std::vector<std::pair<int, int>> tripletKey_;
  std::vector<int> tripletSlot_, diagonalSlot_;
  int keptRows_ = -1;
  Eigen::SparseMatrix<Real> A_, held_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<Real>, Eigen::Lower> ldlt_;
  std::vector<int> patternOuter_, patternInner_;
  bool analysed_ = false;
  bool factorOfA_ = false;             ///< ldlt_ holds the factor of A with factoredValues_ (not a held system)
  std::vector<Real> factoredValues_;
  // Rows the correction may change, their impulses and residuals before it, the per-row change.
  std::vector<uint32_t> touched_;
  std::vector<int> slot_;
  std::vector<Real> lambda0_, residual0_, delta_;
  std::vector<Vec3> v0_, w0_;
  std::vector<char> fixed_;
  std::vector<Real> target_;
};

}  // namespace scree::detail
