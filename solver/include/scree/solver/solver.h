// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Solver settings and per-step statistics (AGX: agx::Solver / agx::DynamicsSystem's solver knobs).
#pragma once

#include <cstddef>

#include "scree/core/math.h"

namespace scree {

namespace detail {
struct SolverStatsWriter;
}

struct SolverStats {
  size_t numBodies = 0;      ///< dynamic bodies in the solve
  size_t numContacts = 0;    ///< geometry contacts solved
  size_t numContactPoints = 0;
  size_t numRows = 0;        ///< constraint rows (normals + friction + joints)
  size_t numIterations = 0;
  size_t numWarmStarted = 0; ///< contact points matched to last step's impulses
  Real lastResidual = 0;     ///< max |delta lambda| of the last PGS sweep, N s
  // DIRECT solver (direct.h), zero when no row is in the direct set.
  size_t numDirectRows = 0;     ///< rows solved by the direct solver
  size_t numIterativeRows = 0;  ///< rows swept by PGS
  size_t numFactorisations = 0; ///< numeric factorisations this step (one per block-pivoting iteration)
  size_t numPivots = 0;         ///< active-set changes (block pivoting) this step
  size_t numSymbolicAnalyses = 0;  ///< symbolic analyses this step (0 while the sparsity pattern is unchanged)
  int directForm = 0;           ///< Solver::DirectForm used by the last direct solve (SCHUR or KKT)
  bool directFallback = false;  ///< the pivot cap was hit and the direct set was finished by PGS (logged)
  /// Complementarity residual of the direct set after the step: max over rows of
  /// |lambda - clamp(lambda - w / A_ii, lo, hi)| with w = J v+ + e lambda - rhs, N s (0: the mixed LCP holds).
  Real complementarityResidual = 0;
  double factorisationTime = 0; ///< s, wall time in numeric factorisations this step
  // Post-step position projection (Solver::setUsePositionProjection), zero when nothing was projected.
  size_t numProjectionIterations = 0;  ///< Newton iterations (one factorisation each) this step
  Real projectionDrift = 0;     ///< largest |drift| of a projected row before the projection, m or rad
  Real projectionResidual = 0;  ///< largest drift beyond the tolerance after it (0 when no iteration ran)
  /// Threads the partitioned sweeps and shock pass ran on this step (Solver::setUsePartitionedSweeps,
  /// setUseAdaptiveSweepThreads); 1 on every other path, 1 when the work was too small to split (fewer than 64
  /// units in the sweeps and 16 supports in the shock pass: tower10, for example), and 1 when they found the
  /// thread team busy (another Simulation stepping on another thread at the same moment; the results are the same
  /// bits).
  int numSweepThreads = 1;
  /// Threads the contact rows were built on this step: with partitioned sweeps and at least 128 contacts the
  /// sweeps' count, else 1; 1 too when the build found the team busy. The rows are the same bits on any count.
  int numRowBuildThreads = 1;
  /// Coarse correction (Solver::setUseCoarseCorrection): the largest number of coarse unknowns of this step's
  /// corrections, the re-factorisations for groups held at their bounds, and the corrections that needed a fresh
  /// symbolic analysis of the coarse operator (0 while its sparsity pattern holds); all 0 when off.
  size_t numCoarseUnknowns = 0;
  size_t numCoarseRefinements = 0;
  size_t numCoarseAnalyses = 0;
};

class Solver {
 public:
  /// Matrix form of the DIRECT solve (docs/design.md §4). SCHUR: A = G M^-1 G^T + E, CHOLMOD LL^T. KKT: the
  /// quasi-definite [M -G^T; -G -E], CHOLMOD LDL^T without pivoting. AUTO: KKT when the Schur matrix would have
  /// more nonzeros than DirectSolver::kktRatio (1) times the KKT matrix (bodies carrying many rows), else SCHUR (see
  /// docs/speed-accuracy.md for the measurements behind it).
  enum DirectForm { AUTO = 0, SCHUR = 1, KKT = 2 };

  /// PGS sweeps per step, >= 1. Default 16.
  void setNumIterations(int n);
  int getNumIterations() const { return iterations_; }
  /// Reuse last step's impulses of matched contact points (default on).
  void setUseWarmStarting(bool on) { warm_ = on; }
  bool getUseWarmStarting() const { return warm_; }
  /// Approach speed above which a contact gets the restitution (impact) treatment, m/s, >= 0. Default 0.2.
  void setRestitutionThreshold(Real v);
  Real getRestitutionThreshold() const { return restitutionThreshold_; }
  /// Largest speed a penetrating contact may push out at, m/s (0: unlimited). Default 0: SPOOK's damping
  /// already limits the push-out.
  void setMaxPenetrationRecoverySpeed(Real v);
  Real getMaxPenetrationRecoverySpeed() const { return maxRecovery_; }
  /// Shock propagation after the PGS sweeps (default on, see PgsSolver::shockPass): contacts between bodies of
  /// different support levels are solved once more from the static ground upwards with the supporting
  /// (lower) body held immovable, so stacks and heavy-on-light supports hold at low iteration counts. It gives
  /// up exact momentum exchange between the two bodies in that pass (the support does not feel the reaction);
  /// switch it off for the plain PGS result. Next step's warm start of those contacts is the sweeps' impulses
  /// (plus, on a body's single support, the load the pass added, spread evenly), not the pass's: its reaction
  /// would reach the lower body a step late and pump stacks (docs/solver-internals.md "Resting stacks").
  void setUseShockPropagation(bool on) { shock_ = on; }
  bool getUseShockPropagation() const { return shock_; }
  // ---- Contact manifolds (issue 18; docs/solver-internals.md "Resting stacks"), both on by default ----
  /// Friction of a contact manifold (2..16 points, one normal, one mu, iterative rows) as one tangent pair at
  /// the manifold's centre bounded by mu * sum(lambda_n) plus a twist row about the normal, instead of two
  /// rows per point (default on). Per-point friction rows solved one after the other push a symmetric manifold
  /// sideways; the centre pair acts on the manifold as a whole. Alone it helps nothing (a box dropped flat
  /// drifts 22 mm instead of 13.6 mm); with the normal block below it keeps an aligned tower's top box exactly
  /// in place.
  void setUseManifoldFriction(bool on) { manifoldFriction_ = on; }
  bool getUseManifoldFriction() const { return manifoldFriction_; }
  /// The normal rows of such a manifold solved as one block on its centre-and-tilt coordinates (default on), so
  /// that a symmetric manifold gets symmetric impulses (Gauss-Seidel over a box's four corners leaves a torque).
  /// With manifold friction: a box dropped flat bounces straight (0 mm of drift, 13.6 mm with both off),
  /// exactly aligned towers keep zero horizontal velocity, and pyramid20 at 10 iterations drifts 0.015 cm (0.41
  /// with both off). Switch both off for the per-point rows of earlier versions.
  void setUseManifoldNormalBlock(bool on) { manifoldBlock_ = on; }
  bool getUseManifoldNormalBlock() const { return manifoldBlock_; }
  /// Largest number of sweeps per support level in the shock pass, >= 1. Default 16.
  void setNumShockIterations(int n);
  int getNumShockIterations() const { return shockIterations_; }
  void setDirectForm(DirectForm f) { form_ = f; }
  DirectForm getDirectForm() const { return form_; }
  /// Cap on block-pivoting iterations per direct solve, >= 1. Default 50. Past it the direct set is finished
  /// by PGS and a warning is logged.
  void setMaxPivots(int n);
  int getMaxPivots() const { return maxPivots_; }
  /// Alternating direct / iterative rounds when both sets exist, >= 1. Default 2.
  void setNumHybridRounds(int n);
  int getNumHybridRounds() const { return hybridRounds_; }
  /// Geometric-stiffness damping of direct-set joint rows (Simulation::addGeometricStiffness, default on): keeps
  /// light links under heavy loads stable at large time steps at the price of damping their fast rotation.
  void setUseGeometricStiffness(bool on) { geometricStiffness_ = on; }
  bool getUseGeometricStiffness() const { return geometricStiffness_; }
  /// Post-step position projection of rigid direct-set joint rows (default on; Simulation::projectPositions):
  /// after the positions are integrated, each holonomic joint row whose SPOOK regularisation is below 1 % of
  /// its mass term (a spring the step cannot resolve, i.e. a rigid joint) and whose drift (ConstraintRow::drift)
  /// exceeds the tolerance is pulled back to the tolerance by the smallest displacement in the mass metric
  /// (with the joints' geometric stiffness), dx = M^-1 G^T mu, G M^-1 G^T mu = -excess, solved by the DIRECT
  /// solver and repeated (Newton) until the excess is below 1e-3 of the tolerance. Velocities are unchanged
  /// (post-stabilisation, Cline & Pai 2003). Rows that are ITERATIVE, bounded or compliant are never moved.
  /// Drift within the tolerance is left to SPOOK's own feedback, which keeps its energy: projecting every step
  /// throws away the constraint's stabilisation state and damps motion by (omega h)^2 per step, so the
  /// projection is a guard against large drift only. SPOOK's lag on a smooth motion, about a_c h tau / 2
  /// (centripetal acceleration a_c, damping time tau), stays below the default tolerance for ordinary joints;
  /// the measurements behind the default are in docs/solver-internals.md.
  void setUsePositionProjection(bool on) { projection_ = on; }
  bool getUsePositionProjection() const { return projection_; }
  /// Newton iterations of the position projection per step, >= 1. Default 3.
  void setNumProjectionIterations(int n);
  int getNumProjectionIterations() const { return projectionIterations_; }
  /// Drift the projection tolerates, m (linear rows) or rad (angular rows), > 0. Default 2e-3.
  void setPositionProjectionTolerance(Real tol);
  Real getPositionProjectionTolerance() const { return projectionTolerance_; }
  /// Position error beyond the elastic stretch (m or rad) above which a joint DOF counts as separated: the
  /// constraint is listed in StepReport::separatedConstraints and logged once. > 0, +infinity switches the
  /// check off. Default 0.1.
  void setConstraintErrorThreshold(Real e);
  Real getConstraintErrorThreshold() const { return constraintErrorThreshold_; }
  // ---- issue 18 (sweep scheduling): graph-coloured sweeps ----
  /// Graph-coloured PGS sweeps (default off; PgsColouring, docs/solver-internals.md "Coloured sweeps"): each
  /// contact's and joint's rows are one unit, units are coloured so that no two of a colour share a dynamic
  /// body, and the sweeps visit the colours in a fixed order with a colour's units shared among the threads
  /// (setNumThreads). Results are bit-identical for any thread count. The visiting order differs from the
  /// default serial order (contacts in contact-list order), so trajectories differ from the default's.
  void setUseColouredSweeps(bool on) { colouredSweeps_ = on; }
  bool getUseColouredSweeps() const { return colouredSweeps_; }
  // ---- issue 18 (friction anchors; docs/solver-internals.md "Friction anchors") ----
  /// Friction anchors of contact manifolds (default off; acts only on manifold friction, setUseManifoldFriction).
  /// While a manifold's friction sticks, its centre and first tangent are remembered in both bodies' frames, and
  /// its tangent pair and twist row get SPOOK's position term -a g on the anchors' tangential separation and
  /// twist angle (a the normal rows' gain from the contact's damping time), within their Coulomb bounds.
  /// Velocity-level friction alone lets whatever tangential velocity the sweeps leave accumulate as creep; the
  /// anchors pull it back. A manifold at its bound whose anchors are more than 1 % of its radius apart slips and
  /// starts a new anchor, so sliding is unchanged except that a box stopping from a slide may be pulled back by
  /// up to that distance. Without the shock pass it removes most of pyramid20's lean at 10 iterations, but not
  /// the rattling of its top rows (figures in the docs page); with the shock pass it changes little.
  void setUseFrictionAnchors(bool on) { frictionAnchors_ = on; }
  bool getUseFrictionAnchors() const { return frictionAnchors_; }
  // ---- issue 18 (sweep scheduling): partitioned sweeps ----
  /// Partitioned PGS sweeps and a parallel shock pass (default off; PgsPartition, docs/solver-internals.md
  /// "Partitioned sweeps"): the dynamic bodies are cut by a plane into two regions of about equal work; the
  /// contacts and joints inside each region are swept by their own thread, those across the cut by one thread
  /// between barriers (one barrier per sweep instead of one per colour). The shock pass runs the supports of
  /// each region on their own thread in the same dependency order (its result equals the serial pass's). With 128
  /// contacts or more the contact rows are laid out region by region (by the last step's regions) and built and
  /// prepared (warm start) on the region's thread too (SolverStats::numRowBuildThreads). Results are
  /// bit-identical for any thread count (setNumThreads). The
  /// sweep order differs from the default serial order (each region's contacts, then those across the cut), so
  /// trajectories differ from the default's. Takes precedence over setUseColouredSweeps when both are on.
  void setUsePartitionedSweeps(bool on) { partitionedSweeps_ = on; }
  bool getUsePartitionedSweeps() const { return partitionedSweeps_; }
  /// The partitioned sweeps' thread count by measurement (default on): whether a second thread pays depends on
  /// the host (how fast a cache line crosses between its cores) more than on the scene, and the results are the
  /// same bits on any count. So the step times its partitioned work, from the contact row build to the result
  /// store, on every available thread (scree::setNumThreads, at most one per region) and on one, 8 steps each
  /// (the first 2 not counted), and keeps the count with the lower median (one on a tie) for 120 steps, then
  /// measures again; each measurement that confirms the choice doubles the hold, up to 7680 steps. Off: always
  /// every available thread. SolverStats::numSweepThreads reports the count of the last step. docs/solver-internals.md
  /// "Partitioned sweeps: the thread count by measurement".
  void setUseAdaptiveSweepThreads(bool on) { adaptiveSweepThreads_ = on; }
  bool getUseAdaptiveSweepThreads() const { return adaptiveSweepThreads_; }
  // ---- issue 18 (coarse correction; docs/solver-internals.md "Coarse correction") ----
  /// A two-level correction of the contact loads between the rigid PGS sweeps (default off; ITERATIVE path,
  /// after the 2nd and the 4th sweep when a sweep follows). Gauss-Seidel moves a stack's load one level per
  /// sweep, so a tall stack's slowest load mode barely shrinks in 10 sweeps (0.977 per sweep on 20 levels);
  /// the shock pass (setUseShockPropagation) fixes that by holding the lower body still, which gives up the
  /// reaction on it. The correction instead solves, by a sparse LDL^T, for a few coarse unknowns per loaded
  /// contact manifold (its load, its tilt along its long axis, its sticking friction pair) with the exact
  /// coupling through the bodies, and adds the result to the impulses (bounds by refinement and a descent guard
  /// keep it from ever making the sweeps' objective worse). With friction anchors (setUseFrictionAnchors) and the
  /// shock pass off it holds pyramid20 at 10 iterations within 0.001 cm for 30 s, with every box's horizontal
  /// speed below 1e-9 m/s; the plain sweeps drift 8.6 cm and rattle at 0.2 m/s. Meant with the anchors: without
  /// them the sticking friction creeps, its loads build up to the cone and pyramid20 falls after a few seconds.
  /// Measured up to 25 rows; on pyramid30 the correction cannot keep within the bounds and is skipped, so that
  /// scene runs (and collapses) as on the plain sweeps, where the shock pass holds it.
  /// Cost on pyramid20 (about 1600 unknowns, two factorisations per step): 4.6 ms per step against 0.61 ms for
  /// the default (bench_rigid_stages, BM_pyramid20_coarse_stages; docs/solver-internals.md "Coarse correction").
  void setUseCoarseCorrection(bool on) { coarseCorrection_ = on; }
  bool getUseCoarseCorrection() const { return coarseCorrection_; }
  const SolverStats& getStats() const { return stats_; }

 private:
  friend struct detail::SolverStatsWriter;  // the step's stages fill stats_ (solver/src/simulation_state.h)
  int iterations_ = 16;
  bool warm_ = true;
  Real restitutionThreshold_ = 0.2;
  Real maxRecovery_ = 0;
  bool shock_ = true;
  bool manifoldFriction_ = true, manifoldBlock_ = true;  // contact manifolds (issue 18), on by default
  int shockIterations_ = 16;
  DirectForm form_ = AUTO;
  int maxPivots_ = 50;
  int hybridRounds_ = 2;
  bool geometricStiffness_ = true;
  bool projection_ = true;
  int projectionIterations_ = 3;
  Real projectionTolerance_ = 2e-3;
  Real constraintErrorThreshold_ = 0.1;
  SolverStats stats_;
  bool colouredSweeps_ = false;  // issue 18 (sweep scheduling)
  bool frictionAnchors_ = false;  // issue 18 (friction anchors), opt-in
  bool partitionedSweeps_ = false;  // issue 18 (sweep scheduling): partitioned sweeps
  bool adaptiveSweepThreads_ = true;  // issue 18: the partitioned sweeps' thread count by measurement
  bool coarseCorrection_ = false;  // issue 18: two-level correction of the contact loads, opt-in
};

}  // namespace scree
