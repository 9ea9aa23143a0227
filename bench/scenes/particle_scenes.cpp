// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scenes/particle_scenes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <unordered_map>

namespace scree::scenes {

ParticleScene buildParticleLattice(const SphereLatticeParams& p) {
  ParticleScene s;
  std::string name = "particles" + std::to_string(p.count);
  if (p.jitter) name += "_jitter";
  initScene(s, name, p.mu, p.dt, p.numSteps);
  s.params = p;
  s.material->setDensity(p.density);
  addGround(s);
  s.wallInner = 0.5 * p.perRow * p.spacing + (p.spacing - 2 * p.radius);
  const Real wt = 0.5 * p.wallThickness, wh = 0.5 * p.wallHeight;
  const Real wl = s.wallInner + p.wallThickness;
  const Real wc = s.wallInner + wt;
  s.walls.push_back(addStaticBox(s, Vec3(wt, wl, wh), Vec3(wc, 0, wh)));
  s.walls.push_back(addStaticBox(s, Vec3(wt, wl, wh), Vec3(-wc, 0, wh)));
  s.walls.push_back(addStaticBox(s, Vec3(wl, wt, wh), Vec3(0, wc, wh)));
  s.walls.push_back(addStaticBox(s, Vec3(wl, wt, wh), Vec3(0, -wc, wh)));

  GranularBodySystem& ps = s.particles();
  ps.setMaterial(s.material);
  const Real half = 0.5 * (p.perRow - 1);
  const size_t perLayer = size_t(p.perRow) * size_t(p.perRow);
  uint64_t rng = p.seed;
  for (size_t n = 0; n < p.count; ++n) {
    const size_t k = n / perLayer, inLayer = n % perLayer;
    const size_t j = inLayer / size_t(p.perRow), i = inLayer % size_t(p.perRow);
    Vec3 pos((Real(i) - half) * p.spacing, (Real(j) - half) * p.spacing,
             p.radius + (p.spacing - 2 * p.radius) + p.spacing * Real(k));
    if (p.jitter) {
      const Real dx = splitmixSymmetric(rng) * p.jitterAmplitude;
      const Real dy = splitmixSymmetric(rng) * p.jitterAmplitude;
      pos.x() += dx;
      pos.y() += dy;
    }
    ps.createParticle(pos, p.radius);
  }
  return s;
}

ParticleScene buildParticles10kJitter() {
  SphereLatticeParams p;
  p.jitter = true;
  return buildParticleLattice(p);
}

ParticleMetrics measureParticles(const ParticleScene& s) {
  ParticleMetrics m;
  const GranularBodySystem& ps = s.particles();
  const size_t n = ps.size();
  std::vector<uint32_t> live;
  Real sumZ = 0, maxR = 0;
  m.maxHeight = -std::numeric_limits<Real>::infinity();
  const bool walls = !s.walls.empty();
  for (size_t i = 0; i < n; ++i) {
    if (!ps.isAliveDense(i)) continue;
    const Vec3& x = ps.positions()[i];
    const Real r = ps.radii()[i], mass = ps.masses()[i];
    const bool fin = x.allFinite() && ps.velocities()[i].allFinite() && ps.angularVelocities()[i].allFinite();
    m.finite = m.finite && fin;
    ++m.count;
    m.totalMass += mass;
    m.kineticEnergy += 0.5 * mass * ps.velocities()[i].squaredNorm() +
                       0.5 * 0.4 * mass * r * r * ps.angularVelocities()[i].squaredNorm();
    const bool inside = !walls || (std::abs(x.x()) <= s.wallInner && std::abs(x.y()) <= s.wallInner);
    if (!fin || !inside || x.z() < 0) ++m.escaped;
    if (!fin) continue;
    live.push_back(uint32_t(i));
    maxR = std::max(maxR, r);
    sumZ += x.z();
    m.maxHeight = std::max(m.maxHeight, x.z());
    m.maxPenFloor = std::max(m.maxPenFloor, r - x.z());
    if (walls && inside)
      m.maxPenWall = std::max(m.maxPenWall, std::max({x.x() + r - s.wallInner, -x.x() + r - s.wallInner,
                                                      x.y() + r - s.wallInner, -x.y() + r - s.wallInner}));
  }
  m.meanHeight = m.count ? sumZ / Real(m.count) : 0;
  if (m.count == 0) m.maxHeight = 0;
  // Pairs through an independent grid (cell = largest diameter), each pair once from the lower index.
  const Real cell = std::max<Real>(2 * maxR, 1e-9);
  auto key = [](int64_t a, int64_t b, int64_t c) {
    return uint64_t((a & 0x1FFFFF) | ((b & 0x1FFFFF) << 21) | ((c & 0x1FFFFF) << 42));
  };
  std::unordered_map<uint64_t, std::vector<uint32_t>> grid;
  std::unordered_map<uint32_t, std::array<int64_t, 3>> cells;
  for (uint32_t i : live) {
    const Vec3& x = ps.positions()[i];
    const std::array<int64_t, 3> c{int64_t(std::floor(x.x() / cell)), int64_t(std::floor(x.y() / cell)),
                                   int64_t(std::floor(x.z() / cell))};
    cells[i] = c;
    grid[key(c[0], c[1], c[2])].push_back(i);
  }
  for (uint32_t i : live) {
    const auto& c = cells[i];
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          auto it = grid.find(key(c[0] + dx, c[1] + dy, c[2] + dz));
          if (it == grid.end()) continue;
          for (uint32_t j : it->second) {
            if (j <= i) continue;
            const Real d = (ps.positions()[i] - ps.positions()[j]).norm();
            m.maxPenPair = std::max(m.maxPenPair, ps.radii()[i] + ps.radii()[j] - d);
          }
        }
  }
  m.maxPenetration = std::max({m.maxPenPair, m.maxPenFloor, m.maxPenWall, Real(0)});
  return m;
}

uint64_t hashParticleState(const GranularBodySystem& ps) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&](const Vec3& v) {
    for (int k = 0; k < 3; ++k) {
      uint64_t bits;
      const double d = v[k];
      std::memcpy(&bits, &d, sizeof bits);
      for (int b = 0; b < 8; ++b) {
        h ^= (bits >> (8 * b)) & 0xffu;
        h *= 1099511628211ull;
      }
    }
  };
  for (size_t i = 0; i < ps.size(); ++i) {
    if (!ps.isAliveDense(i)) continue;
    mix(ps.positions()[i]);
    mix(ps.velocities()[i]);
    mix(ps.angularVelocities()[i]);
  }
  return h;
}

}  // namespace scree::scenes
