// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// ParticleCollider: contacts of GranularBodySystem particles with each other and with geometries.
//
// Broadphase: a hashed uniform grid over the particles, cell size = largest particle diameter + the slow
// particles' pair margin (below), so every touching or speculative pair of slow particles lies in the same or an
// adjacent cell (27-cell stencil, visited as a half stencil: the own cell and the 13 cells after it, so each
// pair of cells is met from one side). The
// cells are built by a counting sort in dense order (deterministic); candidate pairs are found in parallel over
// fixed chunks of particles, each chunk writing its own buffer, and the buffers are concatenated in chunk order,
// so the contact list is the same for any number of threads. A stencil cell whose nearest point is at least one
// cell away from the particle is skipped (no pair can reach it), and each bucket is scanned in a contiguous copy
// of its particles' cells and centres.
// Dense grid: while the live particles' cells span a box of at most 8 cells per particle, the buckets are
// that box's cells (padded by one, in z, y, x order) instead of hash buckets: no collisions and no cell test
// per candidate, and the 14 cells of the half stencil become 5 contiguous runs of the copy (the own cell from
// the particle's own entry on, plus x+1; the rows y+1 of its layer and y-1..y+1 of the layer above, x-1..x+1).
// A particle flung far away falls back to the hashed grid. Both find the same pairs, which are then sorted,
// so the contact list is identical either way.
//
// Two-speed grid (issue 16, docs/terrain.md "Digging cost"): the pair margin depends on the relative speed, so a
// grid sized for the fastest particle (cell 2 maxR + reach, up to two diameters) makes every particle scan a
// cube of 27 such cells for its few neighbours. Instead, with u the median of the particles' velocities (in the
// trench: the bucket's soil), each particle gets a speed bound w_i = h |v_i - u| (1 + 1e-9), and
// h |v_i - v_j| <= w_i + w_j (triangle inequality; the 1e-9 exceeds the rounding). Slow particles
// (w_i <= 0.25 maxR) share a cell of 2 maxR + min(0.5 maxR + margin, reach) and find each other through the
// half stencil; a fast particle searches every cell within r_i + maxR + min(2 w_i + margin, reach) and takes
// slow partners and fast partners of lower bound (equal: higher index), so each pair is found exactly once.
// The cut 0.25 maxR cost the fewest instructions in the trench (0.1 and 0.5 test fewer or more candidates but
// cost 1-4 % more; the old grid, a cut at the reach, tested 2.2 times the candidates).
// The found pairs are sorted as before, so the contact list is the same, pair for pair and bit for bit.
// localityOrder and getCellSize keep the old cell (2 maxR + reach), so the reorder and the particle solver's
// slabs are unchanged.
//
// Particle pairs: analytic sphere-sphere. A pair is a (speculative) contact when its gap is below
//   margin_ab = h |v_a - v_b| + contactMargin,
// capped at one largest diameter (the grid's reach): particles closing faster than that relative to each other
// may miss one step of speculative contact (particle-geometry contacts have no such cap).
//
// Particles vs geometries: every collision-enabled geometry in the list (all shapes, height fields, sensors)
// is tested with the geometry narrowphase (collideGeometries) using a per-thread sphere geometry; the margin is
// h |v_particle - v_body| + contactMargin, so fast particles get speculative contacts against thin walls. A
// geometry's candidates come from the grid cells its bounding box covers (or all particles when that is fewer).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "scree/collide/geometry.h"
#include "scree/core/granular_body_system.h"
#include "scree/core/particle_contact.h"

namespace scree::detail {

class ParticleCollider {
 public:
  ParticleCollider();
  ~ParticleCollider();

  /// Distance added to every pair's speculative margin, m (default 1e-3, as Space).
  void setContactMargin(Real m) { margin_ = m; }
  Real getContactMargin() const { return margin_; }

  /// Finds the contacts of all live particles of `ps` (dense entries flagged dead are skipped) with each other
  /// and with `geometries` (world transforms current). h is the time step (speculative margins).
  void collide(const GranularBodySystem& ps, const std::vector<GeometryRef>& geometries, Real h);

  /// Particle-particle contacts (b >= 0), ordered by a, then b.
  const std::vector<ParticleContact>& getParticleParticleContacts() const { return pp_; }
  std::vector<ParticleContact>& getParticleParticleContacts() { return pp_; }
  /// Particle-geometry contacts (b = -1), sensors included (sensor = true), ordered by geometry then a.
  const std::vector<ParticleContact>& getParticleGeometryContacts() const { return pg_; }
  std::vector<ParticleContact>& getParticleGeometryContacts() { return pg_; }

  /// Grid cell size of the last collide(), m: no particle pair in contact is farther apart than this
  /// (2 maxR + the reach; the two-speed grid's own cell may be smaller).
  Real getCellSize() const;
  /// Particles the last collide() searched as fast (see "Two-speed grid"; 0 when every particle was slow).
  size_t getNumFastParticles() const;

  /// A permutation (for GranularBodySystem::reorder) that sorts particles along the grid (cells in z, y, x
  /// order), so neighbours in space are near in memory. Uses the grid of the last collide().
  std::vector<uint32_t> localityOrder(const GranularBodySystem& ps) const;

  // ---- Candidate filter (issue 16, docs/terrain.md "Digging cost", eighth round) ----------------------------
  // On the dense grid, each run of candidate entries first goes through a four-wide AVX2 version of the cheap
  // reject (structure-of-arrays copy of the entries' centres, radii and speed bounds; the same operations in
  // the same order, with a 1e-12 relative slack towards keeping), and only the kept candidates get the scalar
  // test, which alone decides: the contact list is the same, bit for bit, with the filter on or off. Chosen at
  // run time (__builtin_cpu_supports("avx2")); without AVX2 every candidate gets the scalar test.
  /// True when the CPU has AVX2 (and the build targets x86-64 with GCC or Clang).
  static bool pairFilterAvailable();
  /// Test and measurement switch (process-wide; default true). Off: every candidate gets the scalar test.
  static void setPairFilterEnabled(bool on);
  /// Enabled and available.
  static bool pairFilterActive();
  /// The last collide() ran the filter (a test's evidence).
  bool usedPairFilter() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Real margin_ = 1e-3;
  std::vector<ParticleContact> pp_, pg_;
};

}  // namespace scree::detail
