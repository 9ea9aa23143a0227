// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Store-results stage: the solved impulses become the contact points' forces and next step's warm start, the
// constraints' results (Constraint::storeResult) and the particle contacts' forces.
#include <cmath>

#include "step_stages.h"

namespace scree::detail {

void storeResults(SimulationState& s) {
  const Real invH = 1.0 / s.h;
  s.warmStart.beginStore();
  // Next step's warm start: a row's sweeps' impulse when the shock pass recorded one (s.sweepLambda), else its
  // solved impulse (solve_stage.cpp rigidShock says why).
  auto warmLambda = [&s](int32_t i) {
    return size_t(i) < s.sweepLambda.size() && !std::isnan(s.sweepLambda[i]) ? s.sweepLambda[i] : s.rows[i].lambda;
  };
  // Inlined into both loops below: called, it cost pyramid20's store about 12 % more instructions.
  auto store = [&](const PointRows& pr) __attribute__((always_inline)) {
    GeometryContact& c = s.contacts[pr.contact];
    ContactPoint& p = c.points()[pr.point];
    const Real ln = s.rows[pr.normal].lambda;
    Vec3 ft = Vec3::Zero();
    if (pr.t1 >= 0) ft = s.rows[pr.t1].lambda * pr.tangent1 + s.rows[pr.t1 + 1].lambda * pr.tangent2;
    if (pr.twist >= 0) ft = pr.share * ft + s.rows[pr.twist].lambda * pr.twistArm;  // manifold friction's share
    p.normalImpulse = ln;
    p.frictionImpulse = ft;
    p.normalForce = ln * invH;
    p.frictionForce = ft * invH;
    p.impactSpeed = pr.impactSpeed;
    Vec3 fw = Vec3::Zero();
    if (pr.t1 >= 0) fw = warmLambda(pr.t1) * pr.tangent1 + warmLambda(pr.t1 + 1) * pr.tangent2;
    if (pr.twist >= 0) fw = pr.share * fw + warmLambda(pr.twist) * pr.twistArm;
    s.warmStart.add({contactPairKey(c), p.featureId, warmLambda(pr.normal), fw, pr.impactSpeed, p.point});
  };
  // In contact order, which is the warm-start cache's pair order (WarmStartCache::commit sorts anything else): the
  // grouped row build (contact_rows.cpp) lays the points out by region, and each contact's points are together.
  if (s.rowGroupsReady) {
    for (uint32_t ci = 0; ci < s.contacts.size(); ++ci)
      if (s.contactLayout[ci].count > 0)
        for (uint32_t j = s.contactLayout[ci].point; j < s.pointRows.size() && s.pointRows[j].contact == ci; ++j)
          store(s.pointRows[j]);
  } else {
    for (const PointRows& pr : s.pointRows) store(pr);
  }
  s.warmStart.commit();
  storeFrictionAnchors(s);  // issue 18 (friction anchors, friction_anchor.h): keep the anchors that stick
  for (const auto& r : s.ranges) r.c->storeResult(s.rows.data() + r.begin, s.rowDofs.data() + r.begin, r.count, s.h);
  if (s.granularStep) {
    const ParticleContactLists lists{&s.particleCollider.getParticleParticleContacts(),
                                     &s.particleCollider.getParticleGeometryContacts(), &s.particleGeometrySides,
                                     s.particleCollider.getCellSize()};
    s.particles.storeResults(s.granular, lists, s.h);
  }
}

}  // namespace scree::detail
