// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The state that the bit-identity tests compare (partitioned sweeps on 1 and 2 threads, Simulations stepped at
// once on several threads): every rigid body's position, velocity, angular velocity and rotation, in the
// Simulation's order.
#pragma once

#include <cstring>
#include <vector>

#include <scree/scree.h>

namespace scree::test {

inline std::vector<Real> bodyState(const Simulation& sim) {
  std::vector<Real> state;
  for (const RigidBodyRef& b : sim.getRigidBodies()) {
    for (const Vec3& v : {b->getPosition(), b->getVelocity(), b->getAngularVelocity()})
      state.insert(state.end(), v.data(), v.data() + 3);
    const Quat q = b->getRotation();
    state.insert(state.end(), {q.w(), q.x(), q.y(), q.z()});
  }
  return state;
}

/// The two states hold the same bits (memcmp, so -0.0 differs from 0.0 and a NaN may equal itself).
inline bool sameBits(const std::vector<Real>& a, const std::vector<Real>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Real)) == 0;
}

}  // namespace scree::test
