// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The particle pair search's reference for tests: every pair of live particles tested with the rule of
// collide/include/scree/collide/particle_collider.h (a pair is a contact when its gap is below
// min(h |v_a - v_b| + margin, reach), reach = min(2 h max|v| + margin, one largest diameter)). It evaluates the
// same floating-point expressions as the collider's exact test, so a test may compare the two lists exactly, pair
// for pair and in (a, b) order.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <scree/scree.h>
#include "scree/collide/particle_collider.h"

namespace scree::test {

using ParticlePairs = std::vector<std::pair<uint32_t, int32_t>>;

/// The collider's particle-particle contacts of the last collide, as (a, b) pairs in its order.
inline ParticlePairs pairsOf(const detail::ParticleCollider& c) {
  ParticlePairs out;
  for (const ParticleContact& pc : c.getParticleParticleContacts()) out.emplace_back(pc.a, pc.b);
  return out;
}

/// Every pair of live particles in contact by the collider's rule, by brute force over all pairs.
inline ParticlePairs bruteForce(const GranularBodySystem& ps, Real h, Real margin) {
  const auto& x = ps.positions();
  const auto& v = ps.velocities();
  const auto& r = ps.radii();
  Real maxR = 0, maxV = 0;
  for (size_t i = 0; i < ps.size(); ++i) {
    maxR = std::max(maxR, r[i]);
    maxV = std::max(maxV, v[i].squaredNorm());
  }
  const Real reach = std::min(2 * std::sqrt(maxV) * h + margin, 2 * maxR);
  ParticlePairs out;
  for (size_t a = 0; a < ps.size(); ++a) {
    if (!ps.isAliveDense(a)) continue;
    for (size_t b = a + 1; b < ps.size(); ++b) {
      if (!ps.isAliveDense(b)) continue;
      const Real lim = r[a] + r[b] + std::min(h * (v[a] - v[b]).norm() + margin, reach);
      if ((x[a] - x[b]).squaredNorm() < lim * lim) out.emplace_back(uint32_t(a), int32_t(b));
    }
  }
  return out;
}

}  // namespace scree::test
