// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The collision stages: geometry bookkeeping, the Space's broadphase and narrowphase, particle collision and
// the contact materials. With the contact events, the only solver files that use collide headers beyond the
// Simulation's own (the rest of the step sees contacts, rows and bodies).
#include "rolling_radius.h"
#include "step_stages.h"

namespace scree::detail {

void syncGeometries(SimulationState& s) {
  // Geometries added to or removed from bodies since the last step reach the space.
  for (size_t i = 0; i < s.bodies.size(); ++i) {
    const auto& geoms = s.bodies[i]->getGeometries();
    auto& reg = s.registered[i];
    bool same = geoms.size() == reg.size();
    for (size_t k = 0; same && k < geoms.size(); ++k) same = geoms[k].get() == reg[k];
    if (same) continue;
    for (Geometry* g : reg) {
      bool kept = false;
      for (const auto& ng : geoms) kept |= ng.get() == g;
      if (!kept)
        for (const GeometryRef& ref : s.space.getGeometries())
          if (ref.get() == g) {
            GeometryRef keep = ref;
            s.space.remove(keep);
            break;
          }
    }
    for (const auto& ng : geoms)
      if (!s.space.contains(ng.get())) s.space.add(ng);
    reg.clear();
    for (const auto& ng : geoms) reg.push_back(ng.get());
  }
}

void collideGeometries(SimulationState& s) {
  // Issue 18 (sweep scheduling): the chunked parallel narrowphase (Space::setUseParallelNarrowphase) stays off with
  // the partitioned sweeps too. It is an OpenMP region, and libgomp's threads spin for GOMP_SPINCOUNT after it
  // ends: on the shared 2-core machine (load 8) pyramid20's collide stage took 12.6 ms on two threads against
  // 0.4 ms on one, and the spinning thread starved the sweeps' team (docs/solver-internals.md "Persistent team").
  // To be moved onto the persistent team (scree/core/parallel.h runTeam) in Space::collide.
  s.space.setUseParallelNarrowphase(false);
  s.space.collide(s.h, s.contacts);
  s.stats.numBroadphasePairs = s.space.getNumBroadphasePairs();
}

namespace {
/// The geometries the particles may touch: all of the space's, less those whose collision groups are disabled
/// against one of the particle system's groups (Simulation::setEnableCollisions). Without particle groups the
/// space's list itself (no copy).
const std::vector<GeometryRef>& particleGeometries(SimulationState& s) {
  const auto& groups = s.granular.getGroups();
  if (groups.empty()) return s.space.getGeometries();
  s.particleGeometries.clear();
  for (const GeometryRef& g : s.space.getGeometries()) {
    bool enabled = true;
    for (uint32_t pg : groups)
      for (uint32_t gg : g->getGroups()) enabled = enabled && s.space.getEnablePair(pg, gg);
    if (enabled) s.particleGeometries.push_back(g);
  }
  return s.particleGeometries;
}
}  // namespace

void describeParticleGeometrySides(SimulationState& s) {
  // What the particle rows need of each contact's geometry (they include no collide header).
  const auto& pg = s.particleCollider.getParticleGeometryContacts();
  s.particleGeometrySides.resize(pg.size());
  const Geometry* last = nullptr;
  ParticleGeometrySide side;
  for (size_t k = 0; k < pg.size(); ++k) {
    if (pg[k].geometry != last) {
      last = pg[k].geometry;
      side.body = last->getRigidBody();
      side.material = last->getMaterial().get();
      side.rollingRadius = rollingRadius(last);
      side.geometryId = last->getId();
    }
    s.particleGeometrySides[k] = side;
  }
}

void collideParticles(SimulationState& s) {
  // Particles: their own grid against each other and every geometry. Destroys are deferred from here to the
  // end of the step so that dense indices held by the contacts stay valid through the listeners.
  GranularBodySystem& ps = s.granular;
  s.granularStep = s.particles.active(ps);
  if (!s.granularStep) return;
  // Reorder at the start of a step, before any dense index is handed out for this step.
  if (ps.size() > 0 && s.particleSteps > 0 && s.particleSteps % GranularStage::kReorderInterval == 0 &&
      !ps.isDeferring())
    ps.reorder(s.particleCollider.localityOrder(ps));
  ++s.particleSteps;
  s.particleCollider.collide(ps, particleGeometries(s), s.h);
  ps.beginDeferral();
  describeParticleGeometrySides(s);
}

void resolveContactMaterials(SimulationState& s) {
  for (GeometryContact& c : s.contacts) {
    const Material* m0 = c.geometry(0)->getMaterial().get();
    const Material* m1 = c.geometry(1)->getMaterial().get();
    const FrictionModel* fm = nullptr;
    s.materials.resolve(m0, m1, c.material(), &fm);
    c.setFrictionModel(fm);
  }
}

}  // namespace scree::detail
