// Projected Gauss-Seidel on the Schur form (docs/design.md §4). Reads only core types and rows, so tests can feed
// hand-built systems.
//
// Per row i: delta = (rhs_i - J_i v - e_i lambda_i) / (J_i M^-1 J_i^T + e_i), lambda_i <- clamp(lambda_i + delta),
// v <- v + M^-1 J_i^T (clamped delta). Friction bounds follow the row's normal row (scaled box and the
// projected cone use the current normal iterate, box uses fixed lo/hi). Paired tangent rows (projected cone)
// get scalar updates at the same velocity, then the pair is projected onto the disc |lambda_t| <= mu lambda_n.
// Warm starting: rows arrive with lambda from last step; prepare() applies those impulses first.
#pragma once

#include <cstdint>
#include <vector>

#include "scree/core/math.h"
#include "scree/solver/constraint_row.h"
#include "scree/solver/solver.h"

namespace scree::detail {

/// Velocities and inverse mass of one body as the solver sees it (world frame, at the centre of mass).
struct SolverBodyState {
  Vec3 v = Vec3::Zero();
  Vec3 w = Vec3::Zero();
  Real invMass = 0;
  Mat3 invInertia = Mat3::Zero();
};

class PgsSolver {
 public:
  /// Computes M^-1 J^T and the diagonals, then applies the warm-start impulses to the velocities.
  static void prepare(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies);
  /// `iterations` sweeps over all rows in order. Returns the largest |delta lambda| of the last sweep.
  static Real iterate(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, int iterations);
  /// The same sweeps over the rows listed in `subset` only (ascending indices; a projected-cone pair must be
  /// listed whole); the other rows' impulses are held fixed. Used by the hybrid direct/iterative solve.
  static Real iterate(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, int iterations,
                      const std::vector<uint32_t>& subset);

  /// A row range whose body `frozen` (0 = A, 1 = B) is held immovable in the shock-propagation pass.
  struct ShockRange {
    uint32_t begin, count;
    int frozen;
  };
  /// Shock propagation (Guendelman, Bridson & Fedkiw 2003): after the sweeps, the given row ranges (ordered
  /// from the ground up) are solved in turn, each with its lower body held immovable, up to `maxSweeps`
  /// Gauss-Seidel sweeps per range (fewer once its impulses stop changing). Rows of a range are visited
  /// normals first.
  ///
  /// Why: plain PGS with warm starting has a loop gain of about 2 from one step to the next (an impulse error
  /// e leaves a velocity error that shifts the next step's solution by e again), so the sweeps must cut the
  /// error by more than half every step. On a stack of N bodies Gauss-Seidel contracts by ~1 - c/N^2 per
  /// sweep: towers of three or more boxes rocked at 10-64 sweeps. Solving each support with the lower body
  /// fixed removes the coupling down the stack, and sweeping each support to convergence makes its 4-point
  /// manifold consistent, so the loop gain drops below one.
  static void shockPass(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies,
                        const std::vector<ShockRange>& ranges, int maxSweeps);
};

}  // namespace scree::detail
