// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Finiteness check stage: a body whose state turned non-finite in this step is restored to its pose at the
// start of the step and stopped, reported in the step report and logged (no exceptions inside the step).
#include <sstream>

#include "scree/core/logger.h"
#include "step_stages.h"

namespace scree::detail {

void checkFinite(SimulationState& s) {
  for (size_t i = 0; i < s.bodies.size(); ++i) {
    RigidBody& b = *s.bodies[i];
    if (b.getMotionControl() == RigidBody::STATIC) continue;
    if (BodyAccess::cm(b).allFinite() && BodyAccess::rotation(b).coeffs().allFinite() &&
        BodyAccess::velocity(b).allFinite() && BodyAccess::angularVelocity(b).allFinite())
      continue;
    std::ostringstream msg;
    msg << "RigidBody \"" << b.getName() << "\" (id " << b.getId() << ") has a non-finite state after the step at t = "
        << s.time << " s; restored its last finite pose and stopped it";
    BodyAccess::cm(b) = s.savedX[i];
    BodyAccess::rotation(b) = s.savedQ[i];
    BodyAccess::velocity(b).setZero();
    BodyAccess::angularVelocity(b).setZero();
    s.report.nonFiniteBodies.push_back(b.getId());
    s.report.messages.push_back(msg.str());
    Logger::error(msg.str());
  }
}

}  // namespace scree::detail
