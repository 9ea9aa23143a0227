// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Terrain shovel read-outs (digging force and fill, TerrainShovelStats in terrain.h) and the ground cutting force
// (TerrainDataInterface::setShovelGroundCuttingForce). The definitions and the reasons for them are in the
// headers; this file only reads the step's contact lists and adjusts shovel-terrain contact points.
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "scree/core/errors.h"
#include "scree/model/terrain.h"
#include "scree/solver/constraint.h"
#include "scree/solver/simulation.h"
#include "scree/solver/spook.h"

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

// ---- ground cutting force of a shovel that is also a deformer: one friction-like row along forward -------------
// terrain.h ("A shovel that is also a deformer"): a velocity row on the relative velocity of the shovel and the
// terrain at the cutting edge along the shovel's forward direction, target 0, impulse bounds +-F h. It acts only
// along forward (a shovel sliding sideways does not feel it), holds the shovel while the other forces along
// forward stay below F, and applies exactly F against the motion while the edge moves along forward.
class Terrain::CuttingConstraint : public Constraint {
 public:
  CuttingConstraint(RigidBodyRef shovelBody, RigidBodyRef terrainBody, const Geometry* shovel)
      : Constraint(std::move(shovelBody), std::move(terrainBody), 1, "TerrainGroundCutting"), shovel_(shovel) {
    setName("ground cutting force");
    setSolveType(FrictionModel::ITERATIVE);  // a bounded row: PGS clamps it, no LCP in the direct solver
    setEnableCollisions(true);               // the shovel keeps colliding with the terrain
  }
  const Geometry* shovel() const { return shovel_; }
  /// Armed for this step (the contact listener saw the shovel touch the terrain) with the force F, N.
  void arm(Real force) { force_ = force, active_ = true, solved_ = false; }
  bool active() const { return active_; }
  /// True when this step's solve had the row (armed, and the shovel's body dynamic and in the simulation).
  bool solved() const { return solved_; }
  void disarm() { active_ = false, solved_ = false; }
  /// The world direction the row acted along in the last step (unit forward).
  const Vec3& direction() const { return dir_; }

  void addRows(const ConstraintContext& ctx, std::vector<detail::ConstraintRow>& rows,
               std::vector<int>& outDofs) override {
    if (!active_) return;
    const Transform& G = shovel_->getTransform();  // this step's collision pose
    const Vec3 fwdLocal = shovel_->getPropertyContainer().getPropertyVec3(ShovelForwardProperty);
    const Vec3 fwd = G.rotate(fwdLocal);
    if (!(fwd.norm() > 0)) return;
    dir_ = fwd.normalized();
    const Vec3 tip = G.p + fwd;  // the cutting edge (terrain.h, shovels)
    detail::ConstraintRow r;
    r.bodyA = ctx.indexA;
    r.bodyB = ctx.indexB;
    r.jLinA = dir_;
    r.jAngA = (tip - a_->getCmPosition()).cross(dir_);
    if (b_) {
      r.jLinB = -dir_;
      r.jAngB = -(tip - b_->getCmPosition()).cross(dir_);
    }
    r.rhs = 0;  // no relative motion along forward unless the other forces exceed F
    r.e = spookVelocityRegularisation(ctx.h, getCompliance(0));
    r.lo = -force_ * ctx.h;
    r.hi = force_ * ctx.h;
    r.lambda = std::clamp(warm_[0], r.lo, r.hi);
    r.solveType = FrictionModel::ITERATIVE;
    rows.push_back(r);
    outDofs.push_back(0);
    solved_ = true;
  }

 private:
  const Geometry* shovel_;
  Real force_ = 0;
  bool active_ = false, solved_ = false;
  Vec3 dir_ = Vec3::UnitX();
};

namespace {
RigidBodyRef refOf(Simulation& sim, const RigidBody* b) {
  if (!b) return nullptr;
  for (const RigidBodyRef& r : sim.getRigidBodies())
    if (r.get() == b) return r;
  return nullptr;
}
}  // namespace

// ---- ground cutting force: the contact listener part ------------------------------------------------------------
void Terrain::applyGroundCuttingForce(GeometryContact& c, const Geometry& other) {
  const Real value = data_->getShovelGroundCuttingForce();
  if (!(value > 0) || !isGeometryShovel(other)) return;
  if (isDeformer(other)) {
    // A constant force along forward: the shovel's cutting row (CuttingConstraint above), armed for this step.
    if (!c.isEnabled() || c.isSensor() || c.points().empty()) return;
    const RigidBody* body = other.getRigidBody();
    if (!body || body == geometry_->getRigidBody()) return;  // a static shovel does not move: nothing to resist
    CuttingConstraint* row = nullptr;
    for (const auto& k : cutting_)
      if (k->shovel() == &other && k->getBodyAt(0) == body) row = k.get();
    if (!row) {
      Simulation* sim = getSimulation();
      RigidBodyRef a = sim ? refOf(*sim, body) : nullptr;
      if (!a) return;
      RigidBodyRef b = geometry_->getRigidBody() ? refOf(*sim, geometry_->getRigidBody()) : nullptr;
      auto k = std::make_shared<CuttingConstraint>(a, b, &other);
      cutting_.push_back(k);
      addOwned(ConstraintRef(k));  // rows only while armed (addRows), so it may stay installed
      row = k.get();
    }
    row->arm(value);
  } else {
    // A scale on the friction coefficient: mu (1 + value).
    const Real muContact = c.material().getFrictionCoefficient();
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
  // The ground cutting rows of this step (shovels that are deformers): their force on the shovel, then disarmed.
  for (const auto& k : cutting_) {
    const bool solved = k->solved();
    k->disarm();
    if (!solved) continue;  // no row this step: no force (getCurrentForce would be an older step's)
    const auto it = index.find(k->shovel());
    if (it != index.end()) shovelStats_[it->second].groundCuttingForce += k->getCurrentForce(0) * k->direction();
  }
  if (shovelStats_.empty()) return;

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
