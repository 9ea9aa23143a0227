// Step listeners (PRE_COLLIDE, PRE_STEP, POST_STEP stages): each listener whose mask has the bit, in the order
// they were added.
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

}  // namespace scree::detail
