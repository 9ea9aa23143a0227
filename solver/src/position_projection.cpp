// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Position projection stage (Solver::setUsePositionProjection): post-stabilisation of rigid direct-set joint
// rows after the positions are integrated.
#include <algorithm>
#include <cmath>

#include "integrator.h"
#include "step_stages.h"

namespace scree::detail {

void projectPositions(SimulationState& s) {
  // Post-stabilisation (Cline & Pai 2003, "Post-stabilization for rigid body simulation with contact and
  // constraints"): SPOOK's rows are linearised at the start of the step, so a joint whose links turn fast
  // drifts by about (omega h)^2 |r| / 2 per step, and the damped position feedback removes that only over the
  // next steps. At a large step with light links whipping under a heavy load (chain20 at dt 1/60) the drift
  // reaches centimetres. Here the rigid holonomic rows of direct-set joints are rebuilt at the integrated
  // positions, and the drift (the position error beyond the elastic stretch of the solved force, see
  // ConstraintRow::drift) that exceeds the tolerance (Solver::setPositionProjectionTolerance) is removed by the
  // smallest displacement in the mass metric: dx = M^-1 G^T mu with G M^-1 G^T mu = -excess (rows within the
  // tolerance: 0), one direct factorisation per Newton iteration, the pattern (and so CHOLMOD's symbolic
  // analysis) kept across steps. Velocities are not changed: the step's momenta and the forces the joints
  // report stay those of the solve. Drift within the tolerance stays with SPOOK's feedback, which keeps the
  // energy (see Solver::setUsePositionProjection). Compliant rows (regularisation >= 1 % of the mass term,
  // springs the step resolves: tire modes, soft joints) and bounded rows are left to SPOOK. Joints within the
  // tolerance (a resting chain, a pendulum) cost one rebuild of their rows and no factorisation.
  SolverStats& st = s.solverStats();
  st.numProjectionIterations = 0;
  st.projectionDrift = st.projectionResidual = 0;
  if (!s.solver.getUsePositionProjection() || s.directSet.empty() || s.ranges.empty()) return;
  bool any = false;
  for (const auto& r : s.ranges) any |= r.c->getSolveType() != FrictionModel::ITERATIVE;
  if (!any) return;
  const Real tolerance = s.solver.getPositionProjectionTolerance();
  constexpr Real kRigid = 1e-2;      // e / (J M^-1 J^T) below this: a rigid row
  // The metric: the bodies' masses, and inertias plus the joints' geometric stiffness h^2 sum |f| |r| (see
  // addGeometricStiffness, this step's impulses). With the bare inertia the smallest-norm correction of a taut
  // chain bends its light links (a shortening that is second order in their rotation), so Newton stalls and the
  // rotations it applies feed energy into the whip; the tension term makes those rotations as costly as the
  // force they turn against, and Newton converges in a few iterations (docs/solver-internals.md).
  const size_t nb = s.bodies.size();
  // The metric is built on first use (issue 18, chain20's cost): most steps of a chain at rest or swinging
  // within the tolerance need no factorisation, and a row whose linear mass term alone shows it rigid (every
  // ball joint's row) needs no inertia to be classified (rigidByMass below). Built or not, the rows kept, the
  // drift reported and every correction are the same.
  auto invMassOf = [](const RigidBody& b) {
    return b.getMotionControl() == RigidBody::DYNAMICS ? b.getInvMass() : Real(0);
  };
  bool metricReady = false;
  auto buildMetric = [&] {
    if (metricReady) return;
    metricReady = true;
    s.projBodies.resize(nb);
    const bool tension = computeGeometricStiffness(s);
    for (size_t i = 0; i < nb; ++i) {
      const RigidBody& b = *s.bodies[i];
      SolverBodyState& pb = s.projBodies[i];
      pb.v.setZero();
      pb.w.setZero();
      const bool dyn = b.getMotionControl() == RigidBody::DYNAMICS;
      pb.invMass = invMassOf(b);
      pb.invInertia = dyn ? b.getInvInertiaWorld() : Mat3::Zero();
      if (dyn && tension && s.geomK[i] > 0)
        pb.invInertia = (pb.invInertia.inverse() + (s.h * s.h * s.geomK[i]) * Mat3::Identity()).inverse();
    }
  };
  auto massTerm = [&](const ConstraintRow& r) {
    buildMetric();
    Real k = 0;
    if (r.bodyA >= 0) {
      const SolverBodyState& pb = s.projBodies[r.bodyA];
      k += pb.invMass * r.jLinA.squaredNorm() + r.jAngA.dot(pb.invInertia * r.jAngA);
    }
    if (r.bodyB >= 0) {
      const SolverBodyState& pb = s.projBodies[r.bodyB];
      k += pb.invMass * r.jLinB.squaredNorm() + r.jAngB.dot(pb.invInertia * r.jAngB);
    }
    return k;
  };
  // The test `kd > 0 && e < kRigid kd` without the metric, when the linear terms settle it: they are massTerm's
  // own products, and the angular terms it adds are >= 0 (the inverse inertias are positive semi-definite; a
  // rounding below zero would have to meet a row exactly at the threshold), so a row rigid by its linear terms
  // is rigid by massTerm.
  auto rigidByMass = [&](const ConstraintRow& r) {
    Real lin = 0;
    if (r.bodyA >= 0) lin += invMassOf(*s.bodies[size_t(r.bodyA)]) * r.jLinA.squaredNorm();
    if (r.bodyB >= 0) lin += invMassOf(*s.bodies[size_t(r.bodyB)]) * r.jLinB.squaredNorm();
    return lin > 0 && r.e < kRigid * lin;
  };
  const int maxIterations = s.solver.getNumProjectionIterations();
  for (int it = 0;; ++it) {
    s.projRows.clear();
    s.projDofs.clear();
    for (const auto& range : s.ranges) {
      Constraint* c = range.c;
      if (c->getSolveType() == FrictionModel::ITERATIVE || !c->getEnable()) continue;
      ConstraintContext ctx;
      ctx.h = s.h;
      ctx.indexA = s.solverIndex(c->getBodyAt(0));
      ctx.indexB = s.solverIndex(c->getBodyAt(1));
      const size_t begin = s.projRows.size();
      c->addRows(ctx, s.projRows, s.projDofs);
      size_t keep = begin;
      for (size_t k = begin; k < s.projRows.size(); ++k) {
        ConstraintRow& r = s.projRows[k];  // edited in place, moved down only past dropped rows
        if (!r.holonomic || r.lo > -1e299 || r.hi < 1e299 || !std::isfinite(r.drift)) continue;
        if (!rigidByMass(r)) {
          const Real kd = massTerm(r);
          if (!(kd > 0) || !(r.e < kRigid * kd)) continue;
        }
        // Pull back only what exceeds the tolerance; rows within it are held where they are.
        r.rhs = -(r.drift - std::clamp(r.drift, -tolerance, tolerance));
        r.e = 0;
        r.lambda = 0;
        r.normalRow = -1;
        r.pairedRow = -1;
        r.solveType = FrictionModel::DIRECT;
        if (keep != k) s.projRows[keep] = r;
        ++keep;
      }
      s.projRows.resize(keep);
    }
    Real worst = 0, excess = 0;
    for (const ConstraintRow& r : s.projRows) {
      worst = std::max(worst, std::abs(r.drift));
      excess = std::max(excess, std::abs(r.rhs));
    }
    if (it == 0) st.projectionDrift = worst;
    else st.projectionResidual = excess;
    if (excess <= 1e-3 * tolerance || it == maxIterations) break;
    buildMetric();
    PgsSolver::prepare(s.projRows, s.projBodies);
    s.projSet.resize(s.projRows.size());
    for (uint32_t k = 0; k < s.projSet.size(); ++k) s.projSet[k] = k;
    DirectSolver::Settings ds;
    ds.form = s.solver.getDirectForm();
    const DirectSolver::Result res = s.projector.solve(s.projRows, s.projSet, s.projBodies, ds);
    ++st.numProjectionIterations;
    if (!res.converged) break;
    // The solve's "velocities" are the displacements (linear, and rotation vector) of the bodies.
    for (size_t i = 0; i < nb; ++i) {
      SolverBodyState& pb = s.projBodies[i];
      if (!(pb.invMass > 0)) continue;
      RigidBody& b = *s.bodies[i];
      BodyAccess::cm(b) += pb.v;
      BodyAccess::rotation(b) = (expRotation(pb.w, 1.0) * BodyAccess::rotation(b)).normalized();
      pb.v.setZero();
      pb.w.setZero();
    }
  }
}

}  // namespace scree::detail
