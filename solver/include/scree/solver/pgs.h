// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Projected Gauss-Seidel on the Schur form (docs/design.md §4). Reads only core types and rows, so tests can feed
// hand-built systems.
//
// Per row i: delta = (rhs_i - J_i v - e_i lambda_i) / (J_i M^-1 J_i^T + e_i), lambda_i <- clamp(lambda_i + delta),
// v <- v + M^-1 J_i^T (clamped delta). Friction bounds follow the row's normal row (scaled box and the
// projected cone use the current normal iterate, box uses fixed lo/hi). Paired tangent rows (projected cone)
// get scalar updates at the same velocity, then the pair is projected onto the disc |lambda_t| <= mu lambda_n.
// Warm starting: rows arrive with lambda from last step; prepare() applies those impulses first.
#pragma once

#include <cstdint>
#include <vector>

#include "scree/core/math.h"
#include "scree/solver/constraint_row.h"
#include "scree/solver/solver.h"

namespace scree::detail {

/// Velocities and inverse mass of one body as the solver sees it (world frame, at the centre of mass).
struct SolverBodyState {
  Vec3 v = Vec3::Zero();
  Vec3 w = Vec3::Zero();
  Real invMass = 0;
  Mat3 invInertia = Mat3::Zero();
};

/// J v of row r: its velocity along the row's Jacobian (bodies with index < 0 are static and contribute nothing).
inline Real rowVelocity(const ConstraintRow& r, const std::vector<SolverBodyState>& b) {
  Real jv = 0;
  if (r.bodyA >= 0) jv += r.jLinA.dot(b[size_t(r.bodyA)].v) + r.jAngA.dot(b[size_t(r.bodyA)].w);
  if (r.bodyB >= 0) jv += r.jLinB.dot(b[size_t(r.bodyB)].v) + r.jAngB.dot(b[size_t(r.bodyB)].w);
  return jv;
}

/// The constant operators of each manifold normal block (pgs.cpp solveNormalBlock), built once per step by
/// PgsSolver::prepare so that a sweep's block visit is three 12-wide dot products, a 3 x 3 triangular solve and
/// three 12-wide updates instead of assembling and factoring the 3 x 3 system on every visit (issue 18: that
/// assembly was 60 % of pyramid20's step). Kept by the caller across steps so that its storage is reused.
struct PgsBlocks {
  struct Block {
    /// Per coordinate a (centre, tilt u, tilt v): G_a = sum_i D_ai J_i (the coordinate's row), W_a = M^-1 G_a^T.
    Vec3 gLinA[3], gAngA[3], gLinB[3], gAngB[3];
    Vec3 wLinA[3], wAngA[3], wLinB[3], wAngB[3];
    Real dRhs[3];  ///< sum_i D_ai rhs_i
    Real se[6];    ///< D E D^T = sum_i D_ai e_i D_ci, packed lower (s00 s10 s11 s20 s21 s22)
    /// Inverse (symmetric, lower row-major packed: s00 s10 s11 s20 s21 s22) of D (K + E) D^T with both bodies
    /// free [0], body A frozen [1], body B frozen [2], from its Cholesky factor; ok[k] false when that system is
    /// not positive definite.
    /// Configuration 0 is built with the block; 1 and 2 on first use (built[k]), by the shock pass's fallback
    /// sweeps, through a const block: mutable, and each block is only ever visited by one thread at a time.
    mutable Real sInv[3][6];
    mutable bool ok[3];
    mutable bool built[3];
    bool axisU, axisV;
    /// False while the block's ConstraintRows lack M^-1 J^T and their diagonals: PgsSolver::prepare with
    /// deferBlockRows leaves them to the first path that reads them (ensureBlockRows in pgs.cpp: a visit's
    /// bound-hit fallback, the shock pass's fallback sweeps, a non-compact manifold's row sweeps). Mutable like
    /// sInv, and for the same reason: one thread per block at a time.
    mutable bool rowsReady = true;
  };
  std::vector<Block> blocks;
  /// PgsSolver::prepare: each block's first row, in row order (slot order); after the grouped prepare each
  /// group's blocks from the group's own base slot, UINT32_MAX in the slots left unused.
  std::vector<uint32_t> starts;
  /// Whether PgsSolver::prepare left any block's rows unprepared (Block::rowsReady): the passes that prepare
  /// every deferred block of a range return at once when none is.
  bool anyDeferred = false;

  // ---- issue 18 (compact contact arrays; pgs.cpp "Compact manifold sweeps", docs/solver-internals.md) ----
  /// A manifold contact (contact_rows.h: [t1, t2, twist][normal block]) swept as one unit: every datum a visit
  /// reads lies in this record and its points. Six rows act on the two bodies: the normal block's coordinates
  /// (centre, tilt u, tilt v: Block::g/w) and the friction rows (t1, t2, twist). Compact layout (issue 18,
  /// fourth round, docs/solver-internals.md "Compact contact rows"):
  ///  - linear parts once per manifold and only where a row has one: a contact row's J_linB = -J_linA, so each
  ///    row's linear part is one A-side direction against the relative velocity v_A - v_B, and M^-1 J_lin^T is
  ///    that direction times the body's inverse mass. The tilt coordinates' linear part sum_i u_i n_i vanishes
  ///    (u, v are centred) and the twist row has none: three directions (the block centre's sum of normals, t1,
  ///    t2) serve all six rows;
  ///  - per row only the angular parts J_ang and I^-1 J_ang^T, both bodies' as one 6-vector [A; B] that a visit
  ///    dots with the bodies' angular velocities (w_A; w_B) held as one 6-vector (SSE2: three packets of two);
  ///  - per point its block coordinates, compliance, impulse and lower bound (40 bytes; contact normal rows
  ///    have no upper bound). The compliance stays per point: a tilted manifold mixes touching points (SPOOK's
  ///    e) with speculative ones (e = 0).
  /// Double precision throughout: the compact sweeps must give the ConstraintRow sweeps' impulses to 1e-9
  /// (test_unit_compact_sweeps), which float Jacobians (6e-8 relative) do not.
  using Vec6 = Eigen::Matrix<Real, 6, 1>;
  struct Manifold {
    Vec6 ang[6];             ///< angular J [A; B] per row: 0..2 block (centre, u, v), 3..5 friction (t1, t2, twist)
    Vec6 w[6];               ///< I^-1 J_ang^T [A; B] per row
    Vec3 lin[3];             ///< A-side linear J: block centre (row 0), t1 (row 3), t2 (row 4); B side negated
    Real imA, imB;           ///< the bodies' inverse masses (0: static)
    Real rhs[3], e[3], invDiag[3], lambda[3];  ///< friction rows t1, t2, twist
    Real dRhs[3], sInv[6];   ///< Block::dRhs, Block::sInv[0]
    /// Sums over the points, kept with their impulses (one pass when a block update is accepted, instead of
    /// two loops per visit): sum e lambda, sum e lambda u, sum e lambda v (the compliances' term of the block's
    /// residual) and sum max(lambda, 0) (the friction bound, boundingNormal).
    Real sl, slu, slv, sumN;
    Real mu, muTwist;        ///< friction coefficients of the pair and the twist (ConstraintRow::mu)
    int32_t a, b;            ///< solver bodies (-1: static)
    uint32_t row;            ///< ConstraintRow of t1; t2 = row + 1, twist = row + 2, normals from row + 3
    uint32_t block;          ///< slot in blocks
    uint32_t point;          ///< first of its n entries in points
    int32_t n;               ///< normal rows
    bool cone;               ///< t1, t2 a projected-cone pair (else two scaled-box rows)
    bool ok, axisU, axisV;   ///< Block::ok[0], axisU, axisV
  };
  /// A normal row of a manifold block: its block coordinates, compliance, impulse and lower bound.
  struct Point {
    Real u, v, e, lambda, lo;
  };
  /// The serial sweep's visiting order: a compact manifold (manifold >= 0) or the ConstraintRows [begin, end)
  /// swept row by row (joints, per-point contacts, anything not of the manifold form).
  struct Unit {
    uint32_t begin, end;
    int32_t manifold;
  };
  std::vector<Manifold> manifolds;
  std::vector<Point> points;
  std::vector<Unit> plan;
  /// Per ConstraintRow: the record whose rows start there, or -1; filled only when the records are not in row
  /// order (the partitioned sweeps lay them out region by region), empty otherwise (the records are then
  /// searched by row). Records with n < 0 are never visited: the gaps between regions and, in the partitioned
  /// layout (one record per unit), the records of units that are no compact manifold.
  std::vector<int32_t> rowManifold;
};

// ---- issue 18 (sweep scheduling): graph-coloured sweeps (pgs.cpp, docs/solver-internals.md "Coloured sweeps") ----
/// The rows cut into units (one contact's or one joint's rows: every row of a unit acts on the same two bodies)
/// and the units into colours such that no two units of one colour share a body the sweeps can move (static and
/// kinematic bodies -- zero inverse mass and inertia -- do not count). A coloured sweep visits the colours in a
/// fixed order and, within a colour, units that touch disjoint bodies, so the units of a colour can be swept by
/// any number of threads in any order with bit-identical results. Kept by the caller across steps (storage
/// reused: no per-step allocation once grown).
struct PgsColouring {
  struct Unit {
    uint32_t begin, count;
  };
  /// Input: the units in the order the serial sweep visits them (PgsSolver::colour reorders them by colour).
  std::vector<Unit> units;
  /// Output: colour c holds units [colourStart[c], colourStart[c + 1]); units that found no colour among the
  /// first 64 are the last group, swept by one thread.
  std::vector<uint32_t> colourStart;
  bool lastGroupSerial = false;
  // Scratch (reused).
  std::vector<uint64_t> bodyMask;
  std::vector<uint8_t> unitColour;
  std::vector<Unit> sorted;
  /// Rows whose static body was given a private copy for the sweeps (row index, side, original body index).
  struct Remap {
    uint32_t row;
    int side;
    int32_t body;
  };
  std::vector<Remap> remapped;
};

// ---- issue 18 (sweep scheduling): partitioned sweeps (pgs_partition.cpp, pgs.cpp end, docs/solver-internals.md
// "Partitioned sweeps") ----
/// A sweep schedule with few barriers: the units (one contact's or joint's rows) in one order plus split points.
/// The movable bodies are cut into kRegions regions of about equal work by a plane (PgsSolver::partition);
/// a unit whose movable bodies all lie in region r belongs to region r, a unit that touches two regions to the
/// boundary. `order` holds region 0's units, region 1's, ..., then the boundary's, each group in the serial
/// sweep's order; group g is [split[g], split[g + 1]) (split has kRegions + 2 entries, the last group being the
/// boundary). Regions share no movable body, so they can be swept at the same time by different threads; the
/// boundary is swept by one thread between barriers. The result does not depend on the thread count: on one
/// thread the regions simply run one after the other. The schedule is data (an order of units and split points),
/// independent of the row layout. Kept by the caller across steps (storage reused); the cut is kept while the
/// units (their bodies and row counts, in order) stay the same as when it was made.
struct PgsPartition {
  static constexpr int kRegions = 2;
  /// A body the sweeps move (dynamic): what the regions hold. Static and kinematic bodies belong to no region.
  static bool movable(const SolverBodyState& b) { return b.invMass > 0 || !b.invInertia.isZero(0); }
  struct Unit {
    uint32_t begin, count;
  };
  /// Input: the units in the serial sweep's order, and each solver body's position (for the cutting plane).
  std::vector<Unit> units;
  std::vector<Vec3> bodyPosition;
  /// Output.
  std::vector<Unit> order;
  uint32_t split[kRegions + 2] = {};
  std::vector<int8_t> bodyRegion;  ///< per solver body: its region, -1 for static and kinematic bodies
  /// The boundary's units in phases that both threads sweep at once (PgsSolver::iterate), with a barrier between
  /// phases: phase c is [boundarySplit[c], boundarySplit[c + 1]), thread 0 taking [boundarySplit[c],
  /// boundaryMid[c]) and thread 1 the rest; no unit of one share shares a movable body with the other's. The
  /// boundary's units in `order` are in that order, which is also the serial sweep's (PgsSolver::splitBoundary).
  /// boundaryPhases 0: the boundary is one group that thread 0 sweeps. Depends on the scene only, never on the
  /// thread count.
  static constexpr int kMaxBoundaryPhases = 2;
  int boundaryPhases = 0;
  uint32_t boundarySplit[kMaxBoundaryPhases + 1] = {};
  uint32_t boundaryMid[kMaxBoundaryPhases] = {};
  int axis = 0;                    ///< the cutting plane's normal (0 x, 1 y, 2 z)
  // Scratch (reused).
  std::vector<uint32_t> sortedBodies;
  std::vector<Real> bodyWeight;
  std::vector<int8_t> unitGroup;
  std::vector<uint64_t> signature;  ///< the units' body pairs and row counts when the cut was last made
  std::vector<uint8_t> bodyMark;  ///< per solver body (zero between calls; splitBoundary)
  std::vector<Unit> unitScratch;
  std::vector<int32_t> unitManifold;  ///< per unit of `order`: its compact record (PgsBlocks::manifolds) or -1
  /// The sweeps' own copy of the bodies, region by region (PgsSolver::iterate with a partition): each region's
  /// movable bodies, then the static and kinematic bodies its units touch (private copies; region 0's serve the
  /// boundary too), then a gap. `localOf[g * n + b]` is body b's slot as region g's units see it (n bodies;
  /// movable bodies have one slot in every view), `globalOf` each slot's body (-1 in the gaps).
  std::vector<SolverBodyState> local;
  std::vector<int32_t> localOf, globalOf;
  /// Shock pass (PgsSolver::shockPass with a partition): per range, the thread list it belongs to and how many
  /// ranges of the other list must be finished before it runs.
  std::vector<uint32_t> shockList[kRegions];
  std::vector<uint32_t> shockWait[kRegions];
  std::vector<uint32_t> shockDone;  ///< per solver body: 1 + position of its last writer in its region's list
  /// Per range of a list: 1 when a range of the other list waits for the count this range's end reaches (its
  /// thread then publishes that count); the other ranges' ends are not published.
  std::vector<uint8_t> shockPublish[kRegions];
  /// Cap on the threads of the partitioned sweeps and shock pass (0: scree::getNumThreads()); at most one thread
  /// per region either way. The solve stage sets it from its measurements (Solver::setUseAdaptiveSweepThreads).
  int maxThreads = 0;
  /// Output: set when a sweep or shock job asked the team for two threads and ran on one, because another
  /// Simulation held the team (scree/core/parallel.h runTeamJob; the bits are the same). Never cleared here: the
  /// caller clears it before the step's partitioned work.
  bool teamBusy = false;
  /// Output: the most threads a sweep or shock job of the step ran on: 1 when the work was too small to split
  /// (fewer than 64 units, or 16 shock ranges) or the team was busy, 0 when none ran. Never cleared here: the
  /// caller clears it before the step's partitioned work (SolverStats::numSweepThreads reports it).
  int threadsRan = 0;
};

class PgsSolver {
 public:
  /// Computes M^-1 J^T and the diagonals, then applies the warm-start impulses to the velocities. With `blocks`,
  /// also the manifold normal blocks' operators (ConstraintRow::blockSlot); without, every blockSlot is -1.
  /// With `blocks` and deferBlockRows, the normal blocks' rows get neither (PgsBlocks::Block::rowsReady false):
  /// their warm start is applied per body as M^-1 (sum_i lambda_i J_i^T), and the paths that read the rows'
  /// M^-1 J^T prepare a block's rows on first use. Only for the iterate overloads that take `blocks` (serial and
  /// partitioned; the coloured one prepares every deferred block at entry) and the shock pass; not for the
  /// subset sweeps nor DIRECT, which read the rows directly.
  static void prepare(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies,
                      PgsBlocks* blocks = nullptr, bool deferBlockRows = false);
  /// Rows laid out by region (the grouped contact row build, contact_rows.cpp): rows [0, rowEnd[0]) act on no
  /// movable body outside region 0, rows [rowEnd[0], rowEnd[1]) on none outside region 1, the rows after them
  /// on any (PgsPartition).
  struct PrepareGroups {
    uint32_t rowEnd[PgsPartition::kRegions] = {};
    int threads = 1;              ///< threads asked of the team (scree/core/parallel.h)
    bool* teamBusy = nullptr;     ///< set when the team gave fewer (another Simulation held it)
  };
  /// prepare on grouped rows: the regions' rows on up to `groups.threads` threads at once, then the rest on the
  /// calling thread. Every body's warm-start impulses are summed in row order, so the bits are the serial
  /// prepare's on the same rows, except that static and kinematic bodies get no write (their velocities, to
  /// which the warm start adds zero, keep their bits). A block's slot is not its rank: each region's blocks get
  /// slots from a base of their own, PgsBlocks::starts holds UINT32_MAX in the unused ones.
  static void prepare(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, PgsBlocks* blocks,
                      bool deferBlockRows, const PrepareGroups& groups);
  /// `iterations` sweeps over all rows in order. Returns the largest |delta lambda| of the last sweep. `blocks`
  /// must be the one given to prepare (or null).
  /// With `blocks`, manifold contacts are swept from compact copies (PgsBlocks::Manifold) built at entry and
  /// their impulses written back to the rows at exit.
  static Real iterate(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, int iterations,
                      PgsBlocks* blocks = nullptr);
  /// Colours `colouring.units` (PgsColouring) for the given rows and bodies; call after prepare, every step.
  static void colour(const std::vector<ConstraintRow>& rows, const std::vector<SolverBodyState>& bodies,
                     PgsColouring& colouring);
  /// `iterations` coloured sweeps (alternating forward and backward: colours in increasing order and each unit's
  /// rows forward, then colours in decreasing order and rows backward), the units of a colour shared among the
  /// OpenMP threads. Results do not depend on the number of threads. A unit that touches a static body gets a
  /// private copy of it for the sweeps (appended to `bodies` and removed again), so that no two threads write
  /// the same body even with zero impulses. Returns the largest |delta lambda| of the last sweep.
  static Real iterate(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, int iterations,
                      const PgsBlocks* blocks, PgsColouring& colouring);
  /// The same sweeps over the rows listed in `subset` only (ascending indices; a projected-cone pair must be
  /// listed whole); the other rows' impulses are held fixed. Used by the hybrid direct/iterative solve.
  static Real iterate(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, int iterations,
                      const std::vector<uint32_t>& subset);

  /// A row range whose body `frozen` (0 = A, 1 = B) is held immovable in the shock-propagation pass; freeBody and
  /// frozenBody are its rows' bodies (solver indices, -1 for none), so that the partitioned pass schedules the
  /// ranges without reading the rows, which the other thread writes.
  struct ShockRange {
    uint32_t begin, count;
    int frozen;
    int32_t freeBody, frozenBody;
  };
  /// Optional output of the shock pass: before a range that begins below `end` is solved, its rows' impulses are
  /// copied to lambda[row], on the thread that solves it (the sweeps' impulses, which the next step's warm start
  /// keeps; solve_stage.cpp rigidShock).
  struct ShockRecord {
    Real* lambda;  ///< null: nothing recorded (the default, {})
    uint32_t end;
  };
  /// Shock propagation (Guendelman, Bridson & Fedkiw 2003): after the sweeps, the given row ranges (ordered
  /// from the ground up) are solved in turn, each with its lower body held immovable, up to `maxSweeps`
  /// Gauss-Seidel sweeps per range (fewer once its impulses stop changing). Rows of a range are visited
  /// normals first. With `blocks`, a range that is one manifold (normal block and centre friction) is first solved
  /// exactly on its free body; it is swept only when that solution leaves the bounds (pgs.cpp).
  ///
  /// Why: plain PGS with warm starting has a loop gain of about 2 from one step to the next (an impulse error
  /// e leaves a velocity error that shifts the next step's solution by e again), so the sweeps must cut the
  /// error by more than half every step. On a stack of N bodies Gauss-Seidel contracts by ~1 - c/N^2 per
  /// sweep: towers of three or more boxes rocked at 10-64 sweeps. Solving each support with the lower body
  /// fixed removes the coupling down the stack, and sweeping each support to convergence makes its 4-point
  /// manifold consistent, so the loop gain drops below one.
  static void shockPass(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies,
                        const std::vector<ShockRange>& ranges, int maxSweeps, const PgsBlocks* blocks = nullptr,
                        const ShockRecord& record = {});

  // ---- issue 18 (sweep scheduling): partitioned sweeps ----
  /// Cuts `partition.units` into regions and a boundary (PgsPartition); call after prepare, every step.
  static void partition(const std::vector<ConstraintRow>& rows, const std::vector<SolverBodyState>& bodies,
                        PgsPartition& partition);
  /// `iterations` partitioned sweeps (alternating forward and backward): forward, the regions (in parallel, or
  /// one after the other on one thread), then the boundary; backward, the boundary, then the regions, each
  /// unit's rows backward; the boundary phase by phase (PgsPartition::boundaryPhases), both threads sweeping
  /// their share of each phase. Two barriers per pair of sweeps and phase (two without phases). Results do not
  /// depend on the number of threads.
  /// With `blocks`, manifold contacts are swept from the compact records (as in the serial iterate above).
  static Real iterate(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, int iterations,
                      PgsBlocks* blocks, PgsPartition& partition);
  /// The shock pass (same law and order of dependencies as shockPass above, bit-identical to it): the ranges of
  /// each region's free bodies run on their own thread, waiting only for ranges of the other region whose free
  /// body is their frozen one (point-to-point, no barrier).
  static void shockPass(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies,
                        const std::vector<ShockRange>& ranges, int maxSweeps, const PgsBlocks* blocks,
                        PgsPartition& partition, const ShockRecord& record = {});
  /// The parallel shock pass's schedule (called by it): each range's list (its free body's region), the count of
  /// the other list's ranges it waits for, and which ranges' ends are published (PgsPartition::shockList,
  /// shockWait, shockPublish). `numBodies` solver bodies.
  static void shockSchedule(const std::vector<ShockRange>& ranges, size_t numBodies, PgsPartition& partition);

 private:
  /// The cutting plane and the bodies' regions (pgs_partition.cpp).
  static void cutRegions(const std::vector<ConstraintRow>& rows, const std::vector<SolverBodyState>& bodies,
                         PgsPartition& partition);
  /// The boundary's phases (PgsPartition::boundaryPhases; pgs_partition.cpp).
  static void splitBoundary(const std::vector<ConstraintRow>& rows, const std::vector<SolverBodyState>& bodies,
                            PgsPartition& partition);
  /// One range of the shock pass swept to convergence (shockPass's per-range body).
  static void shockRange(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies,
                         const ShockRange& sr, int maxSweeps, const PgsBlocks* blocks);
  /// One support of the shock pass (a manifold's normal block and its centre friction rows) solved exactly on
  /// the free body when the solution lies inside the bounds (pgs.cpp); false: nothing changed, sweep it.
  static bool solveSupportExactly(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies,
                                  const ShockRange& sr, const PgsBlocks& blocks);
};

}  // namespace scree::detail
