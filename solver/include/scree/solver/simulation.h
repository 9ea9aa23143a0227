// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Simulation (AGX: agxSDK::Simulation): owns the bodies, geometries, constraints and listeners, and runs
// the step. stepForward() is a fixed pipeline of named stages (docs/design.md §2), each timed in StepStats:
//   PRE_COLLIDE listeners; collision (geometries synced with the space, Space broadphase + narrowphase,
//   particle collision, contact materials resolved); contact listeners; PRE_STEP listeners; forces (free
//   velocities); rows (contacts, constraints, particles); solve (PGS, DIRECT or hybrid, particle sweeps);
//   integration; results stored; position projection; finiteness check; POST_STEP listeners; particle
//   destroys deferred since collision applied (so listeners, post included, may create and destroy particles
//   while reading this step's particle contacts).
// No exceptions inside stepForward: a body whose state turns non-finite is reported (getLastStepReport(),
// logged as an error naming the body), restored to its last finite state and stopped.
#pragma once

#include <chrono>
#include <concepts>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "scree/collide/geometry.h"
#include "scree/collide/space.h"
#include "scree/core/contact.h"
#include "scree/core/granular_body_system.h"
#include "scree/core/listeners.h"
#include "scree/core/material.h"
#include "scree/core/particle_contact.h"
#include "scree/core/rigid_body.h"
#include "scree/solver/constraint.h"
#include "scree/solver/model.h"
#include "scree/solver/solver.h"

namespace scree {

namespace detail {
struct SimulationState;
}

/// Wall-clock time of each stage of the last step, in seconds, in step order, and counts. The step's two ends
/// read the steady clock; the stage boundaries read a tick counter (the time-stamp counter on x86-64, see
/// solver/src/simulation.cpp), and each stage gets the step's time times its share of the ticks, so the stages
/// add up to the step. The sums `collide`, `rows` and `integrate` keep their earlier meaning.
struct StepStats {
  double preCollide = 0;         ///< s, PRE_COLLIDE step listeners
  double syncGeometries = 0;     ///< s, geometries added to or removed from bodies since the last step -> space
  double collideGeometries = 0;  ///< s, Space broadphase and narrowphase
  double collideParticles = 0;   ///< s, particle-particle and particle-geometry collision
  double resolveMaterials = 0;   ///< s, contact material and friction model of each geometry contact
  double collide = 0;            ///< s, syncGeometries + collideGeometries + collideParticles + resolveMaterials
  double contactEvents = 0;      ///< s, impact / contact / separation listeners (and particle contact listeners)
  double pre = 0;                ///< s, PRE_STEP step listeners
  double applyForces = 0;        ///< s, free velocities v + h M^-1 f of bodies and particles
  double contactRows = 0;        ///< s, rows of the geometry contacts (with warm start)
  double constraintRows = 0;     ///< s, rows of joints and models
  double particleRows = 0;       ///< s, particle contact units
  double rows = 0;               ///< s, applyForces + contactRows + constraintRows + particleRows
  double solve = 0;              ///< s, the velocity solve (PGS, DIRECT / hybrid, particle sweeps, shock pass)
  double integrateMotion = 0;    ///< s, positions and rotations of bodies and particles from the solved velocities
  double storeResults = 0;       ///< s, contact forces, warm-start caches and constraint results
  double projectPositions = 0;   ///< s, post-step position projection (Solver::setUsePositionProjection)
  double checkFinite = 0;        ///< s, non-finite bodies restored and stopped
  double integrate = 0;          ///< s, integrateMotion + storeResults + projectPositions + checkFinite
  double post = 0;               ///< s, POST_STEP step listeners
  double compactParticles = 0;   ///< s, particle destroys deferred during the step applied (after post)
  double total = 0;              ///< s, the whole step
  size_t numBroadphasePairs = 0;
  size_t numContacts = 0;
  size_t numContactPoints = 0;
  size_t numParticleContacts = 0;  ///< particle-particle plus solved particle-geometry contact points
};

/// The stage times of the last step in milliseconds (StepStats holds the same in seconds), for users reading
/// where a step's time goes (as Box2D's b2Profile and AGX's timing statistics). One field per stage, in step
/// order; the stages run back to back, so they add up to `total` (to the clock's resolution). Broadphase and
/// narrowphase are one stage (`collideGeometries`): the Space runs them together. A stage with nothing to do in
/// this step (no step listeners, no particles, no constraints) reads no clock and shows 0; its few nanoseconds
/// of checks count to the next stage (docs/solver-internals.md "Fixed cost of small rigid scenes").
struct StepTimings {
  double preCollide = 0;         ///< ms, PRE_COLLIDE step listeners
  double syncGeometries = 0;     ///< ms, geometry additions and removals reach the Space
  double collideGeometries = 0;  ///< ms, broadphase and narrowphase of the geometries
  double collideParticles = 0;   ///< ms, particle collision
  double resolveMaterials = 0;   ///< ms, contact materials and friction models
  double contactEvents = 0;      ///< ms, contact listeners (geometry and particle contacts)
  double pre = 0;                ///< ms, PRE_STEP step listeners
  double applyForces = 0;        ///< ms, external forces into free velocities
  double contactRows = 0;        ///< ms, contact row build (with warm start)
  double constraintRows = 0;     ///< ms, joint and model row build
  double particleRows = 0;       ///< ms, particle contact units
  double solve = 0;              ///< ms, the velocity solve: PGS, DIRECT / hybrid, particle sweeps, shock passes
  double integrateMotion = 0;    ///< ms, positions and rotations
  double storeResults = 0;       ///< ms, contact forces, warm-start caches, constraint results
  double projectPositions = 0;   ///< ms, post-step position projection
  double checkFinite = 0;        ///< ms, non-finite check
  double post = 0;               ///< ms, POST_STEP step listeners (models' post-step work included)
  double compactParticles = 0;   ///< ms, deferred particle destroys
  double total = 0;              ///< ms, the whole step
  /// Sum of the stage fields (everything but `total`).
  double sumOfStages() const {
    return preCollide + syncGeometries + collideGeometries + collideParticles + resolveMaterials + contactEvents +
           pre + applyForces + contactRows + constraintRows + particleRows + solve + integrateMotion +
           storeResults + projectPositions + checkFinite + post + compactParticles;
  }
  /// Adds `o` field by field (every stage and `total`), for accumulating timings over steps.
  StepTimings& operator+=(const StepTimings& o) {
    preCollide += o.preCollide;
    syncGeometries += o.syncGeometries;
    collideGeometries += o.collideGeometries;
    collideParticles += o.collideParticles;
    resolveMaterials += o.resolveMaterials;
    contactEvents += o.contactEvents;
    pre += o.pre;
    applyForces += o.applyForces;
    contactRows += o.contactRows;
    constraintRows += o.constraintRows;
    particleRows += o.particleRows;
    solve += o.solve;
    integrateMotion += o.integrateMotion;
    storeResults += o.storeResults;
    projectPositions += o.projectPositions;
    checkFinite += o.checkFinite;
    post += o.post;
    compactParticles += o.compactParticles;
    total += o.total;
    return *this;
  }
};

/// Problems found in the last step.
struct StepReport {
  /// Ids and names of bodies whose state became non-finite (they were restored and stopped).
  std::vector<uint32_t> nonFiniteBodies;
  std::vector<std::string> messages;
  /// Ids of particles whose state became non-finite (they kept their last position and were stopped).
  std::vector<size_t> nonFiniteParticles;
  /// Constraints with a DOF whose position error beyond its elastic stretch (ConstraintRow::drift) exceeded
  /// Solver::getConstraintErrorThreshold() at the start of this step: a joint that came apart (a diverging PGS
  /// chain stays finite while it separates by metres). Each is logged once, as an error, with its error and
  /// solve type; it is listed here every step it stays apart.
  std::vector<const Constraint*> separatedConstraints;
  bool ok() const { return nonFiniteBodies.empty() && nonFiniteParticles.empty() && separatedConstraints.empty(); }
};

class Simulation {
 public:
  Simulation();
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  /// Adds the body and its geometries. Adding twice is a no-op. Null throws.
  void add(RigidBodyRef body);
  bool remove(const RigidBodyRef& body);
  /// A static geometry with no body (a body's geometries come with the body).
  void add(GeometryRef geometry);
  bool remove(const GeometryRef& geometry);
  void add(ConstraintRef constraint);
  bool remove(const ConstraintRef& constraint);
  void add(StepEventListenerRef listener);
  bool remove(const StepEventListenerRef& listener);
  void add(ContactEventListenerRef listener);
  bool remove(const ContactEventListenerRef& listener);
  /// A model (terrain, tire, fields, suction, or a user's Model subclass): recorded, then Model::onAdd installs
  /// its bodies, constraints and listeners; remove() uninstalls them all (scree/solver/model.h). Adding twice is a
  /// no-op; a model in another simulation throws.
  void add(ModelRef model);
  bool remove(const ModelRef& model);
  /// Models are added through the Model path even when they are also constraints or listeners.
  template <class T>
    requires std::derived_from<T, Model>
  void add(std::shared_ptr<T> model) {
    add(ModelRef(std::move(model)));
  }
  template <class T>
    requires std::derived_from<T, Model>
  bool remove(const std::shared_ptr<T>& model) {
    return remove(ModelRef(model));
  }
  const std::vector<ModelRef>& getModels() const;

  const std::vector<RigidBodyRef>& getRigidBodies() const;
  const std::vector<ConstraintRef>& getConstraints() const;
  /// Geometries added without a body.
  const std::vector<GeometryRef>& getStaticGeometries() const;
  const std::vector<StepEventListenerRef>& getStepEventListeners() const;
  const std::vector<ContactEventListenerRef>& getContactEventListeners() const;

  /// s, finite and > 0. Default 1/60.
  void setTimeStep(Real h);
  Real getTimeStep() const;
  /// m/s^2, finite. Default (0, 0, -9.80665).
  void setUniformGravity(const Vec3& g);
  Vec3 getUniformGravity() const;

  void stepForward();
  /// Steps until getTimeStamp() >= time - h/2.
  void stepTo(Real time);
  Real getTimeStamp() const;

  MaterialManager& getMaterialManager();
  Solver& getSolver();
  /// The particles of this simulation (AGX: agx::GranularBodySystem).
  GranularBodySystem& getGranularBodySystem();
  const GranularBodySystem& getGranularBodySystem() const;
  /// Disable/enable collisions between two collision groups (see Geometry::addGroup; particles:
  /// GranularBodySystem::addGroup).
  void setEnableCollisions(uint32_t group1, uint32_t group2, bool enable);
  void setEnableCollisions(const std::string& group1, const std::string& group2, bool enable);

  /// Contacts of the last step, with the forces the solver applied (sensor contacts included, no force).
  const std::vector<GeometryContact>& getContacts() const;
  /// Particle contacts of the last step with their forces (dense particle indices of that step, see
  /// ParticleContact): particle-particle, and particle-geometry (sensor contacts included, flagged). The
  /// indices stay valid through the step's listeners, POST_STEP included (destroys are deferred until after
  /// it); after the step they name that step's arrays, which a destroy may since have compacted.
  const std::vector<ParticleContact>& getParticleParticleContacts() const;
  const std::vector<ParticleContact>& getParticleGeometryContacts() const;
  const StepStats& getStepStats() const;
  /// The last step's stage times in milliseconds (StepTimings); all zero before the first step.
  StepTimings getTimings() const;
  const StepReport& getLastStepReport() const;

 private:
  // Everything the stages share (solver/src/simulation_state.h); the stages are free functions in
  // scree::detail (solver/src/step_stages.h).
  std::unique_ptr<detail::SimulationState> s_;
};

}  // namespace scree
