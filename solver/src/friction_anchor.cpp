// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Friction anchors of contact manifolds (friction_anchor.h states the law and why).
#include "friction_anchor.h"

#include <cmath>

#include "contact_law.h"
#include "simulation_state.h"

namespace scree::detail {

namespace {

struct Frame {
  Vec3 x = Vec3::Zero();
  Quat q = Quat::Identity();
};

Frame frameOf(SimulationState& s, int i) {
  if (i < 0) return {};
  RigidBody& b = *s.bodies[size_t(i)];
  return {BodyAccess::cm(b), BodyAccess::rotation(b)};
}

Vec3 tangential(const Vec3& d, const Vec3& n) { return d - n.dot(d) * n; }

/// The anchors' tangential separation p_A - p_B and twist angle (A's anchor direction from B's, about n).
void separation(const FrictionAnchorCache::Anchor& an, const Frame& A, const Frame& B, const Vec3& n, Vec3& g,
                Real& phi) {
  g = (A.x + A.q * an.localA) - (B.x + B.q * an.localB);
  const Vec3 dA = tangential(A.q * an.dirA, n), dB = tangential(B.q * an.dirB, n);
  phi = std::atan2(n.dot(dB.cross(dA)), dB.dot(dA));
  if (!std::isfinite(phi)) phi = 0;
}

/// Sum of the manifold's normal impulses (the friction rows' bound, pgs.cpp boundingNormal).
Real normalSum(const std::vector<ConstraintRow>& rows, const ConstraintRow& f) {
  if (f.normalRow < 0) return 0;
  Real sum = 0;
  for (int32_t k = 0; k < f.normalCount; ++k) sum += std::max<Real>(rows[size_t(f.normalRow + k)].lambda, 0);
  return sum;
}

}  // namespace

void anchorManifoldFriction(SimulationState& s, uint64_t pair, int ia, int ib, const Vec3& centre,
                            const Vec3& normal, const Vec3& mt1, const Vec3& mt2, Real rEff, int32_t t1,
                            int32_t twist, Real dampingTime, std::vector<FrictionAnchorCache::Active>& active) {
  const Frame A = frameOf(s, ia), B = frameOf(s, ib);
  FrictionAnchorCache::Active act{};
  act.t1 = t1;
  act.twist = twist;
  act.ia = ia;
  act.ib = ib;
  act.normal = normal;
  act.rEff = rEff;
  act.isNew = true;
  act.anchor.pair = pair;
  if (const FrictionAnchorCache::Anchor* kept = s.frictionAnchors.find(pair)) {
    // Reach: the contact has moved on over either body (rolling, tipping over): start again at the centre.
    const Real reach = kAnchorReach * rEff;
    const Vec3 pA = A.x + A.q * kept->localA, pB = B.x + B.q * kept->localB;
    if (tangential(pA - centre, normal).squaredNorm() <= reach * reach &&
        tangential(pB - centre, normal).squaredNorm() <= reach * reach) {
      const Real a = spookHolonomic(s.h, 0.0, dampingTime).a;
      Vec3 g;
      Real phi;
      separation(*kept, A, B, normal, g, phi);
      s.rows[size_t(t1)].rhs -= a * mt1.dot(g);
      s.rows[size_t(t1) + 1].rhs -= a * mt2.dot(g);
      s.rows[size_t(twist)].rhs -= a * phi;
      act.anchor = *kept;
      act.isNew = false;
    }
  }
  if (act.isNew) {
    act.anchor.localA = A.q.conjugate() * (centre - A.x);
    act.anchor.localB = B.q.conjugate() * (centre - B.x);
    act.anchor.dirA = A.q.conjugate() * mt1;
    act.anchor.dirB = B.q.conjugate() * mt1;
  }
  active.push_back(act);
}

void storeFrictionAnchors(SimulationState& s) {
  FrictionAnchorCache& cache = s.frictionAnchors;
  std::vector<FrictionAnchorCache::Anchor>& kept = cache.scratch;
  kept.clear();
  const Real keep = 1 - kAnchorSlipTolerance;
  for (const FrictionAnchorCache::Active& act : cache.active) {
    const ConstraintRow& f1 = s.rows[size_t(act.t1)];
    const ConstraintRow& f2 = s.rows[size_t(act.t1) + 1];
    const ConstraintRow& tw = s.rows[size_t(act.twist)];
    const Real sumN = normalSum(s.rows, f1);
    if (!(sumN > 0)) {
      // Unloaded (a box lifting off for a step): a new anchor is not kept, an old one waits for the landing.
      if (!act.isNew) kept.push_back(act.anchor);
      continue;
    }
    const Real lim = frictionLimit(f1.mu, sumN);
    bool atBound;
    if (f1.pairedRow >= 0)  // projected cone: the pair's magnitude
      atBound = !(f1.lambda * f1.lambda + f2.lambda * f2.lambda < keep * keep * lim * lim);
    else  // scaled box: each tangent
      atBound = !(std::abs(f1.lambda) < keep * lim && std::abs(f2.lambda) < keep * lim);
    atBound = atBound || !(std::abs(tw.lambda) < keep * frictionLimit(tw.mu, sumN));
    if (atBound) {
      // At the bound: slipping once the anchors (at the end of the step) are more than the slip distance apart.
      if (act.isNew) continue;
      Vec3 g;
      Real phi;
      separation(act.anchor, frameOf(s, act.ia), frameOf(s, act.ib), act.normal, g, phi);
      const Real dSlip = kAnchorSlipDistance * act.rEff;
      if (tangential(g, act.normal).norm() > dSlip || std::abs(phi) * act.rEff > dSlip) continue;
    }
    kept.push_back(act.anchor);
  }
  cache.commit(kept);
  cache.active.clear();
}

}  // namespace scree::detail
