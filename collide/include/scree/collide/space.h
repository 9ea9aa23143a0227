// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Space (AGX: agxCollide::Space): the set of geometries, pair filtering, the broadphase and the narrowphase.
//
// A pair is tested when both geometries have collisions enabled, they are not on the same body, at least one
// is on a DYNAMICS body (or one is a sensor and the other moves), no disabled group pair, geometry pair or body
// pair applies. Output: one GeometryContact per touching pair, ordered by (lower geometry id, higher id);
// geometry 0 is the one with the lower id.
#pragma once

#include <cstdint>
#include <set>
#include <utility>
#include <vector>

#include "scree/collide/geometry.h"
#include "scree/collide/uniform_grid.h"
#include "scree/core/contact.h"

namespace scree {

class Space {
 public:
  void add(GeometryRef g);
  bool remove(const GeometryRef& g);
  bool contains(const Geometry* g) const;
  const std::vector<GeometryRef>& getGeometries() const { return geoms_; }

  /// Group pair switch (symmetric; a group with itself is allowed).
  void setEnablePair(uint32_t group1, uint32_t group2, bool enable);
  bool getEnablePair(uint32_t group1, uint32_t group2) const;
  /// Geometry pair and body pair switches (a joint disables its two bodies by default).
  void setEnableCollisions(const Geometry* a, const Geometry* b, bool enable);
  void setEnableCollisions(const RigidBody* a, const RigidBody* b, bool enable);
  bool canCollide(const Geometry& a, const Geometry& b) const;

  /// Distance added to every pair's speculative margin, m (default 1e-3): keeps resting contacts alive
  /// across tiny separations so warm starting holds.
  void setContactMargin(Real m);
  Real getContactMargin() const { return margin_; }

  const detail::UniformGrid& getBroadphase() const { return grid_; }

  /// Updates world transforms, computes AABBs grown by each body's motion over `h` (speculative contacts),
  /// runs broad- and narrowphase and replaces the contents of `out` with the touching pairs (its elements and
  /// their point buffers are reused from the last call).
  void collide(Real h, std::vector<GeometryContact>& out);

  // ---- issue 18 (parallel narrowphase) ----
  /// Narrowphase of the candidate pairs shared among the threads (setNumThreads) in fixed chunks merged in order,
  /// so the contacts are the same on any thread count (default off; the Simulation switches it on with
  /// Solver::setUsePartitionedSweeps). Off by default because on a machine with more runnable threads than cores
  /// the wait for the second thread cost more than the work (docs/solver-internals.md "Partitioned sweeps").
  void setUseParallelNarrowphase(bool on) { parallelNarrowphase_ = on; }
  bool getUseParallelNarrowphase() const { return parallelNarrowphase_; }

  /// Number of candidate pairs from the broadphase in the last collide().
  size_t getNumBroadphasePairs() const { return numPairs_; }

  // ---- issue 18 (persistent box-box manifolds; docs/solver-internals.md "Persistent box-box manifolds") ----
  /// Reuse a box-box pair's manifold while the pair's relative pose stays within a small tolerance of the pose
  /// it was clipped at (default on). The points are kept in the boxes' own frames and their depths recomputed
  /// from the current poses every step; see space.cpp for the tolerance and the error it allows.
  void setUsePersistentManifolds(bool on) { persistentManifolds_ = on; }
  bool getUsePersistentManifolds() const { return persistentManifolds_; }
  /// Box-box pairs whose manifold was reused (not clipped again) in the last collide().
  size_t getNumReusedManifolds() const { return numReused_; }

  // ---- issue 18 (broadphase reuse; docs/solver-internals.md "Broadphase reuse") ----
  /// The broadphase keeps its candidate pairs from step to step while every geometry's AABB stays inside a copy
  /// enlarged by this ratio of its largest extent on every side (default 0.05; 0 turns reuse off). The pairs and
  /// their order are the same either way; a resting scene skips the binning and sorting, and a scene whose
  /// bodies move bins afresh whenever one leaves its enlarged box (UniformGrid::setReuseRatio). Throws
  /// std::invalid_argument unless ratio is finite and >= 0.
  void setBroadphaseReuseRatio(Real ratio) { grid_.setReuseRatio(ratio); }
  Real getBroadphaseReuseRatio() const { return grid_.getReuseRatio(); }
  static constexpr Real kDefaultBroadphaseReuseRatio = 0.05;

 private:
  static uint64_t pairKey(uint32_t a, uint32_t b) {
    return a < b ? (uint64_t(a) << 32) | b : (uint64_t(b) << 32) | a;
  }
  std::vector<GeometryRef> geoms_;
  std::set<uint64_t> disabledGroups_, disabledGeoms_, disabledBodies_;
  detail::UniformGrid grid_{kDefaultBroadphaseReuseRatio};
  Real margin_ = 1e-3;
  size_t numPairs_ = 0;
  // scratch
  std::vector<Aabb> boxes_;
  std::vector<Real> margins_;
  std::vector<std::pair<uint32_t, uint32_t>> pairs_;
  // ---- issue 18 (parallel narrowphase): the candidate pairs in fixed chunks, each chunk's contacts kept apart
  // and merged in chunk order (space.cpp) ----
  struct Hit {
    Geometry *a, *b;
    uint32_t begin, count;  // points in the chunk's buffer
  };
  struct Chunk {
    std::vector<ContactPoint> points, scratch;
    std::vector<Hit> hits;
  };
  std::vector<Chunk> chunks_;
  bool parallelNarrowphase_ = false;
  // ---- issue 18 (fixed cost of small scenes): the serial narrowphase's one scratch buffer, whose storage is
  // swapped into each touching pair's contact (space.cpp) ----
  std::vector<ContactPoint> serialScratch_;
  // ---- issue 18 (persistent box-box manifolds, space.cpp): one record per candidate pair of this step (count 0:
  // none), the last step's records and their (pair key, slot) index sorted by key ----
  struct CachedManifold {
    const Shape* s0 = nullptr;
    const Shape* s1 = nullptr;
    Vec3 h0, h1;     // half extents when clipped
    Transform rel;   // geometry 1 in geometry 0's frame when clipped
    Vec3 n0;         // normal (from 1 towards 0) in geometry 0's frame
    Vec3 p0[4], p1[4];  // each point on geometry 0's / 1's surface, in that geometry's frame
    uint32_t fid[4];
    uint64_t key = 0;   // (geometry 0 id << 32) | geometry 1 id
    uint32_t count = 0;
    bool reused = false;  // this step's points came from the last step's record
  };
  std::vector<CachedManifold> manifolds_, lastManifolds_;
  std::vector<std::pair<uint64_t, uint32_t>> manifoldKeys_;
  bool reuseManifold(const Geometry& g0, const Geometry& g1, Real margin, CachedManifold& rec,
                     std::vector<ContactPoint>& points) const;
  void recordManifold(const Geometry& g0, const Geometry& g1, const std::vector<ContactPoint>& points,
                      CachedManifold& rec) const;
  bool persistentManifolds_ = true;
  size_t numReused_ = 0;
};

}  // namespace scree
