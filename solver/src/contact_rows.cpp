// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Contact rows stage (layout and warm start: contact_rows.h; the normal-row law: contact_law.h), and the
// particle rows stage, which hands this step's particle contacts to the particle stage (granular_stage.h).
#include "contact_rows.h"

#include <algorithm>
#include <cmath>

#include "scree/core/parallel.h"

#include "contact_law.h"
#include "friction_anchor.h"
#include "rolling_radius.h"
#include "step_stages.h"

namespace scree::detail {

namespace {
constexpr uint32_t kMaxBlockPoints = 16;  ///< largest manifold solved as a block (pgs.cpp kMaxNormalBlock)

/// What contactRows does with one contact: COUNT its rows and points only; APPEND them to the step's arrays
/// (the serial build); FILL them at the cursor's places in arrays already sized (the parallel build).
enum class RowMode { COUNT, APPEND, FILL };

/// The step's row-build settings, read once.
struct RowBuildSettings {
  Real h;
  ContactLawSettings law;
  bool warm, anchors, useBlock, useManifoldFriction;
};

/// Where a contact's rows, points and coupling go, and what the build tallies; one per thread.
struct RowCursor {
  uint32_t row = 0, point = 0, coupling = 0;
  size_t warmCursor = 0;  ///< WarmStartCache::pairRangeAscending's
  ChunkTally tally;       ///< points, warm-started points, solved contacts, non-iterative rows; a layout mismatch
  std::vector<FrictionAnchorCache::Active>* anchors = nullptr;  ///< this thread's anchored manifolds
  /// FILL on a guessed layout (last step's counts): the contact's expected row and point counts. A contact whose
  /// counts differ writes nothing and sets tally.mismatch.
  bool verify = false;
  uint32_t expectRows = 0, expectPoints = 0;
};

/// The rows of contact ci: returns how many rows and contact points it takes ({0, 0}: not solved) and, unless
/// mode is COUNT, writes them (rows, points, coupling, anchor) at the cursor and advances it. A contact's rows
/// depend only on the contact, its bodies and the caches, never on the other contacts: so the parallel build
/// gives the serial build's bits.
// A template on the mode, so that the serial build (APPEND) carries no test of the others.
template <RowMode mode>
std::pair<uint32_t, uint32_t> contactRows(SimulationState& s, uint32_t ci, const RowBuildSettings& k, RowCursor& cur) {
  const Vec3 zero = Vec3::Zero();
  GeometryContact& c = s.contacts[ci];
  if (!c.isEnabled() || c.isSensor()) return {};
  const int ia = s.solverIndex(c.rigidBody(0)), ib = s.solverIndex(c.rigidBody(1));
  const bool dynA = ia >= 0 && s.sb[ia].invMass > 0, dynB = ib >= 0 && s.sb[ib].invMass > 0;
  if (!dynA && !dynB) return {};
  const SurfaceParameters& mat = c.material();
  const FrictionModel* fm = c.frictionModel();
  const FrictionModel::Type ftype = fm ? fm->getType() : FrictionModel::ITERATIVE_PROJECTED_CONE;
  const FrictionModel::SolveType solveType = fm ? fm->getSolveType() : FrictionModel::ITERATIVE;

  // Rolling resistance: resisting torque about the tangents bounded by coefficient * r_eff * normal force,
  // r_eff the harmonic combination of the rolling radii (the single radius against a flat shape).
  Real rollMu = 0;
  if (mat.getRollingResistanceCoefficient() > 0) {
    const Real r0 = rollingRadius(c.geometry(0)), r1 = rollingRadius(c.geometry(1));
    const Real reff = (r0 > 0 && r1 > 0) ? r0 * r1 / (r0 + r1) : std::max(r0, r1);
    rollMu = mat.getRollingResistanceCoefficient() * reff;
  }
  // Count active points to lay out rows: [friction and rolling rows of all points][normal rows].
  auto& pts = c.points();
  uint32_t nActive = 0, nFriction = 0;
  for (const ContactPoint& p : pts) {
    if (!p.enabled) continue;
    ++nActive;
    const Real mu = p.frictionCoefficient >= 0 ? p.frictionCoefficient : mat.getFrictionCoefficient();
    if (mu > 0) nFriction += 2;
    if (rollMu > 0) nFriction += 2;
  }
  if (nActive == 0) return {};
  // Manifold treatment (contact_rows.h, DESIGN): the normal block needs one common normal; manifold friction
  // also needs one friction law for all points.
  auto muOf = [&mat](const ContactPoint& p) {
    return p.frictionCoefficient >= 0 ? p.frictionCoefficient : mat.getFrictionCoefficient();
  };
  const ContactPoint* first = nullptr;
  const bool useBlock = k.useBlock, useManifoldFriction = k.useManifoldFriction;
  bool block = (useBlock || useManifoldFriction) && nActive >= 2 && nActive <= kMaxBlockPoints &&
               solveType == FrictionModel::ITERATIVE;
  bool manifoldFriction = useManifoldFriction && rollMu == 0 && ftype != FrictionModel::BOX;
  Vec3 centre = zero;
  // The normal block solves the manifold on its centre-and-tilt coordinates (pgs.cpp), which is the exact block
  // solution only when the rows' compliances are equal: with per-point Young's moduli or damping times (the
  // terrain's deformer contacts mix points 1000x softer than the rest) the affine load it imposes would load
  // the soft points like the stiff ones. Such manifolds keep their rows one by one.
  bool sameLaw = true;
  for (const ContactPoint& p : pts) {
    if (!p.enabled) continue;
    if (!first) first = &p;
    centre += p.point;
    sameLaw = sameLaw && p.youngsModulus == first->youngsModulus && p.damping == first->damping;
    block = block && p.normal.dot(first->normal) > 1 - 1e-9;
    manifoldFriction = manifoldFriction && muOf(p) > 0 && muOf(p) == muOf(*first) &&
                       p.frictionDirection == zero && p.surfaceVelocity == first->surfaceVelocity;
  }
  manifoldFriction = manifoldFriction && block;
  // The count needs the principal axes of no manifold: only whether manifold friction has a lever (below).
  if constexpr (mode == RowMode::COUNT)
    if (!manifoldFriction) return {nFriction + nActive, nActive};
  // The points' offsets from the centre in the tangent plane, along the principal axes of their spread, scaled
  // so that sum(u^2) = sum(v^2) = nActive (a degenerate axis -- collinear or coincident points -- stays 0).
  Real blockU[kMaxBlockPoints], blockV[kMaxBlockPoints];  // filled for the active points when block
  Vec3 arm[kMaxBlockPoints];
  Vec3 mt1 = zero, mt2 = zero;
  Real rEff = 0, sumR2 = 0;
  if (block) {
    const Vec3 n0 = first->normal;
    centre /= Real(nActive);
    orthonormalBasis(n0, mt1, mt2);
    Real a = 0, b = 0, cc = 0;
    uint32_t k = 0;
    for (const ContactPoint& p : pts) {
      if (!p.enabled) continue;
      const Vec3 d = p.point - centre;
      arm[k] = d - n0.dot(d) * n0;
      const Real x = arm[k].dot(mt1), y = arm[k].dot(mt2);
      a += x * x;
      b += x * y;
      cc += y * y;
      rEff += arm[k].norm();
      sumR2 += arm[k].squaredNorm();
      ++k;
    }
    rEff /= Real(nActive);
    if constexpr (mode == RowMode::COUNT)
      return {rEff > 0 && sumR2 > 0 ? 3 + nActive : nFriction + nActive, nActive};
    // The principal axis at theta = atan2(2b, a - cc) / 2, its cosine and sine from the double angle's by the
    // half-angle formulas (the larger of the two by a square root, the other from sin 2theta = 2 sin cos):
    // no atan2, sin or cos per manifold (libm's sincos was 1 % of pyramid20's step, issue 18).
    const Real r2 = std::sqrt((a - cc) * (a - cc) + 4 * b * b);
    Real ct = 1, st = 0;
    if (r2 > 0) {
      const Real c2 = (a - cc) / r2, s2 = 2 * b / r2;
      if (c2 >= 0) {
        ct = std::sqrt(0.5 * (1 + c2));
        st = s2 / (2 * ct);
      } else {
        st = std::copysign(std::sqrt(0.5 * (1 - c2)), s2);
        ct = s2 / (2 * st);
      }
    }
    const Vec3 e1 = ct * mt1 + st * mt2, e2 = n0.cross(e1);
    Real su = 0, sv = 0;
    for (uint32_t i = 0; i < nActive; ++i) {
      blockU[i] = arm[i].dot(e1);
      blockV[i] = arm[i].dot(e2);
      su += blockU[i] * blockU[i];
      sv += blockV[i] * blockV[i];
    }
    const Real spread = a + cc;
    const Real scaleU = su > 1e-10 * spread && spread > 0 ? std::sqrt(Real(nActive) / su) : 0.0;
    const Real scaleV = sv > 1e-10 * spread && spread > 0 ? std::sqrt(Real(nActive) / sv) : 0.0;
    for (uint32_t i = 0; i < nActive; ++i) {
      blockU[i] *= scaleU;
      blockV[i] *= scaleV;
    }
    // Friction at the centre needs a lever for the twist row: points spread around the centre.
    manifoldFriction = manifoldFriction && rEff > 0 && sumR2 > 0;
  }
  if (manifoldFriction) nFriction = 3;
  const uint32_t numRows = nFriction + nActive;
  if constexpr (mode == RowMode::COUNT) return {numRows, nActive};
  if constexpr (mode == RowMode::FILL)
    if (cur.verify && (numRows != cur.expectRows || nActive != cur.expectPoints)) {
      cur.tally.mismatch = true;
      return {};
    }
  if (solveType != FrictionModel::ITERATIVE) cur.tally.nonIterative = true;
  const uint64_t pair = contactPairKey(c);
  const Vec3 xa = ia >= 0 ? BodyAccess::cm(*s.bodies[ia]) : zero;
  const Vec3 xb = ib >= 0 ? BodyAccess::cm(*s.bodies[ib]) : zero;
  // Start-of-step and free (after forces) velocities of both sides.
  const Vec3 va0 = ia >= 0 ? s.vStart[ia] : zero, wa0 = ia >= 0 ? s.wStart[ia] : zero;
  const Vec3 vb0 = ib >= 0 ? s.vStart[ib] : zero, wb0 = ib >= 0 ? s.wStart[ib] : zero;
  const Vec3 vaF = ia >= 0 ? s.sb[ia].v : zero, waF = ia >= 0 ? s.sb[ia].w : zero;
  const Vec3 vbF = ib >= 0 ? s.sb[ib].v : zero, wbF = ib >= 0 ? s.sb[ib].w : zero;
  ++cur.tally.numSolved;
  // The new rows are copies of the default row (constraint_row.h), filled in place below (setPointJacobian,
  // contact_law.h).
  if constexpr (mode == RowMode::APPEND) {
    cur.row = uint32_t(s.rows.size());
    s.rows.resize(s.rows.size() + numRows, defaultConstraintRow());
  } else {
    std::fill(s.rows.begin() + cur.row, s.rows.begin() + cur.row + numRows, defaultConstraintRow());
  }
  const int32_t base = int32_t(cur.row);
  int32_t nextFriction = base;
  int32_t nextNormal = base + int32_t(nFriction);
  // The serial build appends its point records and coupling; the parallel build writes them at the places the
  // count gave.
  auto putPoint = [&s, &cur](const PointRows& pr) {
    if constexpr (mode == RowMode::APPEND) s.pointRows.push_back(pr);
    else s.pointRows[cur.point++] = pr;
  };
  const CouplingRange coupling{ia, ib, uint32_t(base), numRows, false};
  if constexpr (mode == RowMode::APPEND) s.couplings.push_back(coupling);
  else s.couplings[cur.coupling++] = coupling;
  // Weight-based normal impulse estimate for box friction on new contacts: the lighter dynamic body's weight.
  const Real massA = dynA ? 1.0 / s.sb[ia].invMass : 0, massB = dynB ? 1.0 / s.sb[ib].invMass : 0;
  const Real weightImpulse =
      ((dynA && dynB) ? std::min(massA, massB) : std::max(massA, massB)) * s.gravity.norm() * k.h / Real(nActive);

  const int32_t firstNormal = nextNormal;
  uint32_t activeIndex = 0;
  const auto warmRange = k.warm ? s.warmStart.pairRangeAscending(pair, cur.warmCursor)
                              : std::pair<const WarmStartCache::Entry*, const WarmStartCache::Entry*>{};
  Vec3 warmFriction = zero;  // manifold friction: sum of the points' cached friction impulses
  Real warmTwist = 0;        // and their moment about the centre along the normal
  for (uint32_t pi = 0; pi < pts.size(); ++pi) {
    ContactPoint& p = pts[pi];
    if (!p.enabled) continue;
    ++cur.tally.numPoints;
    const uint32_t ak = activeIndex++;
    const Vec3& n = p.normal;
    const Vec3 ra = p.point - xa, rb = p.point - xb;
    const WarmStartCache::Entry* ce = k.warm ? WarmStartCache::find(warmRange, p.featureId, p.point) : nullptr;
    if (ce) ++cur.tally.numWarm;

    // --- normal row (contact_law.h) ---
    ConstraintRow& r = s.rows[nextNormal];
    setPointJacobian(r, ia, ib, ra, rb, n);
    r.solveType = solveType;
    // The approach speeds from the Jacobian's values in registers, not read back from the row just stored:
    // that read waited on the stores (perf: a tenth of buildContactRows' samples on pyramid20, issue 18). Same
    // products in the same order as J v, so the same bits.
    const Vec3 jAngA = ra.cross(n), jLinB = -n, jAngB = -rb.cross(n);
    const Real E = p.youngsModulus > 0 ? p.youngsModulus : mat.getYoungsModulus();
    const Real tau = p.damping >= 0 ? p.damping : mat.getDamping();
    NormalContactState cs;
    cs.depth = p.depth;
    cs.vn0 = n.dot(va0) + jAngA.dot(wa0) + jLinB.dot(vb0) + jAngB.dot(wb0);
    cs.vnFree = n.dot(vaF) + jAngA.dot(waF) + jLinB.dot(vbF) + jAngB.dot(wbF);
    cs.rememberedImpact = ce ? ce->impactSpeed : 0;
    // Adhesion: the contact's adhesive force is shared by its points; while the pair is in contact (points
    // within the contact margin) the row may pull with up to that force towards the rest overlap.
    cs.adhesiveForce = mat.getAdhesiveForce() / Real(nActive);
    cs.adhesiveOverlap = mat.getAdhesiveOverlap();
    cs.restitution = p.restitution >= 0 ? p.restitution : mat.getRestitution();
    const NormalRowCoefficients nr = contactNormalRow(k.law, contactSpook(k.h, E, tau), cs);
    r.rhs = nr.rhs;
    r.e = nr.e;
    r.lo = nr.lo;
    r.hi = 1e300;
    r.lambda = ce ? std::max(ce->normal, r.lo) : 0.0;
    if (block && useBlock && sameLaw) {
      r.blockBegin = firstNormal;
      r.blockCount = int32_t(nActive);
      r.blockU = blockU[ak];
      r.blockV = blockV[ak];
    }
    if (manifoldFriction) {
      if (ce) {
        warmFriction += ce->friction;
        warmTwist += first->normal.dot(arm[ak].cross(ce->friction));
      }
      PointRows pr{ci, pi, nextNormal, base, mt1, mt2, nr.impactSpeed};
      pr.twist = base + 2;
      pr.share = 1.0 / Real(nActive);
      pr.twistArm = first->normal.cross(arm[ak]) / sumR2;
      putPoint(pr);
      ++nextNormal;
      continue;
    }

    // --- friction rows ---
    const Real mu = p.frictionCoefficient >= 0 ? p.frictionCoefficient : mat.getFrictionCoefficient();
    int32_t t1Index = -1;
    Vec3 t1, t2;
    orthonormalBasis(n, t1, t2);
    if (p.frictionDirection != Vec3::Zero()) {
      // A listener's primary direction (e.g. a tire's rolling direction): its tangential part, if any.
      const Vec3 d = p.frictionDirection - n.dot(p.frictionDirection) * n;
      const Real len = d.norm();
      if (len > 1e-9 * p.frictionDirection.norm()) {
        t1 = d / len;
        t2 = n.cross(t1);
      }
    }
    if (mu > 0) {
      t1Index = nextFriction;
      const Real eVisc = spookVelocityRegularisation(k.h, mat.getSurfaceViscosity());
      const Real lnEst = ce && ce->normal > 0 ? ce->normal : weightImpulse;
      for (int k = 0; k < 2; ++k) {
        const Vec3& t = k == 0 ? t1 : t2;
        ConstraintRow& f = s.rows[nextFriction + k];
        setPointJacobian(f, ia, ib, ra, rb, t);
        f.rhs = p.surfaceVelocity.dot(t);
        f.e = eVisc;
        f.mu = mu;
        f.solveType = solveType;
        f.friction = true;
        f.lambda = ce ? ce->friction.dot(t) : 0.0;
        switch (ftype) {
          case FrictionModel::BOX: {
            const Real lim = std::isinf(mu) ? 1e300 : mu * lnEst;
            f.lo = -lim;
            f.hi = lim;
            f.lambda = std::clamp(f.lambda, f.lo, f.hi);
            break;
          }
          case FrictionModel::SCALED_BOX: f.normalRow = nextNormal; break;
          case FrictionModel::ITERATIVE_PROJECTED_CONE:
            f.normalRow = nextNormal;
            if (k == 0) f.pairedRow = nextFriction + 1;
            break;
        }
      }
      nextFriction += 2;
    }
    if (rollMu > 0) {
      // Two angular rows on the relative rotation about the tangents, solved as a disc like the cone.
      for (int k = 0; k < 2; ++k) {
        const Vec3& t = k == 0 ? t1 : t2;
        ConstraintRow& f = s.rows[nextFriction + k];
        f.bodyA = ia;
        f.bodyB = ib;
        f.jAngA = t;
        f.jAngB = -t;
        f.mu = rollMu;
        f.normalRow = nextNormal;
        f.solveType = solveType;
        f.friction = true;
        if (k == 0) f.pairedRow = nextFriction + 1;
      }
      nextFriction += 2;
    }
    putPoint(PointRows{ci, pi, nextNormal, t1Index, t1, t2, nr.impactSpeed});
    ++nextNormal;
  }
  if (manifoldFriction) {
    // [t1, t2, twist] at the manifold's centre, bounded by the sum of its normal impulses (contact_rows.h).
    const Real mu = muOf(*first);
    const Real eVisc = spookVelocityRegularisation(k.h, mat.getSurfaceViscosity());
    for (int k = 0; k < 2; ++k) {
      const Vec3& t = k == 0 ? mt1 : mt2;
      ConstraintRow& f = s.rows[base + k];
      setPointJacobian(f, ia, ib, centre - xa, centre - xb, t);
      f.rhs = first->surfaceVelocity.dot(t);
      f.e = eVisc / Real(nActive);  // the points' viscous compliances act in parallel
      f.mu = mu;
      f.solveType = solveType;
      f.friction = true;
      f.lambda = warmFriction.dot(t);
      f.normalRow = firstNormal;
      f.normalCount = int32_t(nActive);
      if (k == 0 && ftype == FrictionModel::ITERATIVE_PROJECTED_CONE) f.pairedRow = base + 1;
    }
    // Twist: torque about the normal. Point i slips at w r_i and its viscous row carries w r_i / e, a torque
    // w r_i^2 / e, so the points together give e_twist = e / sum(r_i^2) (rad/s per N m s).
    ConstraintRow& tw = s.rows[base + 2];
    tw.bodyA = ia;
    tw.bodyB = ib;
    tw.jAngA = first->normal;
    tw.jAngB = -first->normal;
    tw.e = eVisc / sumR2;
    tw.mu = std::isinf(mu) ? mu : mu * rEff;
    tw.solveType = solveType;
    tw.friction = true;
    tw.lambda = warmTwist;
    tw.normalRow = firstNormal;
    tw.normalCount = int32_t(nActive);
    // ---- issue 18 (friction anchors, friction_anchor.h): the position term of a sticking manifold ----
    if (k.anchors && first->surfaceVelocity == zero)
      anchorManifoldFriction(s, pair, ia, ib, centre, first->normal, mt1, mt2, rEff, base, base + 2,
                             first->damping >= 0 ? first->damping : mat.getDamping(), *cur.anchors);
  }
  cur.row += numRows;
  return {numRows, nActive};
}

/// The grouped build (partitioned sweeps and at least 128 contacts, with a region map from an earlier step): the
/// contacts are laid out by group, the regions' first, then the boundary's (PgsPartition), on any thread count.
bool groupedBuild(const SimulationState& s) {
  // Not tuned: pyramid20's build takes about 0.3 us per contact, so below 128 contacts the half saved (under
  // 20 us) is not much more than the build's two hand-overs to the team (a few us each in the VMs measured).
  constexpr size_t kMinContacts = 128;
  return s.solver.getUsePartitionedSweeps() && s.contacts.size() >= kMinContacts &&
         s.partition.bodyRegion.size() == s.sb.size();
}

/// Threads for the grouped build: the partitioned work's count for this step (beginPartitionedWork).
int rowBuildThreads(const SimulationState& s) {
  return std::max(1, std::min({s.partition.maxThreads, PgsPartition::kRegions, scree::getNumThreads()}));
}

/// A contact's group by the last step's region map: region r when every movable body it touches lies in r,
/// else (two regions, a body the map does not know as movable, or none) the boundary, kRegions.
int contactGroup(const SimulationState& s, uint32_t ci) {
  constexpr int kBoundary = PgsPartition::kRegions;
  const GeometryContact& c = s.contacts[ci];
  int group = -1;
  for (int k = 0; k < 2; ++k) {
    const int b = s.solverIndex(c.rigidBody(k));
    if (b < 0 || !PgsPartition::movable(s.sb[size_t(b)])) continue;
    const int r = s.partition.bodyRegion[size_t(b)];
    if (r < 0 || (group >= 0 && group != r)) return kBoundary;
    group = r;
  }
  return group < 0 ? kBoundary : group;
}

}  // namespace

void buildContactRows(SimulationState& s) {
  const Solver& solver = s.solver;
  beginPartitionedWork(s);  // the row build is the first stage of the partitioned work (sweep_threads.h)
  s.frictionAnchors.beginStep();  // issue 18 (friction anchors)
  const RowBuildSettings k{s.h,
                           {s.h, solver.getRestitutionThreshold(), solver.getMaxPenetrationRecoverySpeed()},
                           solver.getUseWarmStarting(),
                           solver.getUseFrictionAnchors(),
                           solver.getUseManifoldNormalBlock(),
                           solver.getUseManifoldFriction()};
  const uint32_t numContacts = uint32_t(s.contacts.size());
  constexpr int G = PgsPartition::kRegions + 1;  // the regions' groups, then the boundary's
  const bool grouped = groupedBuild(s);
  const int threads = grouped ? rowBuildThreads(s) : 1;
  int ran = threads;  // the fewest threads a job of the build got (one if another Simulation held the team)
  RowCursor serial;  // the one-thread builds' cursor; after the build, every contact's tallies
  s.rowGroupsReady = grouped;
  s.rowGroupThreads = threads;
  if (!grouped) {
    s.rows.clear();
    s.pointRows.clear();
    s.couplings.clear();
    serial.anchors = &s.frictionAnchors.active;
    for (uint32_t ci = 0; ci < numContacts; ++ci) contactRows<RowMode::APPEND>(s, ci, k, serial);
    s.contactLayoutValid = false;
  } else {
    // DESIGN (issue 18, two-thread scaling; docs/solver-internals.md "The contact rows by region"): the contacts
    // laid out by group, by the last step's region map (the partition keeps its cut while the scene's units stay
    // the same): region 0's contacts, region 1's, then the boundary's, each group in contact order. Region r's
    // rows then touch no movable body of the other region, so that PgsSolver::prepare can run the two regions'
    // rows on two threads and keep every body's warm-start sum in row order, and each region's rows are built
    // mostly on the thread that sweeps it. The groups' contacts are cut into runs of 16 (chunks), which the two
    // threads share from both ends (contact_rows.h forChunksFromBothEnds: thread 0 from region 0's first, thread
    // 1 from the boundary's last and then region 1's): they count the chunks' rows and points, one prefix sum
    // places every contact, and they fill the chunks in place, each chunk with its own warm-start cursor, list
    // of anchored manifolds (joined in chunk order, i.e. row order) and tallies. A contact's rows do not depend
    // on which thread writes them: the layout is the same on any thread count, so are the bits.
    for (auto& list : s.contactGroups) list.clear();
    // Last step's layout is a good guess for this step's when the contacts are the same pairs in the same order
    // (a steady scene); see the two-thread build below.
    bool samePairs = s.contactLayoutValid && s.contactLayoutPairs.size() == numContacts;
    s.contactLayoutPairs.resize(numContacts);
    for (uint32_t ci = 0; ci < numContacts; ++ci) {
      s.contactGroups[contactGroup(s, ci)].push_back(ci);
      const uint64_t pair = contactPairKey(s.contacts[ci]);
      samePairs = samePairs && s.contactLayoutPairs[ci] == pair;
      s.contactLayoutPairs[ci] = pair;
    }
    auto& layout = s.contactLayout;
    layout.resize(numContacts);
    if (threads == 1) {
      // One thread: appended group by group, the layout the two-thread build places (and the same bits).
      s.rows.clear();
      s.pointRows.clear();
      s.couplings.clear();
      serial.anchors = &s.frictionAnchors.active;
      for (int g = 0; g < G; ++g) {
        serial.warmCursor = 0;  // each group's contacts ascend
        for (const uint32_t ci : s.contactGroups[g]) {
          const uint32_t row = uint32_t(s.rows.size()), point = uint32_t(s.pointRows.size()),
                         coupling = uint32_t(s.couplings.size());
          const uint32_t numRows = contactRows<RowMode::APPEND>(s, ci, k, serial).first;
          layout[ci] = {row, point, coupling, numRows, uint32_t(s.pointRows.size()) - point};
        }
        s.rowGroupEnd[g] = uint32_t(s.rows.size());
      }
    } else {
      // The groups' contacts in runs of kChunk, shared from both ends (contact_rows.h forChunksFromBothEnds):
      // thread 0 from region 0's first, thread 1 from the boundary's last, then region 1's from its end.
      constexpr uint32_t kChunk = 16;
      auto& chunks = s.contactChunks;
      chunks.clear();
      for (int g = 0; g < G; ++g)
        for (uint32_t i = 0; i < s.contactGroups[g].size(); i += kChunk)
          chunks.push_back({uint32_t(g), i, std::min<uint32_t>(i + kChunk, uint32_t(s.contactGroups[g].size()))});
      const uint32_t numChunks = uint32_t(chunks.size());
      auto contactsOf = [&](uint32_t c, auto&& f) {
        const std::vector<uint32_t>& list = s.contactGroups[chunks[c].group];
        for (uint32_t i = chunks[c].first; i < chunks[c].last; ++i) f(list[i]);
      };
      // One prefix sum over the groups places every contact from its row and point counts (layout[ci].count,
      // .points on entry); then the rows are sized for the fill.
      auto place = [&] {
        uint32_t row = 0, point = 0, coupling = 0;
        for (int g = 0; g < G; ++g) {
          for (const uint32_t ci : s.contactGroups[g]) {
            ContactLayout& l = layout[ci];
            const uint32_t numRows = l.count, numPoints = l.points;
            l = {row, point, coupling, numRows, numPoints};
            row += numRows;
            point += numPoints;
            coupling += numRows > 0 ? 1 : 0;
          }
          s.rowGroupEnd[g] = row;
        }
        s.rows.resize(row);  // each contact writes its rows' defaults (RowMode::FILL)
        s.pointRows.resize(point);
        s.couplings.resize(coupling);
      };
      if (s.chunkAnchors.size() < numChunks) s.chunkAnchors.resize(numChunks);
      s.chunkTallies.resize(numChunks);
      // The fill; with verify, every contact (solved or not last step) checks its counts against the layout.
      auto fill = [&](bool verify) {
        bool mismatch = false;
        ran = std::min(ran, forChunksFromBothEnds(threads, numChunks, [&](uint32_t c) {
          RowCursor cur;  // on this thread's stack: the tallies are written per point (no shared cache line)
          cur.anchors = &s.chunkAnchors[c];
          cur.anchors->clear();
          cur.verify = verify;
          contactsOf(c, [&](uint32_t ci) {
            const ContactLayout& l = layout[ci];
            if (l.count == 0 && !verify) return;
            cur.row = l.row;
            cur.point = l.point;
            cur.coupling = l.coupling;
            cur.expectRows = l.count;
            cur.expectPoints = l.points;
            if (contactRows<RowMode::FILL>(s, ci, k, cur).first == 0 && l.count > 0) cur.tally.mismatch = true;
          });
          s.chunkTallies[c] = cur.tally;
        }));
        for (uint32_t c = 0; c < numChunks; ++c) mismatch = mismatch || s.chunkTallies[c].mismatch;
        return !mismatch;
      };
      // DESIGN (issue 18, two-thread scaling, stop 50; docs/solver-internals.md "The row build on last step's
      // layout"): the fill must know where each contact's rows go, and a count pass over every contact (most of
      // a contact's work up to its manifold's axes) cost a quarter of the fill. When the contacts are the same
      // pairs in the same order as last step's, their counts usually are too: the contacts are placed by last
      // step's counts and filled at once, each contact checking its counts before it writes anything. If one
      // differs, nothing it wrote is kept: the counts are taken afresh and every contact is filled again. Either
      // way the layout is the one the count gives, so the bits are the same.
      bool placed = false;
      if (samePairs) {
        place();
        placed = fill(true);
      }
      if (!placed) {
        ran = std::min(ran, forChunksFromBothEnds(threads, numChunks, [&](uint32_t c) {
          RowCursor scratch;
          contactsOf(c, [&](uint32_t ci) {
            const auto [numRows, numPoints] = contactRows<RowMode::COUNT>(s, ci, k, scratch);
            layout[ci].count = numRows;
            layout[ci].points = numPoints;
          });
        }));
        place();
        fill(false);
      }
      auto& active = s.frictionAnchors.active;
      for (uint32_t c = 0; c < numChunks; ++c) {
        active.insert(active.end(), s.chunkAnchors[c].begin(), s.chunkAnchors[c].end());
        serial.tally += s.chunkTallies[c];
      }
    }
    s.contactLayoutValid = true;
  }
  s.solverStats().numRowBuildThreads = ran;
  s.rowBuildTeamBusy = ran < threads;
  const ChunkTally& t = serial.tally;
  s.nonIterativeRows = t.nonIterative;

  SolverStats& st = s.solverStats();
  st.numContacts = t.numSolved;
  st.numContactPoints = t.numPoints;
  st.numWarmStarted = t.numWarm;
  s.stats.numContacts = s.contacts.size();
  s.stats.numContactPoints = t.numPoints;
}

void buildParticleRows(SimulationState& s) {
  if (!s.granularStep) return;
  const ParticleContactLists lists{&s.particleCollider.getParticleParticleContacts(),
                                   &s.particleCollider.getParticleGeometryContacts(), &s.particleGeometrySides,
                                   s.particleCollider.getCellSize()};
  s.particles.buildRows(s.granular, lists, s.materials, s.solver, s.sb,
                        [&s](const RigidBody* b) { return s.solverIndex(b); }, s.gravity, s.h);
  s.stats.numParticleContacts = s.particles.numUnits();
}

}  // namespace scree::detail
