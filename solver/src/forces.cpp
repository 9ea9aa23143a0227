// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Forces stage: the free velocities v + h M^-1 f of every dynamic body (external forces, gravity, velocity
// damping) and particle (gravity), the start of the velocity solve. Gyroscopic effects are handled by the
// rotation integrator (integrator.h), not as a torque here. The stage also keeps what later stages need of
// the start of the step: each body's velocities (contact rows) and pose (finiteness check).
#include "step_stages.h"

namespace scree::detail {

void applyForces(SimulationState& s) {
  const size_t nb = s.bodies.size();
  s.sb.resize(nb);
  s.vStart.resize(nb);
  s.wStart.resize(nb);
  s.savedX.resize(nb);
  s.savedQ.resize(nb);
  const Real h = s.h;
  size_t numDynamic = 0;
  for (size_t i = 0; i < nb; ++i) {
    RigidBody& b = *s.bodies[i];
    SolverBodyState& sb = s.sb[i];
    s.vStart[i] = b.getVelocity();
    s.wStart[i] = b.getAngularVelocity();
    s.savedX[i] = BodyAccess::cm(b);
    s.savedQ[i] = BodyAccess::rotation(b);
    if (b.getMotionControl() == RigidBody::DYNAMICS) {
      ++numDynamic;
      sb.invMass = b.getInvMass();
      sb.invInertia = b.getInvInertiaWorld();
      sb.v = (b.getVelocity() + h * (s.gravity + b.getForce() * sb.invMass)) / (1.0 + h * b.getLinearVelocityDamping());
      sb.w = (b.getAngularVelocity() + h * (sb.invInertia * b.getTorque())) / (1.0 + h * b.getAngularVelocityDamping());
    } else {
      sb.invMass = 0;
      sb.invInertia.setZero();
      sb.v = b.getMotionControl() == RigidBody::KINEMATICS ? b.getVelocity() : Vec3::Zero();
      sb.w = b.getMotionControl() == RigidBody::KINEMATICS ? b.getAngularVelocity() : Vec3::Zero();
    }
  }
  s.solverStats().numBodies = numDynamic;
  if (s.granularStep) s.particles.applyForces(s.granular, s.gravity, h);
}

}  // namespace scree::detail
