// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Shock ordering: the support levels of the bodies and the order in which the shock-propagation pass
// (PgsSolver::shockPass) visits the couplings, read by the solve stage.
#include <algorithm>

#include "step_stages.h"

namespace scree::detail {

void buildShockOrder(SimulationState& s) {
  // Support levels by breadth-first search over the graph of contacts and constraints from non-dynamic bodies,
  // body-less geometries and the world (level 0). Couplings between different levels freeze the lower body in
  // the shock pass and are visited in increasing lower level; couplings within one level are left to the
  // sweeps.
  const size_t nb = s.bodies.size();
  const int kUnreached = 1 << 30;
  s.level.assign(nb, kUnreached);
  if (s.adjacency.size() < nb) s.adjacency.resize(nb);
  for (size_t i = 0; i < nb; ++i) s.adjacency[i].clear();
  auto& frontier = s.frontier;
  frontier.clear();
  for (uint32_t k = 0; k < s.couplings.size(); ++k) {
    const auto& c = s.couplings[k];
    if (c.ia >= 0) s.adjacency[c.ia].push_back(k);
    if (c.ib >= 0) s.adjacency[c.ib].push_back(k);
  }
  for (size_t i = 0; i < nb; ++i)
    if (s.sb[i].invMass == 0) {
      s.level[i] = 0;
      frontier.push_back(uint32_t(i));
    }
  for (const auto& c : s.couplings) {
    // A dynamic body touching a body-less (static) geometry, or jointed to the world, is at level 1.
    if (c.ia < 0 && c.ib >= 0 && s.level[c.ib] > 1) { s.level[c.ib] = 1; frontier.push_back(uint32_t(c.ib)); }
    if (c.ib < 0 && c.ia >= 0 && s.level[c.ia] > 1) { s.level[c.ia] = 1; frontier.push_back(uint32_t(c.ia)); }
  }
  // frontier holds the level-0 seeds, then the level-1 ones (each loop above pushes one level), so it is already
  // in level order. (A stable_sort here allocated its buffer every step; issue 18: no per-step allocation.)
  for (size_t head = 0; head < frontier.size(); ++head) {
    const uint32_t b = frontier[head];
    for (uint32_t k : s.adjacency[b]) {
      const auto& c = s.couplings[k];
      const int other = c.ia == int32_t(b) ? c.ib : c.ia;
      if (other >= 0 && s.level[other] > s.level[b] + 1) {
        s.level[other] = s.level[b] + 1;
        frontier.push_back(uint32_t(other));
      }
    }
  }
  s.shock.clear();
  auto& order = s.order;
  order.clear();
  // Within a level the couplings go in contact order (then the joints'), whatever the row layout: the grouped
  // build (contact_rows.cpp) lays the contacts out by region, and visiting a level's supports region by region
  // instead of along the contact order tripled the time pyramid20's shock pass spent in clamped block solves.
  const uint32_t numCouplings = uint32_t(s.couplings.size());
  s.couplingOrder.clear();
  if (s.rowGroupsReady) {
    for (uint32_t ci = 0; ci < s.contacts.size(); ++ci)
      if (s.contactLayout[ci].count > 0) s.couplingOrder.push_back(s.contactLayout[ci].coupling);
    for (uint32_t k = uint32_t(s.couplingOrder.size()); k < numCouplings; ++k) s.couplingOrder.push_back(k);
  }
  for (uint32_t n = 0; n < numCouplings; ++n) {
    const uint32_t k = s.rowGroupsReady ? s.couplingOrder[n] : n;
    const auto& c = s.couplings[k];
    const int la = c.ia >= 0 ? s.level[c.ia] : 0, lb = c.ib >= 0 ? s.level[c.ib] : 0;
    if (la == lb) continue;
    if (c.joint && c.ia >= 0 && c.ib >= 0) {
      // A joint only propagates support from a body at least as heavy as the one it holds: freezing a light
      // link under a heavy load would force the light link's velocity error onto the load.
      const Real invLow = la < lb ? s.sb[c.ia].invMass : s.sb[c.ib].invMass;
      const Real invHigh = la < lb ? s.sb[c.ib].invMass : s.sb[c.ia].invMass;
      if (invLow > invHigh) continue;
    }
    order.push_back({std::min(la, lb), k});
  }
  // Stable counting sort by lower level into reused buffers (std::stable_sort allocated a buffer every step).
  int maxLevel = 0;
  for (const auto& e : order) maxLevel = std::max(maxLevel, e.first);
  s.levelStart.assign(size_t(maxLevel) + 2, 0);
  for (const auto& e : order) ++s.levelStart[size_t(e.first) + 1];
  for (size_t l = 1; l < s.levelStart.size(); ++l) s.levelStart[l] += s.levelStart[l - 1];
  s.orderSorted.resize(order.size());
  for (const auto& e : order) s.orderSorted[s.levelStart[size_t(e.first)]++] = e;
  for (const auto& [lvl, k] : s.orderSorted) {
    const auto& c = s.couplings[k];
    const int la = c.ia >= 0 ? s.level[c.ia] : 0, lb = c.ib >= 0 ? s.level[c.ib] : 0;
    const int frozen = la < lb ? 0 : 1;
    s.shock.push_back({c.begin, c.count, frozen, frozen == 0 ? c.ib : c.ia, frozen == 0 ? c.ia : c.ib});
  }
}

}  // namespace scree::detail
