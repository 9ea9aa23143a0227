// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Step listeners (PRE_COLLIDE, PRE_STEP, POST_STEP stages): each listener whose mask has the bit, in the order
// they were added; and the end of the particle deferral after the last of them.
#include "step_stages.h"

namespace scree::detail {

void runStepListeners(SimulationState& s, int mask) {
  for (auto& l : s.stepListeners) {
    if (!(l->getMask() & mask)) continue;
    if (mask == StepEventListener::PRE_COLLIDE) l->preCollide(s.time);
    else if (mask == StepEventListener::PRE_STEP) l->pre(s.time);
    else l->post(s.time);
  }
}

void endParticleDeferral(SimulationState& s) {
  // Particle destroys are deferred from collision until after the POST_STEP listeners, so the dense indices in
  // this step's particle contact lists stay valid for every listener (post included); now they are applied.
  if (s.granularStep) s.granular.endDeferral();
}

}  // namespace scree::detail
