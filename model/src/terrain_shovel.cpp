// Terrain shovel read-outs (digging force and fill, TerrainShovelStats in terrain.h) and the ground cutting force
// (TerrainDataInterface::setShovelGroundCuttingForce). The definitions and the reasons for them are in the
// headers; this file only reads the step's contact lists and adjusts shovel-terrain contact points.
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "scree/core/errors.h"
#include "scree/model/terrain.h"
#include "scree/solver/simulation.h"

namespace scree {

// ---- ground cutting force: parameter ----------------------------------------------------------------------------
void TerrainDataInterface::setShovelGroundCuttingForce(Real force) {
  if (!(std::isfinite(force) && force >= 0))
    detail::throwInvalid("TerrainDataInterface::setShovelGroundCuttingForce", "force", force,
                         "must be finite and >= 0");
  groundCuttingForce_ = force;
}

namespace {
/// A deformer carries the bool property (either value: the value is its useContactDepth, terrain.h).
bool isDeformer(const Geometry& g) { return Terrain::isGeometryDeformer(g); }
}  // namespace

// ---- ground cutting force: the contact listener part ------------------------------------------------------------
void Terrain::applyGroundCuttingForce(GeometryContact& c, const Geometry& other) {
  const Real value = data_->getShovelGroundCuttingForce();
  if (!(value > 0) || !isGeometryShovel(other)) return;
  const Real muContact = c.material().getFrictionCoefficient();
  if (isDeformer(other)) {
    // A constant force: raise every point's coefficient by value / N_last (terrain_data_interface.h).
    Real nLast = 0;
    for (const auto& [g, n] : shovelNormalForce_)
      if (g == &other) nLast = n;
    if (!(nLast > 0)) return;
    const Real dMu = value / nLast;
    for (ContactPoint& p : c.points()) {
      const Real mu = p.frictionCoefficient >= 0 ? p.frictionCoefficient : muContact;
      p.frictionCoefficient = mu + dMu;
    }
  } else {
    // A scale on the friction coefficient: mu (1 + value).
    for (ContactPoint& p : c.points()) {
      const Real mu = p.frictionCoefficient >= 0 ? p.frictionCoefficient : muContact;
      p.frictionCoefficient = mu * (1 + value);
    }
  }
}

// ---- read-outs (post step) --------------------------------------------------------------------------------------
TerrainShovelStats Terrain::getShovelStats(const Geometry& shovel) const {
  for (const TerrainShovelStats& s : shovelStats_)
    if (s.shovel == &shovel) return s;
  TerrainShovelStats none;
  none.shovel = &shovel;
  return none;
}

void Terrain::updateShovelStats() {
  shovelStats_.clear();
  shovelNormalForce_.clear();
  Simulation* sim = getSimulation();
  if (!sim) return;
  // 1. The valid shovels, with the region their fill is counted in (terrain.h).
  struct Region {
    Aabb box;
    Vec3 planePoint, up;  // shovel plane (world) and its unit normal
  };
  std::vector<Region> regions;
  std::unordered_map<const Geometry*, size_t> index;
  auto consider = [&](const GeometryRef& g) {
    if (g.get() == geometry_.get() || !isGeometryShovel(*g)) return;
    g->updateTransform();
    const Transform& G = g->getTransform();
    const PropertyContainer& pc = g->getPropertyContainer();
    const Vec3 up = G.rotate(pc.getPropertyVec3(ShovelUpProperty));
    const Vec3 tip = G.p + G.rotate(pc.getPropertyVec3(ShovelForwardProperty));
    Region r;
    r.box = g->getBoundingBox();
    if (const RigidBody* b = g->getRigidBody())
      for (const GeometryRef& o : b->getGeometries()) {
        if (o.get() == g.get()) continue;
        o->updateTransform();
        const Aabb ob = o->getBoundingBox();
        r.box.lo = r.box.lo.cwiseMin(ob.lo);
        r.box.hi = r.box.hi.cwiseMax(ob.hi);
      }
    // Raised by the larger horizontal side: a heap on the footprint stands lower than that (terrain.h).
    r.box.hi.z() += std::max(r.box.hi.x() - r.box.lo.x(), r.box.hi.y() - r.box.lo.y());
    r.up = up.normalized();
    r.planePoint = tip + up;
    index[g.get()] = shovelStats_.size();
    TerrainShovelStats s;
    s.shovel = g.get();
    shovelStats_.push_back(s);
    regions.push_back(r);
  };
  for (const RigidBodyRef& b : sim->getRigidBodies())
    for (const GeometryRef& g : b->getGeometries()) consider(g);
  for (const GeometryRef& g : sim->getStaticGeometries()) consider(g);
  if (shovelStats_.empty()) return;
  shovelNormalForce_.reserve(shovelStats_.size());
  for (const TerrainShovelStats& s : shovelStats_) shovelNormalForce_.emplace_back(s.shovel, 0.0);

  // 2. Contacts with the terrain geometry: geometry 0 is pushed along +normal (normalForce n + frictionForce).
  for (const GeometryContact& c : sim->getContacts()) {
    const int self = c.geometry(0) == geometry_.get() ? 0 : (c.geometry(1) == geometry_.get() ? 1 : -1);
    if (self < 0 || !c.isEnabled() || c.isSensor()) continue;
    const auto it = index.find(c.geometry(1 - self));
    if (it == index.end()) continue;
    const Real sign = self == 1 ? 1.0 : -1.0;  // the shovel is geometry 0 when the terrain is 1
    for (const ContactPoint& p : c.points()) {
      if (!p.enabled) continue;
      shovelStats_[it->second].terrainContactForce += sign * (p.normalForce * p.normal + p.frictionForce);
      shovelNormalForce_[it->second].second += p.normalForce;
    }
  }

  // 3. Contacts of terrain particles with the shovels: the particle (a) feels normalForce n + frictionForce, the
  //    geometry the opposite. Dense indices of this step are valid through the post-step listeners.
  const GranularBodySystem& gbs = sim->getGranularBodySystem();
  if (particles_.empty()) return;
  std::vector<char> isOurs(gbs.size(), 0);
  for (const auto& [id, vol] : particles_)
    if (gbs.isValid(id)) isOurs[gbs.denseIndex(id)] = 1;
  for (const ParticleContact& c : sim->getParticleGeometryContacts()) {
    if (c.sensor || !c.enabled || c.a >= isOurs.size() || !isOurs[c.a]) continue;
    const auto it = index.find(c.geometry);
    if (it == index.end()) continue;
    shovelStats_[it->second].particleContactForce -= c.normalForce * c.normal + c.frictionForce;
  }

  // 4. Fill: terrain particles with their centre in the region's box and on the up side of the shovel plane.
  for (const auto& [id, vol] : particles_) {
    if (!gbs.isValid(id)) continue;
    const Vec3 p = gbs.getPosition(id);
    for (size_t k = 0; k < regions.size(); ++k) {
      const Region& r = regions[k];
      if ((p.array() < r.box.lo.array()).any() || (p.array() > r.box.hi.array()).any()) continue;
      if ((p - r.planePoint).dot(r.up) < 0) continue;
      shovelStats_[k].fillVolume += vol;
      ++shovelStats_[k].fillParticles;
    }
  }
}

}  // namespace scree
