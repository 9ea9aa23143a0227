// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Solve stage: the velocity solve of this step's rows and particle contact units, by one of four paths
// chosen from what the step holds (docs/design.md §2 and §4):
//
//   path         when                                          what runs
//   NOTHING      no rows, no particle units                    nothing
//   HYBRID       some row in the direct set (DIRECT, SPLIT,    hybrid direct/iterative rounds on the rows, then
//                DIRECT_AND_ITERATIVE; needs SuiteSparse)      the iterative particle units swept against it
//   INTERLEAVED  rigid rows, and particles touching a          one rigid PGS sweep and one particle sweep per
//                dynamic body                                  iteration, so each side sees the other's impulses
//   ITERATIVE    otherwise                                     rigid PGS sweeps, then particle sweeps
//
// Every path but NOTHING starts from the warm start (PgsSolver::prepare, GranularStage::prepare) and ends with
// the shock passes (Solver::setUseShockPropagation). Particle units in the manual's DIRECT mode become rows on
// appended solver bodies for the HYBRID path (granular_stage.h) and are removed again after it.
//
// DESIGN (issue 18, sweep cost, docs/solver-internals.md "Sweep cost"): the stage keeps one PgsBlocks in the
// simulation state and hands it to prepare, the sweeps and the shock pass, so the manifold normal blocks'
// operators are built once per step into reused storage (pgs.cpp). The direct-set subset sweeps of the HYBRID
// path do not use them (they solve row by row, as before).
#include <algorithm>
#include <chrono>
#include <limits>

#include "scree/core/logger.h"
#include "scree/core/parallel.h"
#include "step_stages.h"

namespace scree::detail {

namespace {

enum class SolvePath { NOTHING, HYBRID, INTERLEAVED, ITERATIVE };

bool hasParticleUnits(const SimulationState& s) { return s.granularStep && s.particles.hasUnits(); }

SolvePath choosePath(const SimulationState& s) {
  if (s.rows.empty() && !hasParticleUnits(s)) return SolvePath::NOTHING;
  if (!s.directSet.empty()) return SolvePath::HYBRID;
  if (hasParticleUnits(s) && s.particles.coupled() && !s.rows.empty()) return SolvePath::INTERLEAVED;
  return SolvePath::ITERATIVE;
}

/// Direct set: DIRECT rows; SPLIT and DIRECT_AND_ITERATIVE rows except friction. The iterative set: the rest,
/// and DIRECT_AND_ITERATIVE rows too (after their direct solve). Returns true when SPLIT friction needs the
/// final direct solve of the normals. Scenes whose rows are all ITERATIVE skip the classification.
bool classifyRows(SimulationState& s, bool particleDirect) {
  s.directSet.clear();
  s.iterSet.clear();
  s.pureIterative = false;
  bool split = false;
  if (!DirectSolver::available() || !(s.nonIterativeRows || particleDirect)) return false;
  for (uint32_t i = 0; i < s.rows.size(); ++i) {
    const ConstraintRow& r = s.rows[i];
    const auto t = r.solveType;
    const bool direct = t == FrictionModel::DIRECT || (t != FrictionModel::ITERATIVE && !r.friction);
    if (direct) s.directSet.push_back(i);
    if (!direct || t == FrictionModel::DIRECT_AND_ITERATIVE) s.iterSet.push_back(i);
    s.pureIterative |= !direct;
    split |= t == FrictionModel::SPLIT && r.friction;
  }
  return split;
}

bool useShock(const SimulationState& s) { return s.solver.getUseShockPropagation(); }

/// Particle shock pass (GranularStage::shockPass) along gravity; none without gravity.
void particleShock(SimulationState& s) {
  if (useShock(s) && s.gravity.squaredNorm() > 0)
    s.particles.shockPass(s.granular, s.sb, -s.gravity.normalized(), 2);
}

/// Rigid shock pass over the support order; with onlyIterative, couplings with a non-ITERATIVE row are skipped
/// (their rows are the direct solve's).
void rigidShock(SimulationState& s, bool onlyIterative) {
  if (!useShock(s) || s.couplings.empty()) return;
  buildShockOrder(s);
  auto& sh = s.shock;
  if (onlyIterative)
    sh.erase(std::remove_if(sh.begin(), sh.end(),
                            [&](const PgsSolver::ShockRange& r) {
                              for (uint32_t i = r.begin; i < r.begin + r.count; ++i)
                                if (s.rows[i].solveType != FrictionModel::ITERATIVE) return true;
                              return false;
                            }),
             sh.end());
  if (sh.empty()) return;
  // DESIGN (issue 18, docs/solver-internals.md "Resting stacks: the shock pass and the warm start"): next step's
  // warm start of a contact in the shock pass is built from the impulses the sweeps left, not taken from the
  // shock pass. The pass holds the lower body of each support immovable, so its impulse changes act on the upper
  // body only; cached as a warm start they would act on both bodies next step, a reaction delivered one step
  // late, and that is what pumped resting stacks:
  //  - the split between supports: a body on two supports (every box of pyramid20 above the bottom row) is
  //    solved support by support, and the first one solved takes the whole box, on its inner edge, the second
  //    almost nothing. Fed back, that order-dependent split loaded one lower box's edge; the pyramid breathed
  //    (its top box rose at 0.1 m/s at step 3) and settled with 2 cm of drift with the manifold block.
  //  - the tilt: on a single support the pass turns the upper box to follow the lower one's rocking, and the
  //    lower box felt the counter-torque a step late, a negative damping: a 20-box tower with mm offsets rocked
  //    up by about 5x a second and fell after 6 s.
  // The sweeps' impulses acted on both bodies of each row, so they are a momentum-consistent guess that the next
  // sweeps refine. Only the load the pass added is kept, for a body on a single support, where the pass has one
  // answer whatever the order: spread evenly over the manifold's normal rows (no tilt), it carries the weight of
  // what rests on the body down the stack from the first sweep (without it mass_ratio's 1000 kg box rose 2 um
  // short of its compliance sink at 5 iterations; with it, it sits at the sink at every count). Friction and
  // multi-support contacts start from the sweeps' impulses alone. Joints are left as they were (their warm
  // start is Constraint::storeResult's). Reported contact forces are the solved impulses, shock pass included.
  s.sweepLambda.assign(s.rows.size(), std::numeric_limits<Real>::quiet_NaN());
  s.shockSupports.assign(s.sb.size(), 0);
  for (const PgsSolver::ShockRange& r : sh)
    if (r.freeBody >= 0) ++s.shockSupports[r.freeBody];
  uint32_t contactEnd = uint32_t(s.rows.size());  // contact rows come first, then constraint rows
  for (const auto& cr : s.ranges) contactEnd = std::min(contactEnd, cr.begin);
  // The sweeps' impulses of the contact supports are recorded by the pass, on the thread that solves each range
  // (issue 18, two-thread scaling): read here, on the program thread, they pulled every row of the second region
  // into this core's cache just before the second thread wrote them again.
  const PgsSolver::ShockRecord record{s.sweepLambda.data(), contactEnd};
  if (s.partitionReady)  // issue 18 (sweep scheduling): the same pass, each region's supports on its own thread
    PgsSolver::shockPass(s.rows, s.sb, sh, s.solver.getNumShockIterations(), &s.pgsBlocks, s.partition, record);
  else
    PgsSolver::shockPass(s.rows, s.sb, sh, s.solver.getNumShockIterations(), &s.pgsBlocks, record);
  for (const PgsSolver::ShockRange& r : sh) {
    if (r.begin >= contactEnd || (r.freeBody >= 0 && s.shockSupports[r.freeBody] > 1)) continue;
    Real added = 0;
    int n = 0;
    for (uint32_t i = r.begin; i < r.begin + r.count; ++i)
      if (!s.rows[i].friction) {
        added += s.rows[i].lambda - s.sweepLambda[i];
        ++n;
      }
    if (n == 0) continue;
    added /= Real(n);
    for (uint32_t i = r.begin; i < r.begin + r.count; ++i)
      if (!s.rows[i].friction) s.sweepLambda[i] = std::max(s.sweepLambda[i] + added, s.rows[i].lo);
  }
}

/// One direct solve of the direct set with every other row's impulse held; PGS finishes the set on failure.
void directSolve(SimulationState& s) {
  SolverStats& st = s.solverStats();
  DirectSolver::Settings ds;
  ds.form = s.solver.getDirectForm();
  ds.maxPivots = s.solver.getMaxPivots();
  const DirectSolver::Result r = s.direct.solve(s.rows, s.directSet, s.sb, ds);
  st.numFactorisations += size_t(r.factorisations);
  st.numPivots += size_t(r.pivots);
  st.numSymbolicAnalyses += size_t(r.symbolicAnalyses);
  st.factorisationTime += r.factorSeconds;
  st.directForm = int(r.form);
  st.complementarityResidual = r.residual;
  if (!r.converged) {
    st.directFallback = true;
    Logger::warningOnce("scree.direct.fallback",
                        "DIRECT solver: no solution within the pivot cap (Solver::setMaxPivots) or the matrix "
                        "was not definite; the direct rows of such steps are finished by PGS "
                        "(SolverStats::directFallback)");
    st.complementarityResidual = PgsSolver::iterate(s.rows, s.sb, s.solver.getNumIterations(), s.directSet);
  }
}

/// HYBRID with a glued DIRECT particle lump (issue 16; docs/terrain.md, "External materials and particle solve
/// type"). DESIGN: the manual's DIRECT particle mode (infinite friction and adhesion) makes every particle bond
/// an equality row, so the direct set holds no unilateral particle row and needs no pivot; the lump's bounded
/// contacts (with the bucket, the terrain, loose particles) are iterative units. The two are alternated as
/// block Gauss-Seidel: a direct solve of the direct set with the units' impulses held, then particle sweeps
/// over the iterative units with the direct impulses held (the appended bodies' velocities copied to the
/// particles and back), numHybridRounds times, and the step ENDS with a direct solve. Whatever the sweeps left
/// (a contact not yet converged is corrected by its SPOOK bias next step), the lump's velocities then satisfy
/// its bonds, i.e. it moves as one body up to the bonds' compliance. Ending with the sweeps, as hybridPath
/// does, lets them move the lump's particles one by one: the lump comes apart.
void lumpPath(SimulationState& s) {
  SolverStats& st = s.solverStats();
  st.numDirectRows = s.directSet.size();
  st.numIterativeRows = s.pureIterative ? s.iterSet.size() : 0;
  if (!s.pureIterative) s.iterSet.clear();
  const int iterations = s.solver.getNumIterations();
  // Two particle sweeps per round, at least numHybridRounds rounds: each round lets the lump's contacts act on
  // the whole lump once (a sweep alone moves single particles; the direct solve spreads it over the lump). On
  // the carry test (docs/terrain.md) 2 rounds of 8 sweeps left the lump rocking on the bucket (0.2-0.6 m/s
  // spread of vertical speed, drift 7e-4 m); 8 rounds of 2: 4e-3 m/s, drift 1e-5 m. 16 iterations: 9 direct
  // solves per step (equality rows: one factorisation each, no pivot).
  const int rounds = std::max(s.solver.getNumHybridRounds(), (iterations + 1) / 2);
  const int sweeps = 2;
  st.numIterations = 0;
  Real residual = 0;
  for (int round = 0; round < rounds; ++round) {
    directSolve(s);
    if (!s.iterSet.empty()) residual = std::max(residual, PgsSolver::iterate(s.rows, s.sb, sweeps, s.iterSet));
    s.particles.directToParticles(s.granular, s.sb);
    for (int it = 0; it < sweeps; ++it)
      residual = std::max(residual, s.particles.sweep(s.granular, s.sb, it % 2 == 1));
    if (round + 1 == rounds) particleShock(s);
    s.particles.particlesToDirect(s.granular, s.sb);
    st.numIterations += size_t(sweeps);
  }
  if (!s.iterSet.empty()) rigidShock(s, true);
  directSolve(s);
  s.particles.finishDirect(s.granular, s.rows, s.sb);
  while (!s.directSet.empty() && s.directSet.back() >= s.rows.size()) s.directSet.pop_back();
  st.lastResidual = residual;
}

/// HYBRID (docs/design.md §4): direct solve of the direct set with the iterative rows' impulses held, then PGS
/// sweeps over the iterative set with the direct impulses held, numHybridRounds times; SPLIT friction ends
/// with one more direct solve of the normals. The rigid shock pass visits only couplings whose rows are all
/// iterative. Then the iterative particle units are swept with the rows' impulses held.
void hybridPath(SimulationState& s, bool finalDirect, bool particleDirect) {
  SolverStats& st = s.solverStats();
  st.numDirectRows = s.directSet.size();
  st.numIterativeRows = s.pureIterative ? s.iterSet.size() : 0;
  // Without rows that only PGS solves, there is nothing to alternate with: one direct solve.
  if (!s.pureIterative) s.iterSet.clear();
  const int rounds = s.iterSet.empty() ? 1 : s.solver.getNumHybridRounds();
  const int sweeps = std::max(1, (s.solver.getNumIterations() + rounds - 1) / rounds);
  st.numIterations = 0;
  st.lastResidual = 0;
  for (int round = 0; round < rounds; ++round) {
    directSolve(s);
    if (s.iterSet.empty()) break;
    st.lastResidual = PgsSolver::iterate(s.rows, s.sb, sweeps, s.iterSet);
    st.numIterations += size_t(sweeps);
  }
  if (!s.iterSet.empty()) rigidShock(s, true);
  if (finalDirect) directSolve(s);

  if (particleDirect) {
    s.particles.finishDirect(s.granular, s.rows, s.sb);
    // The particle rows are gone again: keep the direct set valid for the position projection (ascending).
    while (!s.directSet.empty() && s.directSet.back() >= s.rows.size()) s.directSet.pop_back();
  }
  Real residual = st.lastResidual;
  if (hasParticleUnits(s) && s.particles.hasIterativeUnits()) {
    const int iterations = s.solver.getNumIterations();
    for (int it = 0; it < iterations; ++it)
      residual = std::max(residual, s.particles.sweep(s.granular, s.sb, it % 2 == 1));
    particleShock(s);
  }
  st.lastResidual = residual;
}

/// The rigid PGS sweeps: serial in row order, or coloured (Solver::setUseColouredSweeps; units = couplings, which
/// cover every row on these paths).
Real rigidSweeps(SimulationState& s, int iterations) {
  if (s.partitionReady) return PgsSolver::iterate(s.rows, s.sb, iterations, &s.pgsBlocks, s.partition);
  if (!s.solver.getUseColouredSweeps()) return PgsSolver::iterate(s.rows, s.sb, iterations, &s.pgsBlocks);
  return PgsSolver::iterate(s.rows, s.sb, iterations, &s.pgsBlocks, s.colouring);
}

/// The rigid sweeps with the coarse correction (Solver::setUseCoarseCorrection, coarse_correction.h) after the
/// second and the fourth sweep, each only when a sweep follows it: 10 sweeps run as 2, correction, 2,
/// correction, 6. Measured on pyramid20 without the shock pass (docs/solver-internals.md, "Coarse correction"):
/// one correction after 2 sweeps rattled, and so did other schedules; a run that ended its step with a
/// correction (before the descent guard existed) exploded.
Real rigidSweepsCoarse(SimulationState& s, int iterations) {
  if (!s.solver.getUseCoarseCorrection()) return rigidSweeps(s, iterations);
  SolverStats& st = s.solverStats();
  Real residual = 0;
  int done = 0;
  for (int at : {2, 4}) {
    if (iterations <= at) break;
    residual = rigidSweeps(s, at - done);
    done = at;
    const CoarseCorrection::Result r = s.coarse.apply(s.rows, s.sb, s.couplings);
    st.numCoarseUnknowns = std::max(st.numCoarseUnknowns, size_t(r.unknowns));
    st.numCoarseRefinements += size_t(r.refinements);
    st.numCoarseAnalyses += r.analysed ? 1 : 0;
  }
  if (iterations > done) residual = rigidSweeps(s, iterations - done);
  return residual;
}

/// INTERLEAVED and ITERATIVE: PGS sweeps over all rows and particle units, then the shock passes.
void iterativePath(SimulationState& s, bool interleaved) {
  // Issue 18 (sweep scheduling): partitioned sweeps take precedence over coloured ones.
  if (s.solver.getUsePartitionedSweeps() && !s.rows.empty()) {
    PgsPartition& p = s.partition;
    p.units.clear();
    for (const CouplingRange& c : s.couplings) p.units.push_back({c.begin, c.count});
    p.bodyPosition.resize(s.sb.size());
    for (size_t i = 0; i < s.sb.size(); ++i)
      p.bodyPosition[i] = i < s.bodies.size() ? s.bodies[i]->getPosition() : Vec3::Zero();
    PgsSolver::partition(s.rows, s.sb, p);
    s.partitionReady = true;
  } else if (s.solver.getUseColouredSweeps() && !s.rows.empty()) {
    s.colouring.units.clear();
    for (const CouplingRange& c : s.couplings) s.colouring.units.push_back({c.begin, c.count});
    PgsSolver::colour(s.rows, s.sb, s.colouring);
  }
  SolverStats& st = s.solverStats();
  // The partitioned work's thread count was chosen at the row build (beginPartitionedWork); the step times its
  // span from there to the end of the store (endPartitionedWork).
  const int iterations = s.solver.getNumIterations();
  const bool particles = hasParticleUnits(s);
  st.numIterativeRows = s.rows.size();
  Real residual = 0;
  if (interleaved) {
    for (int it = 0; it < iterations; ++it) {
      residual = rigidSweeps(s, 1);
      residual = std::max(residual, s.particles.sweep(s.granular, s.sb, it % 2 == 1));
    }
  } else {
    if (!s.rows.empty()) residual = rigidSweepsCoarse(s, iterations);
    if (particles)
      for (int it = 0; it < iterations; ++it)
        residual = std::max(residual, s.particles.sweep(s.granular, s.sb, it % 2 == 1));
  }
  if (particles) particleShock(s);
  st.lastResidual = residual;
  st.numIterations = size_t(iterations);
  if (!s.rows.empty()) rigidShock(s, false);
  // The count the sweeps and the shock pass ran on: the one asked for, or one if the work was too small to split
  // or a job found the team busy.
  if (s.partitionReady) st.numSweepThreads = std::max(1, s.partition.threadsRan);
}

}  // namespace

void beginPartitionedWork(SimulationState& s) {
  s.partitionSpanStarted = false;
  s.rowBuildTeamBusy = s.partition.teamBusy = false;
  s.partition.threadsRan = 0;
  if (!s.solver.getUsePartitionedSweeps()) return;
  const int available = std::min(PgsPartition::kRegions, scree::getNumThreads());
  const bool adaptive = s.solver.getUseAdaptiveSweepThreads();
  s.partition.maxThreads = adaptive ? s.sweepThreads.begin(available) : available;
  if (adaptive && available >= 2) {
    s.partitionSpanStart = std::chrono::steady_clock::now();
    s.partitionSpanStarted = true;
  }
}

void endPartitionedWork(SimulationState& s) {
  // Timed only when this step's sweeps were partitioned (partitionReady holds from the solve to the next one).
  if (!s.partitionSpanStarted || !s.partitionReady) return;
  s.partitionSpanStarted = false;
  // A step that asked the team for more than one thread and did not get it ran on one: it is not a sample of
  // the count asked for (SweepThreadChoice::end).
  const bool busy = s.rowBuildTeamBusy || s.partition.teamBusy;
  s.sweepThreads.end(busy ? std::numeric_limits<double>::infinity()
                          : std::chrono::duration<double>(std::chrono::steady_clock::now() - s.partitionSpanStart).count());
}

void solve(SimulationState& s) {
  SolverStats& st = s.solverStats();
  st.numDirectRows = st.numIterativeRows = st.numFactorisations = st.numPivots = st.numSymbolicAnalyses = 0;
  st.complementarityResidual = 0;
  st.factorisationTime = 0;
  st.directFallback = false;
  st.numSweepThreads = 1;
  st.numCoarseUnknowns = st.numCoarseRefinements = st.numCoarseAnalyses = 0;
  s.directSet.clear();
  s.iterSet.clear();
  s.sweepLambda.clear();
  s.partitionReady = false;
  if (choosePath(s) == SolvePath::NOTHING) {
    st.numIterations = 0;
    st.lastResidual = 0;
    return;
  }
  // DIRECT-mode particle units become rows on appended solver bodies (warm start first: the appended bodies
  // copy the particle velocities), so they are classified and solved like rigid rows.
  const bool particles = hasParticleUnits(s);
  const bool particleDirect = particles && s.particles.hasDirectUnits();
  if (particleDirect) {
    s.particles.prepare(s.granular, s.sb);
    s.particles.appendDirectRows(s.granular, s.rows, s.sb);
  }
  const bool split = classifyRows(s, particleDirect);
  if (!s.directSet.empty()) addGeometricStiffness(s);
  // The normal blocks' rows are prepared on first use (PgsSolver::prepare, deferBlockRows) on the paths whose
  // sweeps read them only through the blocks: the serial and partitioned sweeps of ITERATIVE and INTERLEAVED.
  // HYBRID's subset sweeps and direct solve and the coloured sweeps read every row.
  const SolvePath path = choosePath(s);
  const bool deferBlockRows = (path == SolvePath::ITERATIVE || path == SolvePath::INTERLEAVED) &&
                              (s.solver.getUsePartitionedSweeps() || !s.solver.getUseColouredSweeps());
  if (!s.rows.empty() && s.rowGroupsReady) {
    // Issue 18 (two-thread scaling): the regions' rows on the row build's threads, which laid them out by region
    // (contact_rows.cpp).
    PgsSolver::PrepareGroups groups;
    for (int g = 0; g < PgsPartition::kRegions; ++g) groups.rowEnd[g] = s.rowGroupEnd[g];
    groups.threads = s.rowGroupThreads;
    groups.teamBusy = &s.rowBuildTeamBusy;
    PgsSolver::prepare(s.rows, s.sb, &s.pgsBlocks, deferBlockRows, groups);
  } else if (!s.rows.empty()) {
    PgsSolver::prepare(s.rows, s.sb, &s.pgsBlocks, deferBlockRows);
  }
  if (particleDirect) s.particles.loadDirectImpulses(s.rows);
  else if (particles) s.particles.prepare(s.granular, s.sb);

  switch (path) {
    case SolvePath::NOTHING: break;
    case SolvePath::HYBRID:
      if (particleDirect && s.particles.needsLumpRounds()) lumpPath(s);
      else hybridPath(s, split, particleDirect);
      break;
    case SolvePath::INTERLEAVED: iterativePath(s, true); break;
    case SolvePath::ITERATIVE: iterativePath(s, false); break;
  }
}

}  // namespace scree::detail
