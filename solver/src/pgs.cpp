#include "scree/solver/pgs.h"

#include <algorithm>
#include <cmath>

namespace scree {

namespace {
const SolverBodyState kStatic{};

// mu * lambda_n with mu = +inf meaning "no slip" (and inf * 0 not turning into NaN).
inline Real frictionLimit(Real mu, Real lambdaN) {
  if (std::isinf(mu)) return 1e300;
  return mu * std::max<Real>(lambdaN, 0);
}

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

Real PgsSolver::iterate(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, int iterations) {
  Real maxDelta = 0;
  const size_t n = rows.size();
  for (int it = 0; it < iterations; ++it) {
    maxDelta = 0;
    for (size_t i = 0; i < n; ++i) {
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
        const Real mag = std::sqrt(l1 * l1 + l2 * l2);
        if (mag > lim) {
          const Real sc = mag > 0 ? lim / mag : 0;
          l1 *= sc;
          l2 *= sc;
        }
        d1 = l1 - r.lambda;
        d2 = l2 - s.lambda;
        r.lambda = l1;
        s.lambda = l2;
        applyImpulse(r, d1, bodies);
        applyImpulse(s, d2, bodies);
        maxDelta = std::max({maxDelta, std::abs(d1), std::abs(d2)});
        ++i;
        continue;
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
      maxDelta = std::max(maxDelta, std::abs(d));
    }
  }
  return maxDelta;
}

}  // namespace scree
