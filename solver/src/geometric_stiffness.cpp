// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Geometric stiffness of direct-set joint rows (Solver::setUseGeometricStiffness), read by the solve stage
// and by the position projection.
#include <cmath>

#include "step_stages.h"

namespace scree::detail {

void addGeometricStiffness(SimulationState& s) {
  // A row's direction turns with its body: a joint carrying force f at lever r has a geometric stiffness |f| |r|
  // about the body's rotation axes that the step's linearised rows miss. With links much lighter than the load
  // it carries, that stiffness makes the linearised step unstable once h^2 |f| |r| exceeds the link's inertia
  // (the chain whips; measurements in docs/solver-internals.md). Following Andrews, Teichmann & Kry
  // (2017, "Geometric stiffness for real-time constrained multibody dynamics"), its diagonal approximation,
  // h^2 sum |lambda/h| |r| per body (last step's impulses), is added to the inertia seen by the solve. It damps
  // the unresolved fast rotation only; it vanishes as h^2 and leaves static loads and masses unchanged. Applied to
  // bodies of direct-set joint rows (Solver::setUseGeometricStiffness).
  if (!s.solver.getUseGeometricStiffness() || !computeGeometricStiffness(s)) return;
  for (size_t b = 0; b < s.sb.size(); ++b) {
    if (!(s.geomK[b] > 0) || !(s.sb[b].invMass > 0)) continue;
    const Mat3 I = s.sb[b].invInertia.inverse() + (s.h * s.h * s.geomK[b]) * Mat3::Identity();
    s.sb[b].invInertia = I.inverse();
  }
}

bool computeGeometricStiffness(SimulationState& s) {
  // s.geomK[b] = sum over direct-set rows on b of |lambda / h| |r| (N m / rad), from the rows' current impulses.
  s.geomK.assign(s.sb.size(), 0.0);
  bool any = false;
  for (uint32_t i : s.directSet) {
    const ConstraintRow& r = s.rows[i];
    const Real f = std::abs(r.lambda) / s.h;
    if (r.bodyA >= 0 && r.leverA > 0) s.geomK[r.bodyA] += f * r.leverA, any = true;
    if (r.bodyB >= 0 && r.leverB > 0) s.geomK[r.bodyB] += f * r.leverB, any = true;
  }
  return any;
}

}  // namespace scree::detail
