// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Particle scenes (GranularBodySystem): the spheres10k lattice as particles instead of rigid bodies, a pour,
// a heap on a plate, and their metrics. Shared by bench/bench_granular.cpp, the granular tests and the demo.
#pragma once

#include <vector>

#include "scenes/scenes.h"

namespace scree::scenes {

struct ParticleScene : Scene {
  SphereLatticeParams params;
  std::vector<RigidBodyRef> walls;  ///< +x, -x, +y, -y (may be empty)
  Real wallInner = 1.0;             ///< m, inner faces at x = +-wallInner and y = +-wallInner
  GranularBodySystem& particles() { return sim->getGranularBodySystem(); }
  const GranularBodySystem& particles() const { return sim->getGranularBodySystem(); }
};

/// docs/scenes.md spheres10k(_jitter) lattice with particles: same ground, walls, material (density, explicit
/// contact material with mu and restitution 0), dt and positions as buildSphereLattice. perRow and count
/// may be scaled (a larger box: perRow * spacing / 2 + 0.01 is the inner half width).
ParticleScene buildParticleLattice(const SphereLatticeParams& p);
/// spheres10k_jitter as particles.
ParticleScene buildParticles10kJitter();

struct ParticleMetrics {
  Real kineticEnergy = 0;     ///< J, translation + rotation (I = 0.4 m r^2)
  Real maxPenetration = 0;    ///< m, over particle-particle (grid), particle-floor (z = 0) and particle-wall
  Real maxPenPair = 0, maxPenFloor = 0, maxPenWall = 0;
  Real meanHeight = 0, maxHeight = 0;  ///< m, centre z
  size_t escaped = 0;         ///< outside the container (|x| or |y| > wallInner, or z < 0) or non-finite
  size_t count = 0;           ///< live particles
  Real totalMass = 0;         ///< kg
  bool finite = true;
};
/// Metrics from the current state. Walls are counted only when the scene has them.
ParticleMetrics measureParticles(const ParticleScene& s);

/// FNV-1a hash of the bit patterns of every live particle's position, velocity and angular velocity, in
/// dense order (identical states give identical hashes).
uint64_t hashParticleState(const GranularBodySystem& ps);

}  // namespace scree::scenes
