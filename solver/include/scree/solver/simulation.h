// Simulation (AGX: agxSDK::Simulation): owns the bodies, geometries, constraints and listeners, and runs
// the step. stepForward() is a fixed pipeline of named stages (DESIGN.md §2):
//   1 preCollide listeners   2-3 collision (Space: broadphase + narrowphase)   4 contact listeners
//   5 pre listeners          6 rows (contacts, constraints)                     7 solve (PGS)
//   8 integrate              9 post listeners
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

/// Wall-clock time of each stage of the last step, seconds, and counts.
struct StepStats {
  double preCollide = 0, collide = 0, contactEvents = 0, pre = 0, rows = 0, solve = 0, integrate = 0, post = 0;
  double total = 0;
  size_t numBroadphasePairs = 0;
  size_t numContacts = 0;
  size_t numContactPoints = 0;
  size_t numParticleContacts = 0;  ///< particle-particle plus solved particle-geometry contact points
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
  const std::vector<ModelRef>& getModels() const { return models_; }

  const std::vector<RigidBodyRef>& getRigidBodies() const { return bodies_; }
  const std::vector<ConstraintRef>& getConstraints() const { return constraints_; }
  /// Geometries added without a body.
  const std::vector<GeometryRef>& getStaticGeometries() const { return staticGeoms_; }
  const std::vector<StepEventListenerRef>& getStepEventListeners() const { return stepListeners_; }
  const std::vector<ContactEventListenerRef>& getContactEventListeners() const { return contactListeners_; }

  /// s, finite and > 0. Default 1/60.
  void setTimeStep(Real h);
  Real getTimeStep() const { return h_; }
  /// m/s^2, finite. Default (0, 0, -9.80665).
  void setUniformGravity(const Vec3& g);
  Vec3 getUniformGravity() const { return gravity_; }

  void stepForward();
  /// Steps until getTimeStamp() >= time - h/2.
  void stepTo(Real time);
  Real getTimeStamp() const { return time_; }

  MaterialManager& getMaterialManager() { return materials_; }
  Solver& getSolver() { return solver_; }
  /// The particles of this simulation (AGX: agx::GranularBodySystem).
  GranularBodySystem& getGranularBodySystem() { return granular_; }
  const GranularBodySystem& getGranularBodySystem() const { return granular_; }
  Space& getSpace() { return space_; }
  /// Disable/enable collisions between two collision groups (see Geometry::addGroup).
  void setEnableCollisions(uint32_t group1, uint32_t group2, bool enable) { space_.setEnablePair(group1, group2, enable); }
  void setEnableCollisions(const std::string& group1, const std::string& group2, bool enable);

  /// Contacts of the last step, with the forces the solver applied (sensor contacts included, no force).
  const std::vector<GeometryContact>& getContacts() const { return contacts_; }
  /// Particle contacts of the last step with their forces (dense particle indices of that step, see
  /// ParticleContact): particle-particle, and particle-geometry (sensor contacts included, flagged).
  const std::vector<ParticleContact>& getParticleParticleContacts() const;
  const std::vector<ParticleContact>& getParticleGeometryContacts() const;
  const StepStats& getStepStats() const { return stats_; }
  const StepReport& getLastStepReport() const { return report_; }

 private:
  struct Impl;
  void runPreCollide();
  void runCollide();
  void runContactEvents();
  void runPre();
  void buildRows();
  void solve();
  void solveHybrid(bool finalDirect);
  void addGeometricStiffness();
  void buildShockOrder();
  void integrate();
  void runPost();
  void storeContactResults();
  void checkFinite();
  void projectPositions();
  void reportSeparated(const Constraint& c, Real drift);
  bool computeGeometricStiffness();
  int solverIndex(const RigidBody* b) const;

  Real h_ = 1.0 / 60.0;
  Vec3 gravity_{0, 0, -9.80665};
  Real time_ = 0;
  std::vector<RigidBodyRef> bodies_;
  std::vector<GeometryRef> staticGeoms_;
  std::vector<ConstraintRef> constraints_;
  std::vector<StepEventListenerRef> stepListeners_;
  std::vector<ContactEventListenerRef> contactListeners_;
  std::vector<ModelRef> models_;
  MaterialManager materials_;
  Solver solver_;
  Space space_;
  GranularBodySystem granular_;
  std::vector<GeometryContact> contacts_;
  StepStats stats_;
  StepReport report_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace scree
