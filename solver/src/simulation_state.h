// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The state of a Simulation shared by the stages of its step (solver-private). Simulation (simulation.cpp)
// owns one and keeps membership in it; each stage (step_stages.h) reads and writes only the parts named for
// it below. Grouped by stage so that a reader can see which stage owns which buffer; every buffer is reused
// from step to step (cleared, never reallocated once large enough).
#pragma once

#include <chrono>
#include <unordered_set>
#include <utility>
#include <vector>

#include "body_access.h"
#include "contact_rows.h"
#include "coarse_correction.h"  // issue 18 (coarse correction)
#include "friction_anchor.h"  // issue 18 (friction anchors)
#include "granular_stage.h"
#include "sweep_threads.h"
#include "scree/collide/particle_collider.h"
#include "scree/collide/space.h"
#include "scree/solver/direct.h"
#include "scree/solver/pgs.h"
#include "scree/solver/simulation.h"

namespace scree::detail {

struct SimulationState {
  // ---- settings and membership (Simulation's public API) ---------------------------------------------------
  Real h = 1.0 / 60.0;
  Vec3 gravity{0, 0, -9.80665};
  Real time = 0;
  std::vector<RigidBodyRef> bodies;
  std::vector<std::vector<Geometry*>> registered;  // geometries of each body known to the space
  std::vector<GeometryRef> staticGeoms;
  std::vector<ConstraintRef> constraints;
  std::vector<StepEventListenerRef> stepListeners;
  std::vector<ContactEventListenerRef> contactListeners;
  std::vector<ModelRef> models;  ///< Simulation::add(ModelRef) (solver/src/model.cpp)
  MaterialManager materials;
  Solver solver;
  Space space;
  GranularBodySystem granular;

  // ---- outputs of the step ---------------------------------------------------------------------------------
  std::vector<GeometryContact> contacts;  // collide -> events -> rows -> store results
  StepStats stats;
  StepReport report;

  // ---- collide (particles) -------------------------------------------------------------------------------
  ParticleCollider particleCollider;
  uint64_t particleSteps = 0;             // steps with particles, for the periodic locality reorder
  std::vector<ParticleGeometrySide> particleGeometrySides;  // per particle-geometry contact, for the rows
  std::vector<GeometryRef> particleGeometries;  // geometries the particles may touch, when they have groups
  bool granularStep = false;              // the particle system is in this step (its destroys are deferred)

  // ---- contact events --------------------------------------------------------------------------------------
  // Touching pairs of the last step (sorted) with their geometries, for impact/separation events.
  std::vector<std::pair<uint64_t, std::pair<Geometry*, Geometry*>>> prevPairs, curPairs;

  // ---- forces: per body (index = position in bodies) ------------------------------------------------------
  std::vector<SolverBodyState> sb;        // free velocities in, solved velocities out
  std::vector<Vec3> vStart, wStart;       // velocities at the start of the step (contact rows read them)
  std::vector<Vec3> savedX;               // last finite pose (finiteness check restores it)
  std::vector<Quat> savedQ;

  // ---- rows ------------------------------------------------------------------------------------------------
  std::vector<ConstraintRow> rows;        // contact rows first, then constraint rows
  std::vector<PointRows> pointRows;       // contact point -> its rows
  WarmStartCache warmStart;
  std::vector<CouplingRange> couplings;   // row range and bodies of each contact and constraint (shock order)
  struct ConstraintRange {
    Constraint* c;
    uint32_t begin, count;
  };
  std::vector<ConstraintRange> ranges;
  std::vector<int> rowDofs;
  bool nonIterativeRows = false;          // some row's solve type is not ITERATIVE
  bool warnedSolveType = false;
  std::unordered_set<const Constraint*> reportedSeparated;  // separated constraints already logged
  GranularStage particles;

  // ---- solve -----------------------------------------------------------------------------------------------
  DirectSolver direct;
  std::vector<uint32_t> directSet, iterSet;
  bool pureIterative = false;             // some row is only in the iterative set
  std::vector<Real> geomK;                // geometric stiffness per body (geometric_stiffness.cpp)
  // Shock ordering (shock_order.cpp).
  std::vector<int> level;                 // support level per body: 0 static/kinematic, 1 touches those, ...
  std::vector<std::vector<uint32_t>> adjacency;
  std::vector<PgsSolver::ShockRange> shock;
  std::vector<uint32_t> frontier;
  std::vector<std::pair<int, uint32_t>> order;
  // ---- issue 18 (sweep cost): reused buffers of the shock order's counting sort (no per-step allocation) ----
  std::vector<uint32_t> levelStart;
  std::vector<std::pair<int, uint32_t>> orderSorted;
  PgsColouring colouring;  // coloured sweeps (Solver::setUseColouredSweeps), storage reused across steps
  // ---- issue 18 (sweep scheduling): partitioned sweeps (Solver::setUsePartitionedSweeps), storage reused ----
  PgsPartition partition;
  bool partitionReady = false;  // the partition was computed for this step's rows (iterative paths only)
  SweepThreadChoice sweepThreads;  // the partitioned work's thread count by measurement (sweep_threads.h)
  // The span of the step's partitioned work (step_stages.h beginPartitionedWork): its start, and whether it was
  // started (adaptive count). It counts when this step's sweeps were partitioned too (partitionReady).
  std::chrono::steady_clock::time_point partitionSpanStart{};
  bool partitionSpanStarted = false;
  // Some team job of this step's row build or prepare got fewer threads than it asked for (another Simulation
  // held the team); the sweeps' and shock pass's jobs report theirs in partition.teamBusy.
  bool rowBuildTeamBusy = false;
  // Warm-start source (issue 18, solve_stage.cpp rigidShock): per contact row in the rigid shock pass, the
  // sweeps' impulse (plus, for a single support's normal rows, an even share of the load the pass added); NaN for
  // other rows; empty when no shock pass ran. storeResults caches these instead of the solved impulses.
  std::vector<Real> sweepLambda;
  std::vector<int> shockSupports;         // per solver body: shock ranges in which it is the free body
  // Issue 18 (solver sweep): the manifold normal blocks' operators, built by PgsSolver::prepare each step into
  // storage kept across steps (pgs.h PgsBlocks).
  PgsBlocks pgsBlocks;
  // ---- issue 18 (coarse correction, coarse_correction.h): its storage and kept symbolic analysis ----
  CoarseCorrection coarse;
  // ---- issue 18 (friction anchors, friction_anchor.h): manifold anchors kept across steps and this step's
  // anchored manifolds (Solver::setUseFrictionAnchors) ----
  FrictionAnchorCache frictionAnchors;
  // ---- issue 18 (two-thread scaling): the grouped contact row build (contact_rows.cpp): the contacts of each
  // group (the regions', then the boundary's), their layout and per-group anchor lists, kept across steps; the
  // end of each group's rows (rows [rowGroupEnd[g - 1], rowGroupEnd[g]) are group g's) ----
  std::vector<uint32_t> contactGroups[PgsPartition::kRegions + 1];
  std::vector<ContactLayout> contactLayout;
  std::vector<uint64_t> contactLayoutPairs;  // each contact's pair key when contactLayout was made
  bool contactLayoutValid = false;           // contactLayout holds the last grouped build's counts
  std::vector<ContactChunk> contactChunks;  // the groups' contacts in runs (contact_rows.h forChunksFromBothEnds)
  std::vector<std::vector<FrictionAnchorCache::Active>> chunkAnchors;  // per chunk: its anchored manifolds
  std::vector<ChunkTally> chunkTallies;                                 // per chunk: its rows' tallies
  uint32_t rowGroupEnd[PgsPartition::kRegions + 1] = {};
  bool rowGroupsReady = false;  // this step's contact rows are grouped (PgsSolver::prepare runs the regions apart)
  int rowGroupThreads = 1;      // the threads the grouped build asked for, which prepare asks for too
  std::vector<uint32_t> couplingOrder;  // shock_order.cpp: the couplings in contact order (grouped rows)

  // ---- position projection: its own direct solver, so each keeps its cached symbolic analysis ---------------
  DirectSolver projector;
  std::vector<ConstraintRow> projRows;
  std::vector<int> projDofs;
  std::vector<uint32_t> projSet;
  std::vector<SolverBodyState> projBodies;

  /// Index of b in bodies (the solver body index), -1 when b is null or not in this simulation.
  int solverIndex(const RigidBody* b) const {
    if (!b) return -1;
    const int i = BodyAccess::simIndex(const_cast<RigidBody&>(*b));
    return (i >= 0 && size_t(i) < bodies.size() && bodies[size_t(i)].get() == b) ? i : -1;
  }
  /// The solver statistics the stages write (Solver exposes them read-only).
  SolverStats& solverStats();
};

/// Key of a geometry contact's pair (ids of geometry 0 and 1): events and the warm-start cache use it.
inline uint64_t contactPairKey(const GeometryContact& c) {
  return (uint64_t(c.geometry(0)->getId()) << 32) | c.geometry(1)->getId();
}

/// The stages' write access to Solver's statistics.
struct SolverStatsWriter {
  static SolverStats& of(Solver& solver) { return solver.stats_; }
};
inline SolverStats& SimulationState::solverStats() { return SolverStatsWriter::of(solver); }

}  // namespace scree::detail
