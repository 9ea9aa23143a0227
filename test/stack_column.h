// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// What the box and the cylinder stack sweeps (test_extremes_stacks.cpp, test_extremes_stacks_cylinders.cpp) share:
// the placements, the per-step drift read-out, and the closed forms of a column of equal blocks on compliant
// contacts (docs/solver-internals.md, "Stack sweep: compliance sink and buckling").
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <scree/scree.h>

namespace scree::stack_column {

enum class Placement { ALIGNED, OFFSET, GAP };

inline std::string name(Placement p) {
  return p == Placement::ALIGNED ? "aligned" : p == Placement::OFFSET ? "mm offsets" : "1 mm gaps";
}

/// Centre of block i of edge (or height) `size` on the ground z = 0: touching, shifted by a fixed +-1 mm /
/// +-0.5 mm pattern per block, or dropped through 1 mm gaps.
inline Vec3 blockPosition(Real size, int i, Placement placement) {
  const Real gap = placement == Placement::GAP ? 1e-3 : 0.0;
  Vec3 p(0, 0, size / 2 + (size + gap) * i + gap);
  if (placement == Placement::OFFSET) p += Vec3(1e-3 * ((i % 3) - 1), 5e-4 * ((i % 2) ? 1 : -1), 0);
  return p;
}

struct TowerResult {
  Real maxHorizontalDrift = 0;  ///< m, largest horizontal distance of any block from its start, over the run
  Real maxHorizontalSpeed = 0;  ///< m/s, largest horizontal speed of any block, over the run
  Real topDrop = 0;             ///< m, how far the top block ended below its start
  bool finite = true;
};

/// Folds one step's state of the blocks into r (call after every step).
inline void observe(TowerResult& r, const std::vector<RigidBodyRef>& blocks, const std::vector<Vec3>& start) {
  for (size_t i = 0; i < blocks.size(); ++i) {
    const Vec3 p = blocks[i]->getPosition(), v = blocks[i]->getVelocity();
    r.finite &= p.allFinite() && v.allFinite();
    r.maxHorizontalDrift = std::max(r.maxHorizontalDrift, (p - start[i]).head<2>().norm());
    r.maxHorizontalSpeed = std::max(r.maxHorizontalSpeed, v.head<2>().norm());
  }
}

/// Contact stiffness per point between two bodies of the same material of Young's modulus E (series: E/2).
inline Real pairStiffness(Real youngsModulus) {
  return youngsModulus * youngsModulus / (youngsModulus + youngsModulus);
}

/// Static sink of the top block of a column of `count` blocks of mass m, each joint on `points` springs of
/// stiffness k: joint j (0 = ground) carries the n - j blocks above it, so the top sinks m g / (points k) n (n+1)/2.
inline Real complianceSink(Real m, int count, Real g, Real k, int points) {
  return m * g / (points * k) * count * (count + 1) / 2.0;
}

/// Whether a column of `count` blocks (mass m, height s, centre s/2 above its joint) stands on joints of
/// rotational stiffness kTheta. Tilts theta_j (j = 0 at the bottom); joint j stores kTheta (theta_j -
/// theta_{j-1})^2 / 2 (theta_{-1} = 0, the ground); gravity lowers block i's centre by s theta_j^2 / 2 for every
/// block j below it and by s theta_i^2 / 4 for its own tilt, so the potential is
///   V = theta^T (kTheta T - G) theta / 2,   T = tridiag(-1, 2, -1) with T_{n-1,n-1} = 1,
///   G = diag(m g s (n - j - 1/2)).
/// The column stands iff kTheta T - G is positive definite: no negative pivot in its LDL^T (Sylvester). (The
/// continuous limit is Greenhill's heavy column, q L^3 / EI = 7.84 with q = m g / s, L = n s, EI = kTheta s.)
inline bool columnStands(Real m, Real s, int count, Real g, Real kTheta) {
  Real pivot = 0;
  for (int j = 0; j < count; ++j) {
    const Real d = (j < count - 1 ? 2 * kTheta : kTheta) - m * g * s * (count - j - 0.5);
    pivot = j == 0 ? d : d - kTheta * kTheta / pivot;
    if (pivot <= 0) return false;
  }
  return true;
}

/// The smallest point stiffness k at which the column stands, for joints of kTheta = kThetaPerK * k (bisection
/// on the pivot test; columnStands is false at 1e-6 N/m and true at 1e16 N/m for every sweep tower).
inline Real bucklingStiffness(Real m, Real s, int count, Real g, Real kThetaPerK) {
  Real lo = 1e-6, hi = 1e16;
  for (int i = 0; i < 200; ++i) {
    const Real mid = std::sqrt(lo * hi);
    (columnStands(m, s, count, g, kThetaPerK * mid) ? hi : lo) = mid;
  }
  return hi;
}

}  // namespace scree::stack_column
