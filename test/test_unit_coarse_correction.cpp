// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The coarse correction between PGS sweeps (solver/src/coarse_correction.h, Solver::setUseCoarseCorrection) on
// hand-built rows with closed-form answers:
//   - a straight stack of 20 boxes, each contact a square 4-point manifold, cold-started: the rows' exact
//     solution lies in the coarse space (per manifold: load and two tilts), so one correction after 2 sweeps
//     gives every contact the weight above it, where 10 plain sweeps leave the bottom contact far short;
//   - a separating top box whose warm start still holds a load: the correction must release that contact to its
//     bound, keep every impulse within its bound and lower the quadratic the sweeps minimise to its minimum.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "coarse_correction.h"
#include "contact_rows.h"
#include "scree/solver/pgs.h"

using namespace scree;
using namespace scree::detail;

namespace {

constexpr Real kG = 9.81, kH = 1.0 / 60.0, kMass = 1.0, kHalf = 0.25;

struct Stack {
  std::vector<ConstraintRow> rows;
  std::vector<SolverBodyState> bodies;
  std::vector<CouplingRange> couplings;
};

/// n unit-mass cubes (half extent 0.25 m) stacked on the world, velocities after one step of gravity (-g h);
/// contact k (below body k) has four normal rows at the corners of the 0.5 x 0.5 face, target J v = 0.
Stack buildStack(int n, Real spinX = 0) {
  Stack s;
  const Real inertia = kMass * (2 * kHalf) * (2 * kHalf) / 6;  // cube: m a^2 / 6 with a the edge
  for (int k = 0; k < n; ++k) {
    SolverBodyState b;
    b.v = Vec3(0, 0, -kG * kH);
    b.w = Vec3((k % 2 ? -1 : 1) * spinX, 0, 0);
    b.invMass = 1 / kMass;
    b.invInertia = Mat3::Identity() / inertia;
    s.bodies.push_back(b);
  }
  const Vec3 up(0, 0, 1);
  for (int k = 0; k < n; ++k) {
    const uint32_t begin = uint32_t(s.rows.size());
    for (int c = 0; c < 4; ++c) {
      const Vec3 corner((c & 1) ? kHalf : -kHalf, (c & 2) ? kHalf : -kHalf, 0);
      ConstraintRow q;
      q.bodyA = k - 1;  // the body below (-1: the world), normal from A to B
      q.bodyB = k;
      const Vec3 rB = corner - Vec3(0, 0, kHalf), rA = corner + Vec3(0, 0, kHalf);
      q.jLinB = up;
      q.jAngB = rB.cross(up);
      if (q.bodyA >= 0) {
        q.jLinA = -up;
        q.jAngA = -rA.cross(up);
      } else {
        q.jAngA = -corner.cross(up);  // the world's side: only its lever arm's direction matters to the tilt axes
      }
      q.e = 1e-9;
      q.lo = 0;
      q.hi = 1e300;
      s.rows.push_back(q);
    }
    s.couplings.push_back({k - 1, k, begin, 4, false});
  }
  return s;
}

Real contactLoad(const Stack& s, int k) {
  Real sum = 0;
  for (uint32_t i = s.couplings[size_t(k)].begin; i < s.couplings[size_t(k)].begin + 4; ++i) sum += s.rows[i].lambda;
  return sum;
}

/// The quadratic PGS minimises, up to a constant: 1/2 v^T M v + 1/2 lambda^T E lambda - rhs^T lambda with
/// v = v* + M^-1 J^T lambda (the bodies' velocities carry the impulses already applied).
Real objective(const Stack& s) {
  Real f = 0;
  for (const SolverBodyState& b : s.bodies) {
    f += 0.5 * b.v.squaredNorm() / b.invMass;
    f += 0.5 * b.w.dot(b.invInertia.inverse() * b.w);
  }
  for (const ConstraintRow& q : s.rows) f += 0.5 * q.e * q.lambda * q.lambda - q.rhs * q.lambda;
  return f;
}

}  // namespace

TEST_CASE("coarse correction: one correction after 2 sweeps gives a 20-box stack its loads") {
  constexpr int n = 20;
  Stack plain = buildStack(n, 0.01), coarse = buildStack(n, 0.01);
  PgsSolver::prepare(plain.rows, plain.bodies);
  PgsSolver::iterate(plain.rows, plain.bodies, 10);
  PgsSolver::prepare(coarse.rows, coarse.bodies);
  PgsSolver::iterate(coarse.rows, coarse.bodies, 2);
  CoarseCorrection cc;
  const CoarseCorrection::Result r = cc.apply(coarse.rows, coarse.bodies, coarse.couplings);
  // Exact: contact k stops the n - k bodies above it, (n - k) m g h (compliance 1e-9 changes it by 1e-9 g h).
  // The regularisation (1 + 1e-5 on each diagonal) leaves 1e-5 / (lambda_min / diagonal) of the slowest mode
  // (the whole stack's load): lambda_min / diagonal = 1 - cos(pi / (2 n + 1)) = 2.9e-3 for a chain held at one
  // end, so rho = 3.4e-3 of the bottom load, in that mode's shape (largest at the bottom).
  const Real rho = CoarseCorrection::kRegularisation / (1 - std::cos(M_PI / (2 * n + 1)));
  const Real bottom = n * kMass * kG * kH;
  MESSAGE("bottom contact load / exact: 10 plain sweeps " << contactLoad(plain, 0) / bottom << ", 2 sweeps + one "
          "correction " << contactLoad(coarse, 0) / bottom << " (" << r.unknowns << " unknowns, alpha " << r.alpha
          << ")");
  CHECK(r.unknowns == 3 * n);  // load and two tilts per square manifold, no friction rows
  CHECK(r.analysed);           // the first correction analyses the coarse operator's pattern
  CHECK(r.factorised);         // and factors it
  CHECK(r.alpha == doctest::Approx(1.0));
  CHECK(contactLoad(plain, 0) < 0.9 * bottom);  // what the correction is for: 10 sweeps leave > 10 % missing
  for (int k = 0; k < n; ++k)
    CHECK(std::abs(contactLoad(coarse, k) - (n - k) * kMass * kG * kH) < rho * bottom);
  // The rocking (0.01 rad/s about x, alternating) is stopped by the tilt unknowns to the same accuracy.
  for (const SolverBodyState& b : coarse.bodies) {
    CHECK(std::abs(b.v.z()) < rho * kG * kH * n);
    CHECK(b.w.norm() < rho * 0.01);
  }
  // A second correction after two more sweeps shrinks what the regularisation left, by at least 10x (rho alone
  // would give rho^2; the sweeps between move the error between modes: measured 8e-5 of the bottom load).
  PgsSolver::iterate(coarse.rows, coarse.bodies, 2);
  const CoarseCorrection::Result again = cc.apply(coarse.rows, coarse.bodies, coarse.couplings);
  CHECK(again.unknowns == r.unknowns);
  CHECK_FALSE(again.analysed);  // same manifolds, same unknowns: the kept symbolic analysis is reused
  // Same groups, Jacobians and masses: the same operator bit for bit, so the kept factor serves again.
  CHECK_FALSE(again.factorised);
  for (int k = 0; k < n; ++k)
    CHECK(std::abs(contactLoad(coarse, k) - (n - k) * kMass * kG * kH) < 0.1 * rho * bottom);
}

TEST_CASE("coarse correction: a separating contact is released to its bound, the objective does not rise") {
  // Two boxes; the top one moves up at 1 m/s but its contact's warm start still holds the resting load. The
  // exact answer: the top contact carries nothing (lambda 0, the box flies off), the bottom contact the lower
  // box's weight. The unconstrained coarse solution would pull the top contact into tension (about -1 N s).
  Stack s = buildStack(2);
  s.bodies[1].v.z() = 1.0;
  // Warm start: the top contact its resting load m g h, the bottom one too little (1.5 m g h of 2 m g h).
  for (int k = 0; k < 2; ++k)
    for (uint32_t i = s.couplings[size_t(k)].begin; i < s.couplings[size_t(k)].begin + 4; ++i)
      s.rows[i].lambda = (k == 0 ? 1.5 : 1.0) * kMass * kG * kH / 4;
  PgsSolver::prepare(s.rows, s.bodies);  // applies the warm start to the velocities
  const Real before = objective(s);
  CoarseCorrection cc;
  const CoarseCorrection::Result r = cc.apply(s.rows, s.bodies, s.couplings);
  const Real after = objective(s);
  MESSAGE("objective " << before << " -> " << after << ", refinements " << r.refinements << ", alpha " << r.alpha
          << ", top load " << contactLoad(s, 1) << " N s");
  for (const ConstraintRow& q : s.rows) CHECK(q.lambda >= q.lo);
  CHECK(after < before);
  CHECK(r.alpha > 0.99);
  // The top contact separates (its residual asks for less load) and its load group would go below zero: it is
  // released (load to zero) in the first refinement, and the bottom contact then carries the lower box's weight
  // alone. That is the exact solution: the objective reaches the top box's 1/2 m v^2 = 0.5 J s (a resting lower
  // box adds nothing).
  CHECK(r.refinements == 1);
  CHECK(contactLoad(s, 1) == 0.0);
  CHECK(contactLoad(s, 0) == doctest::Approx(kMass * kG * kH).epsilon(1e-6));
  CHECK(after == doctest::Approx(0.5).epsilon(1e-6));
  // Two more sweeps and a correction keep it there.
  PgsSolver::iterate(s.rows, s.bodies, 2);
  cc.apply(s.rows, s.bodies, s.couplings);
  CHECK(contactLoad(s, 1) == 0.0);
  CHECK(contactLoad(s, 0) == doctest::Approx(kMass * kG * kH).epsilon(1e-6));
  CHECK(s.bodies[1].v.z() > 0.9);
}
