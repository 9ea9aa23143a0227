// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// GranularBodySystem (AGX: agx::GranularBodySystem): the particle container.
//
// Storage is structure-of-arrays: one contiguous array per attribute, indexed by a dense index
// 0 .. size()-1. No per-particle objects. The arrays, their shapes and units:
//   positions()        [size()] Vec3, m, world frame (particle centre)
//   velocities()       [size()] Vec3, m/s
//   angularVelocities()[size()] Vec3, rad/s, world frame
//   radii()            [size()] Real, m, > 0
//   masses()           [size()] Real, kg (density of the particle's material x 4/3 pi r^3)
//   invMasses()        [size()] Real, 1/kg
//   materialIndices()  [size()] uint32, index into getMaterialTable()
//   custom real buffers, one [size()] Real array per name
//
// Ids. A user holds a size_t id: low 32 bits = slot + 1, high 32 bits = the slot's generation. Zero is never a
// valid id (null). Destroying a particle frees its slot and bumps the slot's generation, so an old id of a
// reused slot is rejected (isValid() false; getters throw std::invalid_argument). Dense storage stays packed:
// removal moves the last particle into the gap and fixes its slot back-pointer, and reorder() permutes the
// arrays (for cache locality along the grid) without changing any id.
//
// Destroying while iterating or while the simulation step is running is safe: between beginDeferral() and
// endDeferral() (forEachParticle() and Simulation::stepForward() use them) a destroyed particle is removed from
// the id table at once (numParticles() drops, the id becomes invalid) but its dense entry stays, flagged dead
// with zero inverse mass, until the outermost endDeferral() compacts the arrays. Dense-index loops therefore
// check isAliveDense(i) when deferral may be active.
//
// Bad input (non-finite position/velocity, radius <= 0, null material, unknown id or buffer name) throws
// std::invalid_argument naming the parameter and the value, and leaves the system unchanged.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "scree/core/material.h"
#include "scree/core/math.h"

namespace scree {

class GranularBodySystem {
 public:
  GranularBodySystem();

  // ---- creation and destruction ------------------------------------------------------------------------------
  /// Creates a particle with the current material (setMaterial) and returns its id (never 0).
  /// position m (finite), radius m (finite, > 0), velocity m/s (finite).
  size_t createParticle(const Vec3& position, Real radius, const Vec3& velocity = Vec3::Zero());
  /// Destroys a live particle. An invalid id throws std::invalid_argument.
  void destroyParticle(size_t id);
  /// Destroys every particle (ids of all of them become invalid).
  void clear();
  /// Number of live particles.
  size_t numParticles() const { return numLive_; }
  /// True when id names a live particle.
  bool isValid(size_t id) const;

  // ---- per-particle access by id (throw std::invalid_argument for an invalid id) ----------------------------
  Vec3 getPosition(size_t id) const;
  Vec3 getVelocity(size_t id) const;
  Vec3 getAngularVelocity(size_t id) const;
  Real getRadius(size_t id) const;
  /// kg.
  Real getMass(size_t id) const;
  MaterialRef getParticleMaterial(size_t id) const;
  void setPosition(size_t id, const Vec3& position);
  void setVelocity(size_t id, const Vec3& velocity);
  void setAngularVelocity(size_t id, const Vec3& angularVelocity);
  /// Changes the radius; the mass follows the material density.
  void setRadius(size_t id, Real radius);
  /// Changes one particle's material; the mass follows the new density.
  void setParticleMaterial(size_t id, MaterialRef material);

  /// Material of particles created from now on (its density gives their mass). Null throws. The default is a
  /// Material named "granular" with the material defaults (density 1000 kg/m^3).
  void setMaterial(MaterialRef material);
  const MaterialRef& getMaterial() const { return currentMaterial_; }

  /// Sum of the masses of live particles, kg.
  Real getTotalMass() const;

  // ---- named custom real buffers ----------------------------------------------------------------------------
  /// Adds a buffer with one Real per particle, initialised to 0 (also for particles created later). Adding an
  /// existing name is a no-op. An empty name throws.
  void addCustomBufferReal(const std::string& name);
  bool hasCustomBufferReal(const std::string& name) const;
  void removeCustomBufferReal(const std::string& name);
  void setCustomReal(const std::string& name, size_t id, Real v);
  Real getCustomReal(const std::string& name, size_t id) const;
  /// Names of the custom real buffers, in the order they were added.
  std::vector<std::string> getCustomBufferRealNames() const;
  /// Dense array [size()] of a buffer (nullptr when there is no such buffer). Valid until the next create,
  /// destroy, reorder or buffer change.
  const Real* customBufferReal(const std::string& name) const;
  Real* customBufferReal(const std::string& name);

  // ---- iteration ---------------------------------------------------------------------------------------------
  /// Calls f(id) for every live particle, in dense order. f may create or destroy particles: destroys are
  /// deferred (see the file comment); particles created during the loop are not visited.
  template <class F>
  void forEachParticle(F&& f) {
    beginDeferral();
    const size_t n = size();
    for (size_t i = 0; i < n; ++i)
      if (alive_[i]) f(idOfDense(i));
    endDeferral();
  }
  /// Read-only iteration: f(id) for every live particle, in dense order.
  template <class F>
  void forEachParticle(F&& f) const {
    for (size_t i = 0; i < size(); ++i)
      if (alive_[i]) f(idOfDense(i));
  }
  /// Ids of the live particles, in dense order.
  std::vector<size_t> getParticleIds() const;

  // ---- dense structure-of-arrays access (engine and tools) --------------------------------------------------
  /// Number of dense entries (== numParticles() unless destroys are deferred).
  size_t size() const { return positions_.size(); }
  bool isAliveDense(size_t i) const { return alive_[i] != 0; }
  size_t idOfDense(size_t i) const;
  // ---- (issue 16 performance) the low 32 bits of idOfDense(i), without reading the slot's generation: the
  // particle solver's warm-start keys (solver/src/granular_stage.cpp) -------------------------------------------
  uint32_t idLowOfDense(size_t i) const { return denseToSlot_[i] + 1; }
  /// Dense index of a live id; throws for an invalid id.
  size_t denseIndex(size_t id) const;
  std::vector<Vec3>& positions() { return positions_; }
  const std::vector<Vec3>& positions() const { return positions_; }
  std::vector<Vec3>& velocities() { return velocities_; }
  const std::vector<Vec3>& velocities() const { return velocities_; }
  std::vector<Vec3>& angularVelocities() { return angularVelocities_; }
  const std::vector<Vec3>& angularVelocities() const { return angularVelocities_; }
  const std::vector<Real>& radii() const { return radii_; }
  const std::vector<Real>& masses() const { return masses_; }
  const std::vector<Real>& invMasses() const { return invMasses_; }
  const std::vector<uint32_t>& materialIndices() const { return materialIndices_; }
  /// Materials referenced by materialIndices() (entries are never removed while the system lives).
  const std::vector<MaterialRef>& getMaterialTable() const { return materialTable_; }
  /// Largest radius among dense entries, m (0 when empty).
  Real getMaxRadius() const;

  /// Permutes the dense arrays: entry newOrder[k] moves to position k. newOrder must be a permutation of
  /// 0..size()-1 (throws otherwise). Ids are unchanged. Not allowed while deferral is active (throws
  /// std::logic_error).
  void reorder(const std::vector<uint32_t>& newOrder);

  /// Deferral of compaction (nestable): see the file comment.
  void beginDeferral() { ++deferDepth_; }
  void endDeferral();
  bool isDeferring() const { return deferDepth_ > 0; }

  /// Bumped by every create, destroy, reorder, radius or material change (lets engine caches detect change).
  uint64_t getRevision() const { return revision_; }

  // ---- collision groups (AGX: agx::GranularBodySystem's groups, for the whole system) -----------------------
  /// The particles' collision groups: a particle-geometry pair is not collided when any (particle group,
  /// geometry group) pair is disabled in the simulation (Simulation::setEnableCollisions). Names share the
  /// ids of Geometry::addGroup(const std::string&). Adding a group twice is a no-op; an empty name throws.
  void addGroup(uint32_t id);
  void addGroup(const std::string& name);
  /// False when the group was not there.
  bool removeGroup(uint32_t id);
  bool removeGroup(const std::string& name);
  bool hasGroup(uint32_t id) const;
  bool hasGroup(const std::string& name) const;
  const std::vector<uint32_t>& getGroups() const { return groups_; }

 private:
  struct Slot {
    uint32_t dense = 0;       // dense index while live
    uint32_t generation = 1;  // bumped when freed
    bool live = false;
  };
  static size_t makeId(uint32_t slot, uint32_t generation) {
    return (size_t(generation) << 32) | size_t(slot + 1);
  }
  /// Slot of a live id, or UINT32_MAX.
  uint32_t slotOf(size_t id) const;
  size_t checkedDense(const char* where, size_t id) const;
  uint32_t materialIndexOf(const MaterialRef& m);
  static Real sphereMass(Real density, Real radius);
  void removeDense(size_t i);
  void compact();

  std::vector<Vec3> positions_, velocities_, angularVelocities_;
  std::vector<Real> radii_, masses_, invMasses_;
  std::vector<uint32_t> materialIndices_;
  std::vector<uint32_t> denseToSlot_;
  std::vector<uint8_t> alive_;
  std::vector<std::pair<std::string, std::vector<Real>>> customReal_;

  std::vector<Slot> slots_;
  std::vector<uint32_t> freeSlots_;
  std::vector<MaterialRef> materialTable_;
  MaterialRef currentMaterial_;
  size_t numLive_ = 0;
  size_t numDeadDense_ = 0;
  int deferDepth_ = 0;
  uint64_t revision_ = 0;
  std::vector<uint32_t> groups_;
};

}  // namespace scree
