// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Listener interfaces (AGX: agxSDK::StepEventListener, agxSDK::ContactEventListener).
#pragma once

#include <memory>

#include <vector>

#include "scree/core/contact.h"
#include "scree/core/particle_contact.h"

namespace scree {

class Simulation;
class Geometry;
using TimeStamp = Real;

/// Called around each step. preCollide: before collision detection (e.g. terrain creates particles);
/// pre: after contacts are known, before the solve (forces, vacuum); post: after integration.
class StepEventListener {
 public:
  enum ActivationMask { PRE_COLLIDE = 1, PRE_STEP = 2, POST_STEP = 4, ALL = 7 };
  explicit StepEventListener(int mask = ALL) : mask_(mask) {}
  virtual ~StepEventListener() = default;
  virtual void preCollide(const TimeStamp&) {}
  virtual void pre(const TimeStamp&) {}
  virtual void post(const TimeStamp&) {}
  int getMask() const { return mask_; }
  void setMask(int m) { mask_ = m; }
  Simulation* getSimulation() const { return sim_; }
  void setSimulation(Simulation* s) { sim_ = s; }  ///< set by Simulation::add/remove

 private:
  int mask_;
  Simulation* sim_ = nullptr;
};
using StepEventListenerRef = std::shared_ptr<StepEventListener>;

/// Decides which geometry pairs a ContactEventListener hears about.
class ExecuteFilter {
 public:
  virtual ~ExecuteFilter() = default;
  virtual bool match(const Geometry* g0, const Geometry* g1) const = 0;
};
using ExecuteFilterRef = std::shared_ptr<ExecuteFilter>;

/// Contact callbacks. impact: first step a pair touches; contact: later steps; separation: the step after
/// the last. impact and contact may modify the contact (disable points, change normal, depth, per-point
/// Young's modulus, damping, friction, restitution, surface velocity, or material()) before the solver reads
/// it. Returning REMOVE_CONTACT removes the whole contact for this step.
///
/// particleContacts (mask bit PARTICLE_CONTACT, not in ALL): once per step, after collision and before the
/// rows, with this step's particle contacts (ParticleContact: dense particle indices of this step). The
/// listener may set the per-point overrides (enabled, youngsModulus, frictionCoefficient, damping,
/// restitution, surfaceVelocity); it must not add, remove or reorder entries. The execute filter does not
/// apply (particle contacts have no geometry pair on the particle side). Particles may be created and
/// destroyed from it (destroys are deferred to the end of the step).
class ContactEventListener {
 public:
  /// ALL keeps its meaning: the three geometry-contact events. ALL_WITH_PARTICLES adds particle contacts.
  enum ActivationMask {
    IMPACT = 1,
    CONTACT = 2,
    SEPARATION = 4,
    ALL = 7,
    PARTICLE_CONTACT = 8,
    ALL_WITH_PARTICLES = 15
  };
  enum KeepContactPolicy { KEEP_CONTACT = 0, REMOVE_CONTACT = 1 };

  explicit ContactEventListener(int mask = ALL) : mask_(mask) {}
  virtual ~ContactEventListener() = default;

  virtual KeepContactPolicy impact(const TimeStamp&, GeometryContact&) { return KEEP_CONTACT; }
  virtual KeepContactPolicy contact(const TimeStamp&, GeometryContact&) { return KEEP_CONTACT; }
  virtual void separation(const TimeStamp&, Geometry* /*g0*/, Geometry* /*g1*/) {}
  /// Particle-particle (b >= 0) and particle-geometry (b < 0, sensors included) contacts of this step.
  virtual void particleContacts(const TimeStamp&, std::vector<ParticleContact>& /*particleParticle*/,
                                std::vector<ParticleContact>& /*particleGeometry*/) {}

  int getMask() const { return mask_; }
  void setMask(int m) { mask_ = m; }
  /// nullptr (default): every pair.
  void setFilter(ExecuteFilterRef f) { filter_ = std::move(f); }
  const ExecuteFilterRef& getFilter() const { return filter_; }
  bool matches(const Geometry* g0, const Geometry* g1) const { return !filter_ || filter_->match(g0, g1); }
  Simulation* getSimulation() const { return sim_; }
  void setSimulation(Simulation* s) { sim_ = s; }

 private:
  int mask_;
  ExecuteFilterRef filter_;
  Simulation* sim_ = nullptr;
};
using ContactEventListenerRef = std::shared_ptr<ContactEventListener>;

}  // namespace scree
