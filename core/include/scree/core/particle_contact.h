// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Contacts involving particles (GranularBodySystem), as the collider produces them and the solver reports them.
#pragma once

#include <cstdint>

#include "scree/core/math.h"

namespace scree {

class Geometry;

/// One contact point between particle a and particle b (b >= 0) or between particle a and a geometry (b < 0).
/// a and b are dense indices into the GranularBodySystem arrays of the step that produced the contact (they
/// change when particles are destroyed or reordered: use GranularBodySystem::idOfDense to keep one).
/// The normal points from b (or the geometry) towards a; depth > 0 is overlap, < 0 a speculative gap.
struct ParticleContact {
  uint32_t a = 0;
  int32_t b = -1;
  const Geometry* geometry = nullptr;
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();
  Real depth = 0;
  uint32_t featureId = 0;   ///< narrowphase feature of the geometry (0 for particle pairs)
  bool sensor = false;      ///< the geometry is a sensor: reported, never solved
  // --- per-point overrides a ContactEventListener may set (ContactEventListener::particleContacts), with the
  // meaning of ContactPoint's; a negative value means "use the contact material" ------------------------------
  bool enabled = true;               ///< false: the solver ignores this point this step
  Real youngsModulus = -1;           ///< N/m per point (> 0 overrides)
  Real frictionCoefficient = -1;     ///< (>= 0 overrides; +inf: no slip)
  Real damping = -1;                 ///< SPOOK damping time, s (>= 0 overrides)
  Real restitution = -1;             ///< (>= 0 overrides)
  /// Target tangential velocity of particle a relative to particle b (or the geometry) at the point, world m/s
  /// (a conveyor belt). Only its tangential part is used.
  Vec3 surfaceVelocity = Vec3::Zero();
  // Results of the last step, on particle a.
  Real normalForce = 0;     ///< N
  Vec3 frictionForce = Vec3::Zero();  ///< N, world
};

}  // namespace scree
