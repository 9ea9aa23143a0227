// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Private access to RigidBody internals for the integrator and the simulation (solver-private).
#pragma once

#include "scree/core/rigid_body.h"

namespace scree::detail {

struct BodyAccess {
  static Vec3& cm(RigidBody& b) { return b.x_; }
  static Quat& rotation(RigidBody& b) { return b.q_; }
  static Vec3& velocity(RigidBody& b) { return b.v_; }
  static Vec3& angularVelocity(RigidBody& b) { return b.w_; }
  static const Vec3& principalMoments(const RigidBody& b) { return b.principal_; }
  static const Quat& principalFrame(const RigidBody& b) { return b.principalFrame_; }
  static const Mat3& invInertiaLocal(const RigidBody& b) { return b.invInertia_; }
  static int& simIndex(RigidBody& b) { return b.simIndex_; }
};

}  // namespace scree::detail
