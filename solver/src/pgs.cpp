#include "scree/solver/pgs.h"

#include <algorithm>
#include <cmath>

#include "contact_law.h"
#include "scree/core/assert.h"

namespace scree::detail {

namespace {
const SolverBodyState kStatic{};

inline Real rowVelocity(const ConstraintRow& r, const std::vector<SolverBodyState>& b) {
  Real jv = 0;
  if (r.bodyA >= 0) jv += r.jLinA.dot(b[r.bodyA].v) + r.jAngA.dot(b[r.bodyA].w);
  if (r.bodyB >= 0) jv += r.jLinB.dot(b[r.bodyB].v) + r.jAngB.dot(b[r.bodyB].w);
  return jv;
}

inline void applyImpulse(const ConstraintRow& r, Real d, std::vector<SolverBodyState>& b) {
  if (r.bodyA >= 0) {
    b[r.bodyA].v += r.mJLinA * d;
    b[r.bodyA].w += r.mJAngA * d;
  }
  if (r.bodyB >= 0) {
    b[r.bodyB].v += r.mJLinB * d;
    b[r.bodyB].w += r.mJAngB * d;
  }
}

}  // namespace

void PgsSolver::prepare(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies) {
  for (ConstraintRow& r : rows) {
    SCREE_ASSERT(r.bodyA < int32_t(bodies.size()) && r.bodyB < int32_t(bodies.size()));
    SCREE_VALIDATE_CHECK(r.jLinA.allFinite() && r.jAngA.allFinite() && r.jLinB.allFinite() && r.jAngB.allFinite());
    const SolverBodyState& A = r.bodyA >= 0 ? bodies[r.bodyA] : kStatic;
    const SolverBodyState& B = r.bodyB >= 0 ? bodies[r.bodyB] : kStatic;
    r.mJLinA = A.invMass * r.jLinA;
    r.mJAngA = A.invInertia * r.jAngA;
    r.mJLinB = B.invMass * r.jLinB;
    r.mJAngB = B.invInertia * r.jAngB;
    Real k = r.e;
    if (r.bodyA >= 0) k += r.jLinA.dot(r.mJLinA) + r.jAngA.dot(r.mJAngA);
    if (r.bodyB >= 0) k += r.jLinB.dot(r.mJLinB) + r.jAngB.dot(r.mJAngB);
    r.diag = k;
    r.invDiag = k > 0 ? 1.0 / k : 0.0;
  }
  for (size_t i = 0; i < rows.size(); ++i) {
    ConstraintRow& r = rows[i];
    if (r.lambda != 0) applyImpulse(r, r.lambda, bodies);
  }
}

// One Gauss-Seidel update of row i, or of the projected-cone pair (i, i+1). Returns |delta lambda|.
static Real solveUnit(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, size_t i) {
  ConstraintRow& r = rows[i];
  if (r.pairedRow == int32_t(i) + 1) {
    // Projected cone: a scalar Gauss-Seidel update of each tangent row at the same velocity, then the pair is
    // projected radially onto the disc |lambda_t| <= mu lambda_n. Solving the 2x2 block exactly before the
    // projection would be wrong for sliding: K^-1 r couples the tangents through the point's lever arm, so the
    // projected impulse would not oppose the sliding velocity (a sliding box then drifts sideways).
    ConstraintRow& s = rows[i + 1];
    Real d1 = (r.rhs - rowVelocity(r, bodies) - r.e * r.lambda) * r.invDiag;
    Real d2 = (s.rhs - rowVelocity(s, bodies) - s.e * s.lambda) * s.invDiag;
    Real l1 = r.lambda + d1, l2 = s.lambda + d2;
    const Real lim = r.normalRow >= 0 ? frictionLimit(r.mu, rows[r.normalRow].lambda) : r.hi;
    projectOntoDisc(l1, l2, lim);
    d1 = l1 - r.lambda;
    d2 = l2 - s.lambda;
    r.lambda = l1;
    s.lambda = l2;
    applyImpulse(r, d1, bodies);
    applyImpulse(s, d2, bodies);
    return std::max(std::abs(d1), std::abs(d2));
  }
  Real lo = r.lo, hi = r.hi;
  if (r.normalRow >= 0) {
    // Scaled box: bounds follow the current normal impulse.
    const Real lim = frictionLimit(r.mu, rows[r.normalRow].lambda);
    lo = -lim;
    hi = lim;
  }
  const Real delta = (r.rhs - rowVelocity(r, bodies) - r.e * r.lambda) * r.invDiag;
  const Real nl = std::clamp(r.lambda + delta, lo, hi);
  const Real d = nl - r.lambda;
  r.lambda = nl;
  if (d != 0) applyImpulse(r, d, bodies);
  return std::abs(d);
}

Real PgsSolver::iterate(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, int iterations) {
  // Symmetric Gauss-Seidel: sweeps alternate forward and backward. On chains (joints, stacks) a one-way sweep
  // carries information one link per sweep in one direction only; alternating halves the propagation time and,
  // with SPOOK's stabilisation, keeps long stiff chains stable at the default iteration count where one-way
  // sweeps left enough residual to feed an oscillation.
  Real maxDelta = 0;
  const size_t n = rows.size();
  for (int it = 0; it < iterations; ++it) {
    maxDelta = 0;
    if (it % 2 == 0) {
      for (size_t i = 0; i < n; ++i) {
        maxDelta = std::max(maxDelta, solveUnit(rows, bodies, i));
        if (rows[i].pairedRow == int32_t(i) + 1) ++i;
      }
    } else {
      for (size_t j = n; j-- > 0;) {
        if (j > 0 && rows[j - 1].pairedRow == int32_t(j)) --j;
        maxDelta = std::max(maxDelta, solveUnit(rows, bodies, j));
      }
    }
  }
  return maxDelta;
}

Real PgsSolver::iterate(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, int iterations,
                        const std::vector<uint32_t>& subset) {
  Real maxDelta = 0;
  const size_t n = subset.size();
  for (int it = 0; it < iterations; ++it) {
    maxDelta = 0;
    if (it % 2 == 0) {
      for (size_t k = 0; k < n; ++k) {
        const uint32_t i = subset[k];
        maxDelta = std::max(maxDelta, solveUnit(rows, bodies, i));
        if (rows[i].pairedRow == int32_t(i) + 1) ++k;
      }
    } else {
      for (size_t k = n; k-- > 0;) {
        if (k > 0 && rows[subset[k - 1]].pairedRow == int32_t(subset[k])) --k;
        maxDelta = std::max(maxDelta, solveUnit(rows, bodies, subset[k]));
      }
    }
  }
  return maxDelta;
}

void PgsSolver::shockPass(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies,
                          const std::vector<ShockRange>& ranges, int maxSweeps) {
  auto solveFrozen = [&](ConstraintRow& r, int frozen, Real lo, Real hi) -> Real {
    // Diagonal with only the free body's mass.
    Real k = r.e;
    if (frozen != 0 && r.bodyA >= 0) k += r.jLinA.dot(r.mJLinA) + r.jAngA.dot(r.mJAngA);
    if (frozen != 1 && r.bodyB >= 0) k += r.jLinB.dot(r.mJLinB) + r.jAngB.dot(r.mJAngB);
    if (!(k > 0)) return 0;
    const Real delta = (r.rhs - rowVelocity(r, bodies) - r.e * r.lambda) / k;
    const Real nl = std::clamp(r.lambda + delta, lo, hi);
    const Real d = nl - r.lambda;
    r.lambda = nl;
    if (d != 0) {
      if (frozen != 0 && r.bodyA >= 0) {
        bodies[r.bodyA].v += r.mJLinA * d;
        bodies[r.bodyA].w += r.mJAngA * d;
      }
      if (frozen != 1 && r.bodyB >= 0) {
        bodies[r.bodyB].v += r.mJLinB * d;
        bodies[r.bodyB].w += r.mJAngB * d;
      }
    }
    return d;
  };
  for (const ShockRange& sr : ranges)
  for (int sweep = 0; sweep < maxSweeps; ++sweep) {
    Real change = 0, scale = 0;
    // Normals (rows without a normalRow link) first, then the friction rows bounded by them.
    for (uint32_t i = sr.begin; i < sr.begin + sr.count; ++i)
      if (rows[i].normalRow < 0 && rows[i].pairedRow < 0) {
        change = std::max(change, std::abs(solveFrozen(rows[i], sr.frozen, rows[i].lo, rows[i].hi)));
        scale = std::max(scale, std::abs(rows[i].lambda));
      }
    for (uint32_t i = sr.begin; i < sr.begin + sr.count; ++i) {
      ConstraintRow& r = rows[i];
      if (r.normalRow < 0) continue;
      const Real lim = frictionLimit(r.mu, rows[r.normalRow].lambda);
      if (r.pairedRow == int32_t(i) + 1) {
        ConstraintRow& s = rows[i + 1];
        change = std::max(change, std::abs(solveFrozen(r, sr.frozen, -lim, lim)));
        change = std::max(change, std::abs(solveFrozen(s, sr.frozen, -lim, lim)));
        const Real mag = std::hypot(r.lambda, s.lambda);
        if (mag > lim) {
          // Project the pair back onto the disc and undo the excess on the free body.
          const Real sc = mag > 0 ? lim / mag : 0;
          const Real d1 = r.lambda * sc - r.lambda, d2 = s.lambda * sc - s.lambda;
          r.lambda += d1;
          s.lambda += d2;
          for (auto [row, d] : {std::pair<ConstraintRow*, Real>{&r, d1}, {&s, d2}}) {
            if (sr.frozen != 0 && row->bodyA >= 0) {
              bodies[row->bodyA].v += row->mJLinA * d;
              bodies[row->bodyA].w += row->mJAngA * d;
            }
            if (sr.frozen != 1 && row->bodyB >= 0) {
              bodies[row->bodyB].v += row->mJLinB * d;
              bodies[row->bodyB].w += row->mJAngB * d;
            }
          }
        }
        ++i;
      } else {
        change = std::max(change, std::abs(solveFrozen(r, sr.frozen, -lim, lim)));
      }
    }
    // Converged: the support's impulses moved by less than 1e-9 of their size (a warm-started resting stack
    // gets here after one or two sweeps).
    if (change <= 1e-9 * scale) break;
  }
}

}  // namespace scree::detail
