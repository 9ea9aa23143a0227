// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// TestWorld: a Simulation with one material and an explicit contact material, plus makers for the usual
// bodies, so that each test case stays short. Built on the scene helpers of bench/scenes (same conventions:
// z up, one Material on every geometry, contact material (mat, mat)).
#pragma once

#include <cmath>
#include <limits>
#include <memory>

#include <scree/scree.h>

#include "scenes/scenes.h"
#include "test_build.h"

namespace scree::test {

/// What a simulation holds, by count: the model-hook tests compare it before a model is added and after it is
/// removed.
struct SimulationCounts {
  size_t bodies, geometries, constraints, stepListeners, contactListeners, models;
  bool operator==(const SimulationCounts&) const = default;
};
inline SimulationCounts countsOf(const Simulation& sim) {
  return {sim.getRigidBodies().size(), sim.getStaticGeometries().size(), sim.getConstraints().size(),
          sim.getStepEventListeners().size(), sim.getContactEventListeners().size(), sim.getModels().size()};
}

struct TestWorld : scenes::Scene {
  /// dt, gravity along -z (9.81 by default; 0 for none), friction and restitution of the contact material.
  explicit TestWorld(Real dt = 1.0 / 60.0, Real g = 9.81, Real mu = 0.5, Real restitution = 0.0) {
    scenes::initScene(*this, "test", mu, dt, 0);
    sim->setUniformGravity(Vec3(0, 0, -g));
    material->setRestitution(restitution);
    contactMaterial->setRestitution(restitution);
  }

  /// Static 100 x 100 x 1 m box with its top face at z = 0.
  RigidBodyRef addGround() { return scenes::addGround(*this); }
  RigidBodyRef addStaticBox(const Vec3& halfExtents, const Vec3& pos, const Quat& q = Quat::Identity()) {
    return scenes::addStaticBox(*this, halfExtents, pos, q);
  }
  /// Dynamic box; mass <= 0 keeps the mass from the geometry (volume x density 1000).
  RigidBodyRef addBox(const Vec3& halfExtents, const Vec3& pos, Real mass = 1.0, const Quat& q = Quat::Identity()) {
    if (mass > 0) return scenes::addBox(*this, halfExtents, mass, pos, q);
    auto geom = std::make_shared<Geometry>(std::make_shared<Box>(halfExtents));
    geom->setMaterial(material);
    auto body = std::make_shared<RigidBody>();
    body->add(geom);
    body->setPosition(pos);
    body->setRotation(q);
    sim->add(body);
    return body;
  }
  /// A "glue" material for the manual's DIRECT particle mode: glue-glue friction and adhesion infinite, adhesive
  /// overlap 0, restitution 0; glue-world (this world's material) restitution 0; both with solve type `type`.
  MaterialRef addGlueMaterial(FrictionModel::SolveType type) {
    auto glue = std::make_shared<Material>("glue");
    auto cm = sim->getMaterialManager().getOrCreateContactMaterial(glue, glue);
    cm->setFrictionCoefficient(std::numeric_limits<Real>::infinity());
    cm->setAdhesion(std::numeric_limits<Real>::infinity(), 0.0);
    cm->setRestitution(0.0);
    cm->setSolveType(type);
    auto cg = sim->getMaterialManager().getOrCreateContactMaterial(glue, material);
    cg->setRestitution(0.0);
    cg->setSolveType(type);
    return glue;
  }
  /// Dynamic sphere; mass <= 0 keeps the mass from the geometry.
  RigidBodyRef addSphere(Real radius, const Vec3& pos, Real mass = 1.0) {
    auto geom = std::make_shared<Geometry>(std::make_shared<Sphere>(radius));
    geom->setMaterial(material);
    auto body = std::make_shared<RigidBody>();
    body->add(geom);
    if (mass > 0) body->setMass(mass);
    body->setPosition(pos);
    sim->add(body);
    return body;
  }

  void steps(int n) {
    for (int i = 0; i < n; ++i) sim->stepForward();
  }
  /// Steps round(seconds / dt) times.
  void stepSeconds(Real seconds) { steps(int(std::lround(seconds / dt))); }
  Real time() const { return sim->getTimeStamp(); }

  /// All contact points of the last step.
  std::vector<ContactPoint> contactPoints() const {
    std::vector<ContactPoint> out;
    for (const GeometryContact& c : sim->getContacts())
      for (const ContactPoint& p : c.points()) out.push_back(p);
    return out;
  }
  /// Contact points of the last step that carry force or overlap (speculative points with a gap excluded).
  std::vector<ContactPoint> activeContactPoints() const {
    std::vector<ContactPoint> out;
    for (const ContactPoint& p : contactPoints())
      if (p.depth >= 0 || p.normalForce > 0) out.push_back(p);
    return out;
  }
  bool finite() const { return scenes::allFinite(*sim); }
};

/// Kinetic + gravitational potential energy of a body (gravity g along -z, zero level z = 0), J.
inline Real mechanicalEnergy(const RigidBody& b, Real g) {
  return b.getKineticEnergy() + b.getMass() * g * b.getCmPosition().z();
}

}  // namespace scree::test
