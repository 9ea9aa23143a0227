// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Store-results stage: the solved impulses become the contact points' forces and next step's warm start, the
// constraints' results (Constraint::storeResult) and the particle contacts' forces.
#include <algorithm>
#include <cmath>

#include "scree/core/parallel.h"

#include "step_stages.h"

namespace scree::detail {

void storeResults(SimulationState& s) {
  const Real invH = 1.0 / s.h;
  // Next step's warm start: a row's sweeps' impulse when the shock pass recorded one (s.sweepLambda), else its
  // solved impulse (solve_stage.cpp rigidShock says why).
  auto warmLambda = [&s](int32_t i) {
    return size_t(i) < s.sweepLambda.size() && !std::isnan(s.sweepLambda[i]) ? s.sweepLambda[i] : s.rows[i].lambda;
  };
  // Inlined into the loops below: called, it cost pyramid20's store about 12 % more instructions. Returns the
  // point's warm-start entry.
  // pair: the contact's pair key (contactPairKey), which the grouped row build has kept per contact.
  auto store = [&](const PointRows& pr, uint64_t pair) __attribute__((always_inline)) {
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
    return WarmStartCache::Entry{pair, p.featureId, warmLambda(pr.normal), fw, pr.impactSpeed, p.point};
  };
  if (s.rowGroupsReady) {
    // DESIGN (issue 18, two-thread scaling; docs/solver-internals.md "Each thread lays out and takes down its
    // region"): with the rows laid out by region (contact_rows.cpp), the contacts are stored on the two threads,
    // in the row build's chunks shared from both ends (contact_rows.h forChunksFromBothEnds), so that each
    // region's contacts are stored mostly on the thread that built, prepared and swept their rows, and the rows'
    // impulses are read where they were written (on the program thread they crossed between the cores, and the
    // next step's row build had to take the lines back). The entries keep the cache's order, contact order: each
    // contact's entries go to the place the contacts before it leave free, and each contact's run is ordered by
    // feature on its thread. Same entries in the same places on any thread count.
    auto& layout = s.contactLayout;
    uint32_t entries = 0;
    uint64_t lastPair = 0;
    bool ascending = true, firstPair = true;
    for (uint32_t ci = 0; ci < s.contacts.size(); ++ci) {
      ContactLayout& l = layout[ci];
      if (l.count == 0) continue;
      l.entry = entries;
      entries += l.points;
      // The row build's copy of the key (contact_rows.cpp): reading it from the contact would load both
      // geometries of every contact on this thread.
      const uint64_t pair = s.contactLayoutPairs[ci];
      ascending = ascending && (firstPair || pair > lastPair);
      lastPair = pair;
      firstPair = false;
    }
    s.warmStart.beginStorePlaced(entries);
    const int threads = s.rowGroupThreads;
    int ran = 1;
    auto storeContact = [&](uint32_t ci) {
      const ContactLayout& l = layout[ci];
      if (l.count == 0) return;
      const uint64_t pair = s.contactLayoutPairs[ci];
      for (uint32_t k = 0; k < l.points; ++k) s.warmStart.set(l.entry + k, store(s.pointRows[l.point + k], pair));
      s.warmStart.sortRun(l.entry, l.entry + l.points);
    };
    if (threads > 1) {
      // The row build's chunks (contact_rows.cpp), shared from both ends (contact_rows.h forChunksFromBothEnds).
      const auto& chunks = s.contactChunks;
      ran = forChunksFromBothEnds(threads, uint32_t(chunks.size()), [&](uint32_t c) {
        const std::vector<uint32_t>& list = s.contactGroups[chunks[c].group];
        for (uint32_t i = chunks[c].first; i < chunks[c].last; ++i) storeContact(list[i]);
      });
    } else {
      for (const auto& list : s.contactGroups)
        for (const uint32_t ci : list) storeContact(ci);
    }
    s.rowBuildTeamBusy = s.rowBuildTeamBusy || ran < threads;
    s.warmStart.commitPlaced(ascending);
  } else {
    s.warmStart.beginStore();
    for (const PointRows& pr : s.pointRows) s.warmStart.add(store(pr, contactPairKey(s.contacts[pr.contact])));
    s.warmStart.commit();
  }
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
