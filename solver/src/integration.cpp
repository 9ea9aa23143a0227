// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Integration stage: positions and rotations from the solved velocities (integrator.h), for dynamic bodies,
// kinematic bodies (their prescribed velocities) and particles. External forces are cleared for the next step.
#include "integrator.h"
#include "scree/core/logger.h"
#include "step_stages.h"

namespace scree::detail {

void integrateMotion(SimulationState& s) {
  const Real h = s.h;
  for (size_t i = 0; i < s.bodies.size(); ++i) {
    RigidBody& b = *s.bodies[i];
    switch (b.getMotionControl()) {
      case RigidBody::STATIC: break;
      case RigidBody::KINEMATICS:
        BodyAccess::cm(b) += h * b.getVelocity();
        BodyAccess::rotation(b) = (expRotation(b.getAngularVelocity(), h) * BodyAccess::rotation(b)).normalized();
        break;
      case RigidBody::DYNAMICS:
        BodyAccess::velocity(b) = s.sb[i].v;
        BodyAccess::angularVelocity(b) = s.sb[i].w;
        BodyAccess::cm(b) += h * s.sb[i].v;
        integrateRotation(b, h);
        break;
    }
    b.clearForces();
  }
  if (s.granularStep) {
    const size_t before = s.report.messages.size();
    s.particles.integrateBondedLumps(s.granular, s.particleCollider.getParticleParticleContacts(), h);
    s.particles.integrate(s.granular, h, s.report.nonFiniteParticles, s.report.messages, s.time);
    for (size_t k = before; k < s.report.messages.size(); ++k) Logger::error(s.report.messages[k]);
  }
}

}  // namespace scree::detail
