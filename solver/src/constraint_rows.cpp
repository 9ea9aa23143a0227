// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Constraint rows stage: the rows of every enabled joint and model constraint with a dynamic body, after the
// contact rows; a constraint whose rows report a separation (drift beyond Solver::getConstraintErrorThreshold)
// is listed in the step report and logged once.
#include <cmath>
#include <sstream>

#include "scree/core/logger.h"
#include "step_stages.h"

namespace scree::detail {

namespace {
void reportSeparated(SimulationState& s, const Constraint& c, Real drift) {
  s.report.separatedConstraints.push_back(&c);
  if (!s.reportedSeparated.insert(&c).second) return;
  static const char* kTypes[] = {"DIRECT", "ITERATIVE", "DIRECT_AND_ITERATIVE", "SPLIT"};
  const int t = int(c.getSolveType());
  std::ostringstream msg;
  msg << c.getTypeName() << " \"" << c.getName() << "\" came apart at t = " << s.time << " s: position error "
      << drift << " (m or rad) beyond its elastic stretch, above Solver::getConstraintErrorThreshold() = "
      << s.solver.getConstraintErrorThreshold() << "; solve type " << (t >= 0 && t < 4 ? kTypes[t] : "?")
      << (c.getSolveType() == FrictionModel::ITERATIVE
              ? " (PGS cannot hold heavy loads on light links: use DIRECT or DIRECT_AND_ITERATIVE)"
              : " (try a smaller time step)")
      << ". Reported once per constraint; StepReport::separatedConstraints lists it every step.";
  s.report.messages.push_back(msg.str());
  Logger::error(msg.str());
}
}  // namespace

void buildConstraintRows(SimulationState& s) {
  const Real errorThreshold = s.solver.getConstraintErrorThreshold();
  bool nonIterative = s.nonIterativeRows;
  s.ranges.clear();
  s.rowDofs.assign(s.rows.size(), -1);
  for (auto& c : s.constraints) {
    if (!c->getEnable()) continue;
    ConstraintContext ctx;
    ctx.h = s.h;
    ctx.indexA = s.solverIndex(c->getBodyAt(0));
    ctx.indexB = s.solverIndex(c->getBodyAt(1));
    const bool dynA = ctx.indexA >= 0 && s.sb[ctx.indexA].invMass > 0;
    const bool dynB = ctx.indexB >= 0 && s.sb[ctx.indexB].invMass > 0;
    if (!dynA && !dynB) continue;
    const uint32_t begin = uint32_t(s.rows.size());
    c->addRows(ctx, s.rows, s.rowDofs);
    if (c->getSolveType() != FrictionModel::ITERATIVE) nonIterative = true;
    // A joint that came apart: its rows' drift (position error beyond the elastic stretch of the last force)
    // is known here for free.
    Real drift = 0;
    for (size_t k = begin; k < s.rows.size(); ++k)
      if (s.rows[k].holonomic) drift = std::max(drift, std::abs(s.rows[k].drift));
    if (!(drift <= errorThreshold)) reportSeparated(s, *c, drift);
    s.ranges.push_back({c.get(), begin, uint32_t(s.rows.size() - begin)});
    // Joints couple bodies for support levels too (a chain hanging from the world is supported link by link).
    s.couplings.push_back({ctx.indexA, ctx.indexB, begin, uint32_t(s.rows.size() - begin), true});
  }
  s.nonIterativeRows = nonIterative;
  if (nonIterative && !s.warnedSolveType && !DirectSolver::available()) {
    s.warnedSolveType = true;
    Logger::warningOnce("scree.solveType.direct",
                        "DIRECT / SPLIT / DIRECT_AND_ITERATIVE solve types need SuiteSparse (built without "
                        "SCREE_WITH_SUITESPARSE): those rows are solved by the iterative PGS solver");
  }
  s.solverStats().numRows = s.rows.size();
}

}  // namespace scree::detail
