// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// GranularStage: the particle path of Simulation::stepForward after collision (internal to the solver module).
// The particle contact lists come from the collide stage (ParticleCollider, collide_stage.cpp); this stage
// turns them into contact units, solves and integrates them. It includes no collide header: what it needs of a
// contact's geometry (body, material, rolling radius, id) arrives as a ParticleGeometrySide per contact.
//
// Stages, called by Simulation's stages in step order:
//   applyForces  free velocities v += h g (the start-of-step velocities are kept for the rows)
//   buildRows    one contact unit per particle contact point: a SPOOK normal row (contact_law.h, the same law
//                as rigid contacts), two friction rows (projected cone, bound mu * normal impulse), and with
//                rolling resistance two angular rows (disc bound coefficient * r_eff * normal impulse).
//                Parameters come from the MaterialManager exactly as for rigid contacts (explicit contact
//                material, else the combination rules). Adhesion: the normal impulse may pull down to
//                -adhesiveForce * h and the rest overlap is the adhesive overlap. Speculative contacts (gap > 0):
//                the row only forbids closing more than the gap in one step. Warm start from last step's
//                impulses keyed by particle slots (stable across destroy of other particles and reorder) and
//                geometry id + feature.
//   sweep        one projected Gauss-Seidel sweep, parallel over spatial slabs: the cloud is cut into up to 64
//                slabs along its longest axis, each at least one grid cell wide, and a unit belongs to the lower
//                slab of its particles, so units of two even slabs (or two odd slabs) never share a particle.
//                Even slabs run in parallel (OpenMP, one thread per slab, serial Gauss-Seidel inside), then odd
//                slabs; units touching a dynamic rigid body run serially last. The partition depends on positions
//                only, so results are bit-identical for any thread count, and a sweep costs two barriers (the
//                reason for slabs rather than a per-contact graph colouring, docs/solver-internals.md). Small
//                or narrow systems (< 4 slabs or < 2048 units) run serially. Sweeps alternate forward /
//                backward (symmetric Gauss-Seidel, as the rigid PGS).
//                Centred pairs: the collider puts a particle pair's point on the line of centres, so the arms
//                lie on n (r_a = -l_a n, r_b = l_b n); such units (detected to 1e-9 relative, a listener may move
//                the point) are swept by solveCentred, the same law without the normal row's zero angular terms
//                and with the tangents' angular parts as multiples of the basis (about half the arithmetic;
//                docs/terrain.md, "Digging cost").
//                Four-wide sweep (where the CPU has AVX2): each slab's units are swept in dependency-level order
//                and centred units of one level, which share no particle, four at a time in SIMD lanes; the
//                result is the scalar sweep's bit for bit (the .cpp's "Four-wide sweep" says why; memory, not
//                arithmetic, bounds it, so the packets are prefetched). Where the CPU has AVX-512, two packets of
//                a level are solved at once in the eight lanes of 512-bit registers (the .cpp's "Eight-wide
//                sweep"), again bit for bit.
//   integrate    x += h v for live particles; a particle whose velocity or position turns non-finite is
//                reported by id, keeps its last position and is stopped. Clusters joined by glued DIRECT bonds
//                move by their exactly integrated rigid motion first (integrateBondedLumps, below).
//   store        forces into the contact lists, impulses into the warm-start cache.
//
// DIRECT mode (AGX manual: particle solve type agx::FrictionModel::DIRECT, with infinite friction and adhesion
// and zero adhesive overlap a stiff, glued lump): a unit whose resolved contact material's solve type is not
// ITERATIVE (DIRECT, SPLIT or DIRECT_AND_ITERATIVE; needs SuiteSparse, else every unit stays iterative) is
// put in its own range after the serial set by partition, and the sweeps and the shock pass skip it. In
// the solve stage, after prepare (warm start), appendDirectRows appends one SolverBodyState per particle of
// such units after the rigid bodies and the units' rows as ConstraintRows: the normal row with the unit's SPOOK
// rhs, e and lower bound (infinite adhesion: unbounded), two friction rows scaled by the normal row
// (normalRow / mu; infinite mu: unbounded) and the two rolling rows if any. They carry the material's solve
// type and the friction flag, so they are classified exactly like rigid contact rows: DIRECT units entirely in
// the direct set; SPLIT and DIRECT_AND_ITERATIVE units with the normal direct and friction/rolling swept by
// the rigid PgsSolver in the hybrid rounds. The rigid and particle direct rows are solved by one DirectSolver
// call (a lump resting on DIRECT rigid rows couples); a lump whose rows are all equalities is one
// factorisation and no pivot. finishDirect copies the impulses back into the units (warm start, storeResults
// and contact forces unchanged) and the velocities into the particle arrays, and removes the appended rows and
// bodies. Then the iterative units are swept as before, with the direct impulses held. With iterative rigid
// rows present the hybrid alternation applies (Solver::setNumHybridRounds direct solves per step). Without
// DIRECT-mode units nothing of this runs: the cost is one comparison per unit in partition.
// Glued lumps (some unit of solve type DIRECT, with iterative units besides: the terrain's DIRECT particle mode,
// whose bucket and terrain contacts are ITERATIVE): the solve stage alternates the direct solve with particle
// sweeps, copying velocities between the appended bodies and the particle arrays (directToParticles,
// particlesToDirect), and ends with the direct solve (solve_stage.cpp, lumpPath). A glued bond rests at the
// overlap it formed with and is captured inelastically in the step it forms (bondRest_ below).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "scree/core/granular_body_system.h"
#include "scree/core/material.h"
#include "scree/core/particle_contact.h"
#include "scree/core/rigid_body.h"
#include "scree/solver/constraint_row.h"
#include "scree/solver/pgs.h"
#include "scree/solver/solver.h"

namespace scree::detail {

/// What the particle rows need of the geometry of one particle-geometry contact (filled by the collide stage).
struct ParticleGeometrySide {
  const RigidBody* body = nullptr;  ///< the geometry's body, or null
  const Material* material = nullptr;
  Real rollingRadius = 0;           ///< m, 0: the shape does not roll
  uint32_t geometryId = 0;
};

/// The particle contacts of this step as the collide stage found them (listeners may have modified them).
struct ParticleContactLists {
  std::vector<ParticleContact>* particleParticle = nullptr;
  std::vector<ParticleContact>* particleGeometry = nullptr;
  const std::vector<ParticleGeometrySide>* geometrySides = nullptr;  ///< one per particleGeometry contact
  Real cellSize = 0;  ///< grid cell of the collision: no particle pair in contact is farther apart
};

class GranularStage {
 public:
  /// Steps between locality reorders of the particle arrays (done by the collide stage).
  static constexpr int kReorderInterval = 50;

  /// True when there is anything for the particle path to do this step.
  bool active(const GranularBodySystem& ps) const { return ps.size() > 0 || !units_.empty(); }

  /// Free velocities v += h g of the particles; the start-of-step velocities are kept for buildRows.
  void applyForces(GranularBodySystem& ps, const Vec3& gravity, Real h);
  /// The contact units of `contacts` (after applyForces). solverIndexOf maps a body to its index in `bodies`
  /// (-1 when not in the simulation).
  void buildRows(GranularBodySystem& ps, const ParticleContactLists& contacts, const MaterialManager& materials,
                 const Solver& solver, std::vector<SolverBodyState>& bodies,
                 const std::function<int(const RigidBody*)>& solverIndexOf, const Vec3& gravity, Real h);
  /// Applies the warm-start impulses.
  void prepare(GranularBodySystem& ps, std::vector<SolverBodyState>& bodies);
  /// One sweep; `backward` reverses the order. Returns the largest |delta lambda|.
  Real sweep(GranularBodySystem& ps, std::vector<SolverBodyState>& bodies, bool backward);
  /// Shock propagation for piles (Guendelman, Bridson & Fedkiw 2003, as the rigid PgsSolver::shockPass): the
  /// units whose normal has a component along `up` (|n . up| > 0.3), and particle contacts with static or
  /// kinematic geometry, are solved once more in order of the height of their lower side, each with the
  /// lower particle held immovable, so a column's weight is carried from the ground up within one step
  /// instead of being propagated by a few Gauss-Seidel sweeps. Serial (deterministic). `sweeps` passes.
  void shockPass(GranularBodySystem& ps, std::vector<SolverBodyState>& bodies, const Vec3& up, int sweeps);
  /// True when some particle touches a dynamic rigid body (then Simulation interleaves the rigid sweeps).
  bool coupled() const { return !slabStart_.empty() && iterativeEnd() > slabStart_[size_t(numSlabs_)]; }
  bool hasUnits() const { return !units_.empty(); }

  // ---- DIRECT mode (see the header comment) -------------------------------------------------------------------
  /// Units whose contact material's solve type is not ITERATIVE (always 0 without SuiteSparse).
  size_t numDirectUnits() const { return units_.empty() ? 0 : units_.size() - iterativeEnd(); }
  bool hasDirectUnits() const { return numDirectUnits() > 0; }
  bool hasIterativeUnits() const { return !units_.empty() && iterativeEnd() > 0; }
  /// Appends one solver body per particle of a DIRECT-mode unit to `bodies` (velocities copied from the particle
  /// arrays, which must already hold the warm start: call prepare() first) and the units' rows to `rows`, with
  /// lambda = 0 so that PgsSolver::prepare does not apply the warm start a second time.
  void appendDirectRows(const GranularBodySystem& ps, std::vector<ConstraintRow>& rows,
                        std::vector<SolverBodyState>& bodies);
  /// After PgsSolver::prepare: the appended rows take the units' warm-start impulses (already in the velocities).
  void loadDirectImpulses(std::vector<ConstraintRow>& rows) const;
  /// After the solve: impulses back into the units, velocities back into the particle arrays, and the appended
  /// rows and bodies removed again.
  void finishDirect(GranularBodySystem& ps, std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies);
  // ---- DIRECT lump rounds (issue 16: a dug DIRECT lump carried as one body; solve_stage.cpp, lumpPath) -------
  /// True when some DIRECT-mode unit is of solve type DIRECT (a glued particle bond of the manual's DIRECT
  /// particle mode) and iterative units exist: then the solve stage alternates the direct solve with the
  /// particle sweeps and ends with the direct solve (valid between appendDirectRows and finishDirect).
  bool needsLumpRounds() const { return glued_ && hasIterativeUnits(); }
  /// Velocities of the appended bodies into the particle arrays (before particle sweeps inside the rounds).
  void directToParticles(GranularBodySystem& ps, const std::vector<SolverBodyState>& bodies) const;
  /// Velocities of the particle arrays into the appended bodies (after the sweeps, before the next direct solve).
  void particlesToDirect(const GranularBodySystem& ps, std::vector<SolverBodyState>& bodies) const;
  // ---- DIRECT lump: rigid integration of a bonded lump's positions (issue 16, second pass) -------------------
  /// Before integrate: each cluster of particles joined by this step's glued bonds (ppRest_, >= 3 particles)
  /// moves by its rigid motion integrated exactly (centre of mass x += h v, rotation by the exact rotation of
  /// angle h|w| about the cluster's angular velocity w = I^-1 L) plus h times each particle's non-rigid velocity
  /// (x += h v on the rest); the rigid part of the velocities turns with the cluster. WHY: x += h v per particle
  /// stretches a cluster turning at w by h^2 w^2 / 2 of its size each step (a pair 0.44 m apart in a lump
  /// rocking at 0.44 rad/s: 1.2e-5 m a step, docs/terrain.md), which the bonds' SPOOK bias then pulls back over
  /// several steps. Momentum, kinetic energy and the centre of mass's path are those of x += h v; a
  /// straight chain (singular inertia) keeps x += h v.
  /// `pp` is the particle-pair list buildRows read this step. integrate then skips the particles moved here.
  void integrateBondedLumps(GranularBodySystem& ps, const std::vector<ParticleContact>& pp, Real h);
  /// Positions; non-finite particles are appended to outNonFinite (ids) with a message each.
  void integrate(GranularBodySystem& ps, Real h, std::vector<size_t>& outNonFinite, std::vector<std::string>& outMessages,
                 Real time);
  /// Forces into `contacts` (the lists buildRows read), impulses into the warm-start cache.
  void storeResults(const GranularBodySystem& ps, const ParticleContactLists& contacts, Real h);
  size_t numUnits() const { return units_.size(); }
  int numSlabs() const { return numSlabs_; }
  // ---- Vectorised centred sweep (issue 16, trench speed; see "Four-wide sweep" in the .cpp) ----------------
  /// Whether this CPU runs the four-wide (AVX2) sweep of centred units; false: every unit is swept by the scalar
  /// code in unit order. The results are bit-identical either way (the .cpp says why).
  static bool vectorSweepAvailable();
  /// Test and measurement switch (all stages of the process): false forces the scalar sweep. Default true.
  static void setVectorSweepEnabled(bool on);
  /// Units put into packets since the process started, over all stages (a test's evidence that the four-wide
  /// path ran).
  static uint64_t packedUnitsTotal();
  /// Whether the sweep solves pairs of packets in the eight lanes of AVX-512 registers (the .cpp's "Eight-wide
  /// sweep"; needs vectorSweepAvailable()); bit-identical to the four-wide and the scalar sweep.
  static bool avx512SweepAvailable();
  /// Test and measurement switch: false keeps the four-wide kernel on an AVX-512 CPU. Default true.
  static void setAvx512SweepEnabled(bool on);
  /// Unit visits solved by the eight-wide kernel since the process started (a test's evidence that it ran).
  static uint64_t wideUnitsTotal();

 private:
  // One contact point between particle a and particle b or a geometry (its rigid body index `body`, -1 none).
  struct Unit {
    uint32_t a = 0;
    int32_t b = -1;       // particle, or -1
    int32_t body = -1;    // rigid solver body for geometry contacts, or -1
    uint32_t src = 0;     // index into the collider's pp (b >= 0) or pg list
    Vec3 n = Vec3::Zero(), t1 = Vec3::Zero(), t2 = Vec3::Zero();
    Vec3 ra = Vec3::Zero(), rb = Vec3::Zero();  // contact point relative to a's centre and b's centre / body's cm
    Real kN = 0, kT1 = 0, kT2 = 0, kR = 0;     // 1 / (J M^-1 J^T + e) of normal, tangents, rolling
    Real rhsN = 0, eN = 0, loN = 0, eT = 0, mu = 0, rollMu = 0;
    Real rhsT1 = 0, rhsT2 = 0;  // friction targets: the surface velocity along t1, t2 (0 unless overridden)
    Real lN = 0, lT1 = 0, lT2 = 0, lR1 = 0, lR2 = 0;
    Real impact = 0;      // approach speed of a speculative stop this step, remembered for next step's bounce
    // Centred pair (particle-particle with the point on the line of centres, as the collider makes it):
    // ra = -la n, rb = lb n exactly, so the normal row has no angular part and n x t2 = -sigma t1,
    // n x t1 = sigma t2; solveCentred uses these forms.
    Real la = 0, lb = 0, sigma = 0;
    bool centred = false;
    bool flip = false;    // a's slot is the higher one of the pair (warm-start vectors are stored for the lower)
    uint8_t solveType = FrictionModel::ITERATIVE;  // of the contact material; not ITERATIVE: DIRECT mode
  };
  /// End of the units the particle sweeps and the shock pass visit; the DIRECT-mode units follow.
  uint32_t iterativeEnd() const { return slabStart_[size_t(numSlabs_) + 1]; }
  struct CacheEntry {
    uint64_t key;
    uint32_t feature;
    Real normal;
    Vec3 friction, rolling;  // on the lower slot (pp) or on the particle (pg)
    Real impact;
  };
  // The warm-start caches are searched through a sorted array of 16-byte keys (a quarter of the entries'
  // size, so the binary search stays in the cache), each pointing at its entry, stored in storeResults order.
  struct CacheKey {
    uint64_t key;
    uint32_t feature;
    uint32_t entry;  // index into the entries; the last tie break, so the order is total
    bool operator<(const CacheKey& o) const {
      return key != o.key ? key < o.key : feature != o.feature ? feature < o.feature : entry < o.entry;
    }
  };
  /// The entry of (key, feature), the first in key order if there are several; null if none.
  static const CacheEntry* find(const std::vector<CacheKey>& keys, const std::vector<uint32_t>& first,
                                const std::vector<CacheEntry>& entries,
                                uint64_t key, uint32_t feature);
  /// One Gauss-Seidel update of unit u (normal, then friction disc, then rolling disc). kFrozen < 0: both
  /// sides move (the sweeps; |delta lambda| goes into maxDelta). kFrozen = 0 or 1: side A or B is held
  /// immovable (the shock pass), the effective masses are those of the free particle alone and rolling is
  /// left to the sweeps.
  template <int kFrozen>
  void solveUnit(Unit& u, std::vector<Vec3>& v, std::vector<Vec3>& w, const std::vector<Real>& invM,
                 const std::vector<Real>& invI, std::vector<SolverBodyState>& bodies, Real& maxDelta) const;
  /// solveUnit<kFrozen> of a centred unit (the same law, with the zero angular terms of the normal row dropped).
  template <int kFrozen>
  void solveCentred(Unit& u, Vec3* v, Vec3* w, const Real* invM, const Real* invI, Real& maxDelta) const;
  /// Slabs from plan_ (see buildRows): slabStart_, numSlabs_, and unitDest_ (each unit's index in units_).
  void partition(const GranularBodySystem& ps, Real cellSize);

  std::vector<Unit> units_;          // all units: the slabs in order, then the serial set, then DIRECT mode
  // [numSlabs + 3] ranges into units_: numSlabs slabs, the serial set, the DIRECT-mode units.
  std::vector<uint32_t> slabStart_;
  int numSlabs_ = 1;
  std::vector<Real> invInertia_;     // [size()] 1 / (0.4 m r^2)
  std::vector<Vec3> vStart_;         // [size()] velocities at the start of the step (before applyForces)
  // Per-step buffers, kept to reuse their memory.
  // What the partition needs of a unit (in contact order), and where the unit is built in units_.
  struct UnitPlan {
    uint32_t a = 0;
    int32_t b = -1, body = -1;
    bool direct = false;  // the contact material's solve type is not ITERATIVE (DIRECT mode)
  };
  std::vector<UnitPlan> plan_;
  std::vector<const CacheEntry*> warm_;  // [pp + pg contacts] the warm-start entry of each contact, or null
  std::vector<uint32_t> unitDest_;
  std::vector<uint16_t> slabOf_;
  std::vector<uint32_t> slabCount_, slabCursor_;
  // Contact parameters resolved once per material pair per step.
  struct PairParams {
    Real youngsModulus = 0, damping = 0;  // of the pair's material (per-point overrides recompute the SPOOK terms)
    Real eN = 0, a = 0, upsilon = 1;      // SPOOK normal row
    Real eT = 0;                          // friction-row regularisation
    Real mu = 0, rest = 0, rolling = 0, adhF = 0, adhO = 0;
    uint8_t solveType = FrictionModel::ITERATIVE;  // ITERATIVE, or DIRECT mode (see the file comment)
  };
  static PairParams makeParams(const SurfaceParameters& s, const FrictionModel* fm, Real h);
  std::vector<PairParams> ppParams_;  // [K * K] particle material pairs
  std::vector<std::pair<std::pair<uint32_t, const Material*>, PairParams>> pgParams_;  // pairs met this step
  std::vector<uint32_t> pgParam_, pgUnit_;  // per particle-geometry contact: its pgParams_ entry and unit
  std::vector<int32_t> pgBody_;             // per particle-geometry contact: solver body, -1 none
  // (height of the lower side as an order-preserving key, unit * 2 + frozen side), and the radix sort's buffer.
  std::vector<std::pair<uint64_t, uint32_t>> shockOrder_, shockScratch_;
  std::vector<CacheEntry> ppCache_, pgCache_;
  std::vector<CacheKey> ppKeys_, pgKeys_, keyScratch_;
  // first[s] = index of the first key whose high half (a particle slot) is s; empty: binary search (see find).
  std::vector<uint32_t> ppFirst_, pgFirst_;
  /// keys = (key, feature, entry) of entries in CacheKey order.
  void indexKeys(const std::vector<CacheEntry>& entries, std::vector<CacheKey>& keys);
  // DIRECT mode, valid between appendDirectRows and finishDirect.
  size_t rowBase_ = 0, bodyBase_ = 0;  // sizes of rows / bodies before the append
  std::vector<int32_t> extBody_;       // [size()] solver body of a particle, -1 none
  std::vector<uint32_t> extParticle_;  // particle of each appended body
  std::vector<uint32_t> directRow_;    // first row of each DIRECT-mode unit (normal, [2 friction], [2 rolling])
  bool glued_ = false;                 // some appended unit is of solve type DIRECT (needsLumpRounds)
  // Glued bonds (infinite adhesion, the DIRECT particle mode; issue 16). DESIGN: a bond rests at the overlap
  // it had when it formed, not at the material's adhesive overlap: particles of different dig steps (two
  // lattices) or a lump landing bond at whatever overlap they meet, and pushing each such bond to one common
  // rest with its SPOOK bias, against the bonds around it, made a carried lump creep by mm per second
  // (docs/terrain.md). Kept like the warm start, by the pair's slot key; a pair that leaves contact or opens a
  // gap (no longer a bond) forgets it.
  std::vector<std::pair<uint64_t, Real>> bondRest_;  // (pair key, rest overlap), sorted; from storeResults
  std::vector<Real> ppRest_;                         // [pp contacts] this step's rest, NaN: not a glued bond
  std::vector<char> lumpMoved_;  // [dense] moved by integrateBondedLumps this step (integrate skips it)
  static bool anyGluedMaterial(const std::vector<PairParams>& ppParams, size_t K);
  Real bondRestOf(uint64_t key, Real depth, bool& found) const;  // the remembered rest of the pair, else `depth`

  // ---- Four-wide sweep of centred units (issue 16, trench speed; the .cpp's "Four-wide sweep") ---------------
 public:
  // Four centred units with 8 distinct particles, lane-interleaved (field f of lane j at f[f][j]): the unit data
  // the sweep reads (a centred unit's two tangent gains are equal: one kKT; packed units have no surface
  // velocity, so the friction targets are zero), and the impulses (the authoritative copy while
  // packed_, written back to the units by unpack()).
  enum PacketField : int {
    kNx, kNy, kNz, kT1x, kT1y, kT1z, kT2x, kT2y, kT2z, kSigma, kLa, kLb, kKN, kKT, kRhsN, kEN, kLoN, kET, kMu,
    kRollMu, kKR, kLN, kLT1, kLT2, kLR1, kLR2, kNumPacketFields
  };
  struct alignas(32) Packet {
    uint32_t a[4], b[4];  // first: the kernel reads them first (then the particles' velocities)
    uint32_t unit[4], pad[4];
    double f[kNumPacketFields][4];
  };

 private:
  std::vector<Packet> packets_;  // [0, numPackets_) in use
  size_t numPackets_ = 0;
  // Per slab, the sweep order as items: >= 0 a unit of units_ (scalar), < 0 the packet -1 - item.
  std::vector<int32_t> items_;
  std::vector<uint32_t> itemStart_;          // [numSlabs + 1] ranges into items_
  std::vector<uint32_t> levelOf_, lastLevel_, stampOf_, levelCount_, levelOrder_;
  std::vector<char> packable_;
  uint32_t stamp_ = 0;
  bool scheduleStale_ = true;  // buildRows made new units: the schedule and packets are rebuilt at the next sweep
  bool packed_ = false;        // the packets hold the current impulses of their units
  // What the schedule needs of each unit (in units_ order), written by buildRows.
  struct SchedUnit {
    uint32_t a = 0;
    int32_t b = -1;
    uint32_t packable = 0;
  };
  std::vector<SchedUnit> schedUnit_;
  static bool packable(const Unit& u);  // may go into a packet (see the .cpp)
  void buildSchedule(const GranularBodySystem& ps);
  void pack(const GranularBodySystem& ps);  // unit data (and impulses) into packets_
  void unpack();                            // packets' impulses back into units_
};

}  // namespace scree::detail
