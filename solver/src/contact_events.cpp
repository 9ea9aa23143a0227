// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Contact events stage: impact (first step a pair touches), contact (later steps) and separation (the step
// after the last) reach the ContactEventListeners, which may modify or remove contacts before the rows are
// built. Speculative-only contacts (every point a gap) are solved but raise no event.
#include "step_stages.h"

namespace scree::detail {

namespace {
bool touching(const GeometryContact& c) {
  for (const ContactPoint& p : c.points())
    if (p.depth >= 0) return true;
  return false;
}
}  // namespace

void runContactEvents(SimulationState& s) {
  auto& cur = s.curPairs;
  auto& prev = s.prevPairs;
  cur.clear();
  bool anyRemoved = false;
  for (GeometryContact& c : s.contacts) {
    if (!touching(c)) {
      // Speculative only: solved (so nothing tunnels), but no events; sensors ignore it.
      if (c.isSensor()) c.setEnable(false);
      continue;
    }
    const uint64_t key = contactPairKey(c);
    auto it = std::lower_bound(prev.begin(), prev.end(), key, [](const auto& e, uint64_t k) { return e.first < k; });
    const bool impact = !(it != prev.end() && it->first == key);
    c.setImpact(impact);
    cur.push_back({key, {c.geometry(0), c.geometry(1)}});
    for (auto& l : s.contactListeners) {
      const int want = impact ? ContactEventListener::IMPACT : ContactEventListener::CONTACT;
      if (!(l->getMask() & want) || !l->matches(c.geometry(0), c.geometry(1))) continue;
      const auto policy = impact ? l->impact(s.time, c) : l->contact(s.time, c);
      if (policy == ContactEventListener::REMOVE_CONTACT) {
        c.setEnable(false);
        c.points().clear();
        anyRemoved = true;
        break;
      }
    }
  }
  // Separation: touching last step, not now (cur is sorted because contacts are).
  bool wantSeparation = false;
  for (auto& l : s.contactListeners) wantSeparation |= (l->getMask() & ContactEventListener::SEPARATION) != 0;
  if (wantSeparation) {
    size_t j = 0;
    for (const auto& e : prev) {
      while (j < cur.size() && cur[j].first < e.first) ++j;
      if (j < cur.size() && cur[j].first == e.first) continue;
      for (auto& l : s.contactListeners)
        if ((l->getMask() & ContactEventListener::SEPARATION) && l->matches(e.second.first, e.second.second))
          l->separation(s.time, e.second.first, e.second.second);
    }
  }
  std::swap(prev, cur);
  if (anyRemoved)
    s.contacts.erase(std::remove_if(s.contacts.begin(), s.contacts.end(),
                                    [](const GeometryContact& c) { return c.points().empty(); }),
                     s.contacts.end());
  runParticleContactEvents(s);
}

void runParticleContactEvents(SimulationState& s) {
  // Only listeners that asked for particle contacts (PARTICLE_CONTACT) are called: a scene without them pays
  // one mask test per contact listener.
  if (!s.granularStep) return;
  auto& pp = s.particleCollider.getParticleParticleContacts();
  auto& pg = s.particleCollider.getParticleGeometryContacts();
  bool called = false;
  for (auto& l : s.contactListeners)
    if (l->getMask() & ContactEventListener::PARTICLE_CONTACT) {
      l->particleContacts(s.time, pp, pg);
      called = true;
    }
  // The rows read one geometry description per particle-geometry contact: keep it aligned if a listener
  // changed the list (the contract says it does not; this keeps a careless listener from reading past it).
  if (called && pg.size() != s.particleGeometrySides.size()) describeParticleGeometrySides(s);
}

}  // namespace scree::detail
