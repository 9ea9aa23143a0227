// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Projected Gauss-Seidel sweeps and the rigid shock pass (pgs.h).
//
// DESIGN (issue 18, sweep cost; figures in docs/solver-internals.md "Sweep cost"):
//  - A manifold's normal block (solveNormalBlock) has constant operators within a step: the coordinates' rows
//    G_a = sum_i D_ai J_i, their velocity changes W_a = M^-1 G_a^T and the Cholesky factor of D (K + E) D^T for
//    both bodies free and for either body frozen (the shock pass). PgsSolver::prepare builds them once per step
//    into PgsBlocks (storage kept across steps, no per-step allocation once grown); a visit is then three 12-wide
//    dot products, a 3 x 3 triangular solve and three 12-wide updates. Assembling and factoring the 3 x 3 system
//    on every visit had been 60 % of pyramid20's step.
//  - The shock pass solves a manifold support (normal block, centre friction pair, twist) as one 6 x 6 system
//    on the free body when its solution lies within the bounds (solveSupportExactly); sweeping it converged by
//    only about 0.6 per sweep and ran 11-16 sweeps per support. Supports that tip, slide or separate are swept
//    as before, now to a relative tolerance of 1e-7 (kShockTolerance).
//  - Sweep order: rows stay in contact-list order, which on the reference stacks is already bottom-up (sorting the
//    couplings by support level changed no figure; top-down made pyramid20 without the shock pass 5.7 m worse).
//  - The visit multiplies by the block's precomputed inverse (PgsBlocks::Block::sInv) instead of two triangular
//    solves: their six dependent divisions were the largest single cost of a visit.
//  - Scheduling: the default sweep is serial in row order; Solver::setUseColouredSweeps selects graph-coloured
//    sweeps shared among threads with bit-identical results (end of this file, pgs.h PgsColouring), and
//    Solver::setUsePartitionedSweeps two regions and a boundary with one barrier per sweep plus a parallel shock
//    pass equal to the serial one (end of this file, pgs_partition.cpp, pgs.h PgsPartition).
//  - Not done: the base sweeps alone still do not hold pyramid20 (shock pass off: 49 cm at 10 iterations,
//    over-relaxing the blocks made it worse).
#include "scree/solver/pgs.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstddef>
#include <cmath>

#include "contact_law.h"
#include "scree/core/assert.h"
#include "scree/core/parallel.h"

#ifdef SCREE_WITH_OPENMP
#include <omp.h>
#endif

namespace scree::detail {

namespace {
const SolverBodyState kStatic{};
constexpr int kMaxNormalBlock = 16;
/// The shock pass stops sweeping a support once its impulses move by less than this fraction of their size.
/// A support's normal block and its friction rows converge by about 0.6 per sweep (the friction at the contact
/// plane tilts the box, which the block then corrects), so 1e-9 took all 16 sweeps on nearly every support of
/// pyramid20 (15.6 on average); 1e-6 takes 7.2 and leaves pyramid20's drift at 0.0143 cm against 0.0145
/// (1e-5: 5.9 sweeps, 0.030 cm; 1e-4: 0.66 cm). docs/solver-internals.md, "Sweep cost".
constexpr Real kShockTolerance = 1e-7;  ///< most normal rows one block holds (contact_rows.cpp builds no larger)

inline void applyImpulse(const ConstraintRow& r, Real d, std::vector<SolverBodyState>& b) {
  if (r.bodyA >= 0) {
    b[r.bodyA].v += r.mJLinA * d;
    b[r.bodyA].w += r.mJAngA * d;
  }
  if (r.bodyB >= 0) {
    b[r.bodyB].v += r.mJLinB * d;
    b[r.bodyB].w += r.mJAngB * d;
  }
}

/// The bound's normal impulse of a friction row: its normal row, or the sum over a manifold's normal rows.
inline Real boundingNormal(const std::vector<ConstraintRow>& rows, const ConstraintRow& r) {
  if (r.normalCount == 1) return rows[r.normalRow].lambda;
  Real sum = 0;
  for (int32_t k = 0; k < r.normalCount; ++k) sum += std::max<Real>(rows[r.normalRow + k].lambda, 0);
  return sum;
}

}  // namespace

// DESIGN (issue 18, docs/solver-internals.md "Resting stacks"): the normal rows of a planar manifold (a box face
// on a box face) are solved as one block, so that a symmetric manifold gets symmetric impulses. Gauss-Seidel
// over the four corners of a resting box leaves the first-visited corner with more impulse than the last, a
// torque that tilts the box a little every step (1.7e-4 rad/s after one step of the issue-18 tower); on a stack
// the tilt turns into sideways motion and towers topple by themselves.
//
// The block is not solved in the points' own coordinates: four coplanar points with one normal make a rank-3
// block (the (+,-,+,-) mode moves nothing), and (K + E)^-1 gives that mode residual / e, which with SPOOK's small
// e exploded pyramid20. The rows J_i = J_c + u_i G_u + v_i G_v are combinations of three rows (a push at the
// manifold's centre and tilts about its two principal axes), so the block is solved on those: impulses
// dlambda = D^T dmu with D = [1; u; v] (3 x n), and dmu from the Galerkin system D (K + E) D^T dmu = D r, r the
// rows' residuals. That is the exact block solution with the null mode left out; the null mode applies no
// impulse to any body, so leaving it out changes no motion. The system is 3 x 3 and SPD whatever n is.
//
// The update is kept only when every row stays within its bounds (a resting or evenly impacting manifold);
// otherwise -- a box tipping onto an edge, a speculative manifold still apart -- the rows are solved one by one
// as before, which handles the clamping.
// The block's update when the unclamped one leaves a row below its bound: rows are released (held at their
// bound) one at a time, the most negative first, and the rows still active (at most 3: then the points' own
// block K_AA + E_A is regular) are solved exactly with the released rows' change held. dl holds the unclamped
// update on entry. Returns false when more than 3 rows stay active (the caller then solves row by row).
static bool solveClampedBlock(ConstraintRow* R, int n, const Real* resid, Real* dl, bool useA, bool useB,
                              std::vector<SolverBodyState>& bodies, Real& change) {
  bool active[kMaxNormalBlock];
  for (int i = 0; i < n; ++i) active[i] = true;
  // K(i, j) = J_i M^-1 J_j^T (+ e_i on the diagonal), each entry formed once per call: the release rounds ask for
  // the same entries again.
  Real kCache[kMaxNormalBlock][kMaxNormalBlock];
  uint32_t kHave[kMaxNormalBlock];
  for (int i = 0; i < n; ++i) kHave[i] = 0;
  auto K = [&](int i, int j) {
    if (kHave[i] >> j & 1u) return kCache[i][j];
    Real k = i == j ? R[i].e : 0.0;
    if (useA) k += R[i].jLinA.dot(R[j].mJLinA) + R[i].jAngA.dot(R[j].mJAngA);
    if (useB) k += R[i].jLinB.dot(R[j].mJLinB) + R[i].jAngB.dot(R[j].mJAngB);
    kHave[i] |= 1u << j;
    kCache[i][j] = k;
    return k;
  };
  for (int round = 0; round < n; ++round) {
    // Release the most violating active row.
    int worst = -1;
    Real worstV = 0;
    for (int i = 0; i < n; ++i)
      if (active[i]) {
        const Real v = R[i].lo - (R[i].lambda + dl[i]);
        if (v > worstV) { worstV = v; worst = i; }
      }
    if (worst < 0) break;
    active[worst] = false;
    int idx[kMaxNormalBlock], m = 0;
    for (int i = 0; i < n; ++i) {
      if (active[i]) idx[m++] = i;
      else dl[i] = R[i].lo - R[i].lambda;
    }
    if (m > 3) return false;
    if (m > 0) {
      // The active rows' K_AA + E_A (lower triangle) is symmetric positive definite for a regular block (e > 0):
      // an unrolled Cholesky solve; a non-positive pivot (a singular block with e = 0) goes row by row.
      Real L[3][3], rhs[3], x[3];
      for (int a = 0; a < m; ++a) {
        rhs[a] = resid[idx[a]];
        for (int i = 0; i < n; ++i)
          if (!active[i] && dl[i] != 0) rhs[a] -= K(idx[a], i) * dl[i];
      }
      for (int j = 0; j < m; ++j) {
        Real d = K(idx[j], idx[j]);
        for (int k = 0; k < j; ++k) d -= L[j][k] * L[j][k];
        if (!(d > 0)) return false;
        L[j][j] = std::sqrt(d);
        for (int i = j + 1; i < m; ++i) {
          Real t = K(idx[i], idx[j]);
          for (int k = 0; k < j; ++k) t -= L[i][k] * L[j][k];
          L[i][j] = t / L[j][j];
        }
      }
      for (int i = 0; i < m; ++i) {
        Real t = rhs[i];
        for (int k = 0; k < i; ++k) t -= L[i][k] * x[k];
        x[i] = t / L[i][i];
      }
      for (int i = m; i-- > 0;) {
        Real t = x[i];
        for (int k = i + 1; k < m; ++k) t -= L[k][i] * x[k];
        x[i] = t / L[i][i];
      }
      if (!std::isfinite(x[0] + (m > 1 ? x[1] : 0.0) + (m > 2 ? x[2] : 0.0))) return false;
      for (int a = 0; a < m; ++a) dl[idx[a]] = x[a];
    }
  }
  for (int i = 0; i < n; ++i)
    if (R[i].lambda + dl[i] < R[i].lo - 1e-12 * std::abs(R[i].lambda) || R[i].lambda + dl[i] > R[i].hi) return false;
  Real maxD = 0;
  for (int i = 0; i < n; ++i) {
    const Real nl = std::max(R[i].lambda + dl[i], R[i].lo);
    const Real d = nl - R[i].lambda;
    R[i].lambda = nl;
    maxD = std::max(maxD, std::abs(d));
    if (d == 0) continue;
    if (useA) {
      bodies[R[i].bodyA].v += R[i].mJLinA * d;
      bodies[R[i].bodyA].w += R[i].mJAngA * d;
    }
    if (useB) {
      bodies[R[i].bodyB].v += R[i].mJLinB * d;
      bodies[R[i].bodyB].w += R[i].mJAngB * d;
    }
  }
  change = maxD;
  return true;
}

// The block's coordinates: D(0, i) = 1, D(1, i) = u_i, D(2, i) = v_i.
static inline Real blockD(const ConstraintRow& r, int a) { return a == 0 ? 1.0 : a == 1 ? r.blockU : r.blockV; }

static void factorBlock(const ConstraintRow* R, const PgsBlocks::Block& B, int cfg);

// Builds the constant operators of the block whose first row is R (PgsBlocks::Block).
static void buildBlock(const ConstraintRow* R, const std::vector<SolverBodyState>& bodies, PgsBlocks::Block& B) {
  const int n = R[0].blockCount;
  Real su = 0, sv = 0;
  for (int i = 0; i < n; ++i) {
    su += R[i].blockU * R[i].blockU;
    sv += R[i].blockV * R[i].blockV;
  }
  B.axisU = su > 0;
  B.axisV = sv > 0;
  const bool hasA = R[0].bodyA >= 0, hasB = R[0].bodyB >= 0;
  const SolverBodyState& bA = hasA ? bodies[size_t(R[0].bodyA)] : kStatic;
  const SolverBodyState& bB = hasB ? bodies[size_t(R[0].bodyB)] : kStatic;
  for (int a = 0; a < 3; ++a) {
    B.gLinA[a] = B.gAngA[a] = B.gLinB[a] = B.gAngB[a] = Vec3::Zero();
    B.dRhs[a] = 0;
    for (int i = 0; i < n; ++i) {
      const Real d = blockD(R[i], a);
      if (d == 0) continue;
      B.gLinA[a] += d * R[i].jLinA;
      B.gAngA[a] += d * R[i].jAngA;
      B.gLinB[a] += d * R[i].jLinB;
      B.gAngB[a] += d * R[i].jAngB;
      B.dRhs[a] += d * R[i].rhs;
    }
    // W_a = M^-1 G_a^T from G_a (one product per body instead of summing the rows' M^-1 J_i^T; issue 18).
    B.wLinA[a] = bA.invMass * B.gLinA[a];
    B.wAngA[a] = bA.invInertia * B.gAngA[a];
    B.wLinB[a] = bB.invMass * B.gLinB[a];
    B.wAngB[a] = bB.invInertia * B.gAngB[a];
  }
  // D E D^T, summed over the points in their order (the frozen configurations and the shock pass reuse it).
  Real se[6] = {0, 0, 0, 0, 0, 0};
  for (int i = 0; i < n; ++i) {
    const Real D[3] = {1.0, R[i].blockU, R[i].blockV};
    for (int a = 0, k = 0; a < 3; ++a)
      for (int c = 0; c <= a; ++c, ++k) se[k] += D[a] * R[i].e * D[c];
  }
  for (int k = 0; k < 6; ++k) B.se[k] = se[k];
  B.built[0] = B.built[1] = B.built[2] = false;
  factorBlock(R, B, 0);
}

// S = D (K + E) D^T of configuration cfg (0: both bodies free, 1: A frozen, 2: B frozen) = G_a . W_c over the
// free bodies + sum_i D_ai e_i D_ci, its Cholesky factor and inverse into B.sInv[cfg] and B.ok[cfg]. Only
// configuration 0 is built with the block (the sweeps use it); the frozen ones only when the shock pass falls
// back to sweeping a support (solvePreparedBlock), which most steps never do: building all three every step
// was about a fifth of buildBlock's instructions on pyramid20 (issue 18). Each configuration is computed with
// the same operations in the same order as when all three were built together, so the results are the same bits.
static void factorBlock(const ConstraintRow* R, const PgsBlocks::Block& B, int cfg) {
  const bool hasA = R[0].bodyA >= 0, hasB = R[0].bodyB >= 0;
  // The parts of body A, of body B and of E once (symmetric), then summed for the configuration.
  Real SA[3][3], SB[3][3], SE[3][3];
  // E's part: buildBlock's sum over the points (B.se).
  for (int a = 0, k = 0; a < 3; ++a)
    for (int c = 0; c <= a; ++c, ++k) {
      SE[a][c] = B.se[k];
      SA[a][c] = SA[c][a] = hasA ? B.gLinA[a].dot(B.wLinA[c]) + B.gAngA[a].dot(B.wAngA[c]) : 0.0;
      SB[a][c] = SB[c][a] = hasB ? B.gLinB[a].dot(B.wLinB[c]) + B.gAngB[a].dot(B.wAngB[c]) : 0.0;
      SE[c][a] = SE[a][c];
    }
  {
    const bool useA = cfg != 1, useB = cfg != 2;
    Real S[3][3];
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c) S[a][c] = SE[a][c] + (useA ? SA[a][c] : 0.0) + (useB ? SB[a][c] : 0.0);
    // A degenerate axis (collinear or coincident points) carries nothing: identity row, zero right-hand side.
    for (int a = 1; a < 3; ++a)
      if (!(a == 1 ? B.axisU : B.axisV)) {
        for (int c = 0; c < 3; ++c) S[a][c] = S[c][a] = 0;
        S[a][a] = 1;
      }
    // S = L D L^T (unit lower L), then S^-1 = L^-T D^-1 L^-1 (packed lower, symmetric): a visit is then one
    // 3 x 3 product, nine independent multiply-adds, instead of two triangular solves whose dependent divisions
    // were the largest share of a visit (perf on pyramid20). L D L^T rather than Cholesky: the chain is three
    // divisions, without Cholesky's three square roots (issue 18). A pivot that is not positive fails, as
    // Cholesky's would.
    bool ok = S[0][0] > 0;
    Real i0 = 0, i1 = 0, i2 = 0, l10 = 0, l20 = 0, l21 = 0;
    if (ok) {
      i0 = 1 / S[0][0];
      l10 = S[1][0] * i0;
      l20 = S[2][0] * i0;
      const Real d1 = S[1][1] - l10 * S[1][0];
      ok = d1 > 0;
      if (ok) {
        i1 = 1 / d1;
        const Real u21 = S[2][1] - l20 * S[1][0];
        l21 = u21 * i1;
        const Real d2 = S[2][2] - l20 * S[2][0] - l21 * u21;
        ok = d2 > 0;
        if (ok) i2 = 1 / d2;
      }
    }
    if (ok) {
      const Real m10 = -l10, m21 = -l21, m20 = l21 * l10 - l20;
      Real* Si = B.sInv[cfg];
      Si[0] = i0 + m10 * m10 * i1 + m20 * m20 * i2;  // (0,0)
      Si[1] = m10 * i1 + m20 * m21 * i2;              // (1,0)
      Si[2] = i1 + m21 * m21 * i2;                    // (1,1)
      Si[3] = m20 * i2;                               // (2,0)
      Si[4] = m21 * i2;                               // (2,1)
      Si[5] = i2;                                     // (2,2)
      ok = std::isfinite(Si[0] + Si[1] + Si[2] + Si[3] + Si[4] + Si[5]);
    }
    B.ok[cfg] = ok;
  }
  B.built[cfg] = true;
}

// The block update with the operators prepared in B (see solveNormalBlock below for the law).
static bool solvePreparedBlock(ConstraintRow* R, const PgsBlocks::Block& B, std::vector<SolverBodyState>& bodies,
                               int frozen, Real& change) {
  const int cfg = frozen < 0 ? 0 : frozen == 0 ? 1 : 2;
  if (!B.built[cfg]) factorBlock(R, B, cfg);
  if (!B.ok[cfg]) return false;
  const int n = R[0].blockCount;
  const int32_t ia = R[0].bodyA, ib = R[0].bodyB;
  const bool useA = frozen != 0 && ia >= 0, useB = frozen != 1 && ib >= 0;
  Real b[3] = {B.dRhs[0], B.dRhs[1], B.dRhs[2]};
  if (ia >= 0) {
    const Vec3 v = bodies[ia].v, w = bodies[ia].w;
    for (int a = 0; a < 3; ++a) b[a] -= B.gLinA[a].dot(v) + B.gAngA[a].dot(w);
  }
  if (ib >= 0) {
    const Vec3 v = bodies[ib].v, w = bodies[ib].w;
    for (int a = 0; a < 3; ++a) b[a] -= B.gLinB[a].dot(v) + B.gAngB[a].dot(w);
  }
  for (int i = 0; i < n; ++i) {
    const Real el = R[i].e * R[i].lambda;
    b[0] -= el;
    b[1] -= el * R[i].blockU;
    b[2] -= el * R[i].blockV;
  }
  if (!B.axisU) b[1] = 0;
  if (!B.axisV) b[2] = 0;
  const Real* Si = B.sInv[cfg];
  Real dmu[3];
  dmu[0] = Si[0] * b[0] + Si[1] * b[1] + Si[3] * b[2];
  dmu[1] = Si[1] * b[0] + Si[2] * b[1] + Si[4] * b[2];
  dmu[2] = Si[3] * b[0] + Si[4] * b[1] + Si[5] * b[2];
  if (!std::isfinite(dmu[0] + dmu[1] + dmu[2])) return false;
  Real dl[kMaxNormalBlock];
  bool inside = true;
  for (int i = 0; i < n; ++i) {
    dl[i] = dmu[0] + dmu[1] * R[i].blockU + dmu[2] * R[i].blockV;
    const Real nl = R[i].lambda + dl[i];
    inside &= nl >= R[i].lo && nl <= R[i].hi;
  }
  if (!inside) {
    Real resid[kMaxNormalBlock];
    for (int i = 0; i < n; ++i) resid[i] = R[i].rhs - rowVelocity(R[i], bodies) - R[i].e * R[i].lambda;
    return solveClampedBlock(R, n, resid, dl, useA, useB, bodies, change);
  }
  Real maxD = 0;
  for (int i = 0; i < n; ++i) {
    R[i].lambda += dl[i];
    maxD = std::max(maxD, std::abs(dl[i]));
  }
  Vec3 dvA = Vec3::Zero(), dwA = Vec3::Zero(), dvB = Vec3::Zero(), dwB = Vec3::Zero();
  for (int a = 0; a < 3; ++a) {
    dvA += B.wLinA[a] * dmu[a];
    dwA += B.wAngA[a] * dmu[a];
    dvB += B.wLinB[a] * dmu[a];
    dwB += B.wAngB[a] * dmu[a];
  }
  if (useA) {
    bodies[ia].v += dvA;
    bodies[ia].w += dwA;
  }
  if (useB) {
    bodies[ib].v += dvB;
    bodies[ib].w += dwB;
  }
  change = maxD;
  return true;
}

static bool solveNormalBlock(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, size_t begin,
                             int frozen, Real& change, const PgsBlocks* blocks) {
  ConstraintRow* R = rows.data() + begin;
  if (blocks && R[0].blockSlot >= 0)
    return solvePreparedBlock(R, blocks->blocks[size_t(R[0].blockSlot)], bodies, frozen, change);
  const int n = R[0].blockCount;
  const bool useA = frozen != 0 && R[0].bodyA >= 0, useB = frozen != 1 && R[0].bodyB >= 0;
  Real su = 0, sv = 0;
  for (int i = 0; i < n; ++i) {
    su += R[i].blockU * R[i].blockU;
    sv += R[i].blockV * R[i].blockV;
  }
  const bool axisU = su > 0, axisV = sv > 0;
  auto D = [&](int a, int i) -> Real { return a == 0 ? 1.0 : a == 1 ? R[i].blockU : R[i].blockV; };
  // W_a = M^-1 J^T D_a^T: the velocity change of a unit dmu_a, per body.
  Vec3 wLinA[3], wAngA[3], wLinB[3], wAngB[3];
  for (int a = 0; a < 3; ++a) {
    wLinA[a] = wAngA[a] = wLinB[a] = wAngB[a] = Vec3::Zero();
    for (int i = 0; i < n; ++i) {
      const Real d = D(a, i);
      if (d == 0) continue;
      wLinA[a] += d * R[i].mJLinA;
      wAngA[a] += d * R[i].mJAngA;
      wLinB[a] += d * R[i].mJLinB;
      wAngB[a] += d * R[i].mJAngB;
    }
  }
  Eigen::Matrix<Real, 3, 3> S = Eigen::Matrix<Real, 3, 3>::Zero();
  Eigen::Matrix<Real, 3, 1> b = Eigen::Matrix<Real, 3, 1>::Zero();
  Real resid[kMaxNormalBlock];
  for (int i = 0; i < n; ++i) {
    const ConstraintRow& r = R[i];
    Real jv = 0;
    if (r.bodyA >= 0) jv += r.jLinA.dot(bodies[r.bodyA].v) + r.jAngA.dot(bodies[r.bodyA].w);
    if (r.bodyB >= 0) jv += r.jLinB.dot(bodies[r.bodyB].v) + r.jAngB.dot(bodies[r.bodyB].w);
    const Real res = r.rhs - jv - r.e * r.lambda;
    resid[i] = res;
    Real jw[3];
    for (int c = 0; c < 3; ++c) {
      jw[c] = 0;
      if (useA) jw[c] += r.jLinA.dot(wLinA[c]) + r.jAngA.dot(wAngA[c]);
      if (useB) jw[c] += r.jLinB.dot(wLinB[c]) + r.jAngB.dot(wAngB[c]);
    }
    for (int a = 0; a < 3; ++a) {
      const Real da = D(a, i);
      b[a] += da * res;
      for (int c = 0; c < 3; ++c) S(a, c) += da * (jw[c] + r.e * D(c, i));
    }
  }
  // A degenerate axis (collinear or coincident points) carries nothing: identity row, zero right-hand side.
  for (int a = 1; a < 3; ++a)
    if (!(a == 1 ? axisU : axisV)) {
      S.row(a).setZero();
      S.col(a).setZero();
      S(a, a) = 1;
      b[a] = 0;
    }
  const Eigen::LLT<Eigen::Matrix<Real, 3, 3>> llt(S);
  if (llt.info() != Eigen::Success) return false;
  const Eigen::Matrix<Real, 3, 1> dmu = llt.solve(b);
  if (!dmu.allFinite()) return false;
  Real dl[kMaxNormalBlock];
  for (int i = 0; i < n; ++i) {
    dl[i] = dmu[0] + dmu[1] * R[i].blockU + dmu[2] * R[i].blockV;
    const Real nl = R[i].lambda + dl[i];
    if (nl < R[i].lo || nl > R[i].hi) {
      return solveClampedBlock(R, n, resid, dl, useA, useB, bodies, change);
    }
  }
  Real maxD = 0;
  for (int i = 0; i < n; ++i) {
    R[i].lambda += dl[i];
    maxD = std::max(maxD, std::abs(dl[i]));
  }
  for (int a = 0; a < 3; ++a) {
    if (dmu[a] == 0) continue;
    if (useA) {
      bodies[R[0].bodyA].v += wLinA[a] * dmu[a];
      bodies[R[0].bodyA].w += wAngA[a] * dmu[a];
    }
    if (useB) {
      bodies[R[0].bodyB].v += wLinB[a] * dmu[a];
      bodies[R[0].bodyB].w += wAngB[a] * dmu[a];
    }
  }
  change = maxD;
  return true;
}

// M^-1 J^T and the diagonal of one row.
static inline void prepareRow(ConstraintRow& r, const std::vector<SolverBodyState>& bodies) {
  SCREE_ASSERT(r.bodyA < int32_t(bodies.size()) && r.bodyB < int32_t(bodies.size()));
  const SolverBodyState& A = r.bodyA >= 0 ? bodies[r.bodyA] : kStatic;
  const SolverBodyState& B = r.bodyB >= 0 ? bodies[r.bodyB] : kStatic;
  r.mJLinA = A.invMass * r.jLinA;
  r.mJAngA = A.invInertia * r.jAngA;
  r.mJLinB = B.invMass * r.jLinB;
  r.mJAngB = B.invInertia * r.jAngB;
  Real k = r.e;
  if (r.bodyA >= 0) k += r.jLinA.dot(r.mJLinA) + r.jAngA.dot(r.mJAngA);
  if (r.bodyB >= 0) k += r.jLinB.dot(r.mJLinB) + r.jAngB.dot(r.mJAngB);
  r.diag = k;
  r.invDiag = k > 0 ? 1.0 / k : 0.0;
}

// The rows of the normal block starting at `first`, prepared on first use when PgsSolver::prepare deferred them
// (PgsBlocks::Block::rowsReady). `bodies` is the array the rows' body indices point into at the call (the
// partitioned sweeps' local copies hold the same masses and inertias).
static void ensureBlockRows(std::vector<ConstraintRow>& rows, const std::vector<SolverBodyState>& bodies,
                            size_t first, const PgsBlocks* blocks) {
  const int32_t slot = rows[first].blockSlot;
  if (!blocks || slot < 0) return;
  const PgsBlocks::Block& B = blocks->blocks[size_t(slot)];
  if (B.rowsReady) return;
  for (size_t k = first; k < first + size_t(rows[first].blockCount); ++k) prepareRow(rows[k], bodies);
  B.rowsReady = true;
}

// Every deferred block of rows [begin, end) (block rows are contiguous and begin at their first row).
static void ensureBlockRows(std::vector<ConstraintRow>& rows, const std::vector<SolverBodyState>& bodies,
                            size_t begin, size_t end, const PgsBlocks* blocks) {
  if (!blocks || !blocks->anyDeferred) return;
  for (size_t i = begin; i < end; ++i)
    if (rows[i].blockCount > 1 && rows[i].blockBegin == int32_t(i)) ensureBlockRows(rows, bodies, i, blocks);
}

// Prepare's pass over rows [begin, end), in row order: each row's M^-1 J^T and diagonal, then its warm-start
// impulse; a normal block's first row goes into blocks->starts at the next slot (from `slot` up), and its
// operators are built afterwards (buildBlocks). With kFixedUntouched the warm start writes no static or
// kinematic body (PgsPartition::movable): it adds nothing to them, and two ranges on two threads may share them.
// A template so that the serial pass carries no test of it. Sets anyDeferred when a block's rows were left
// unprepared; returns the slot after the last block.
template <bool kFixedUntouched>
static uint32_t prepareRange(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies,
                             PgsBlocks* blocks, bool deferBlockRows, size_t begin, size_t end, uint32_t slot,
                             bool& anyDeferred) {
  auto writes = [&bodies](int32_t b) {
    if constexpr (kFixedUntouched) return b >= 0 && PgsPartition::movable(bodies[size_t(b)]);
    else return b >= 0;
  };
  for (size_t i = begin; i < end; ++i) {
    ConstraintRow& r = rows[i];
    SCREE_VALIDATE_CHECK(r.jLinA.allFinite() && r.jAngA.allFinite() && r.jLinB.allFinite() && r.jAngB.allFinite());
    if (blocks && r.blockCount > 1 && r.blockBegin == int32_t(i)) {
      const size_t n = size_t(r.blockCount);
      if (blocks->starts.size() <= slot) blocks->starts.resize(slot + 1);     // the serial pass: as they come
      blocks->starts[slot] = uint32_t(i);
      if (blocks->blocks.size() <= slot) blocks->blocks.resize(slot + 1);  // grows only: reused across steps
      bool defer = deferBlockRows && i + n <= end;
      for (size_t k = i + 1; defer && k < i + n; ++k)
        defer = rows[k].bodyA == r.bodyA && rows[k].bodyB == r.bodyB && rows[k].blockBegin == int32_t(i);
      blocks->blocks[slot].rowsReady = !defer;
      ++slot;
      anyDeferred = anyDeferred || defer;
      if (defer) {
        SCREE_ASSERT(r.bodyA < int32_t(bodies.size()) && r.bodyB < int32_t(bodies.size()));
        Vec3 lA = Vec3::Zero(), aA = Vec3::Zero(), lB = Vec3::Zero(), aB = Vec3::Zero();
        bool warm = false;
        for (size_t k = i; k < i + n; ++k) {
          ConstraintRow& q = rows[k];
          SCREE_VALIDATE_CHECK(q.jLinA.allFinite() && q.jAngA.allFinite() && q.jLinB.allFinite() &&
                               q.jAngB.allFinite());
          q.blockSlot = -1;
          if (q.lambda == 0) continue;
          warm = true;
          lA += q.lambda * q.jLinA;
          aA += q.lambda * q.jAngA;
          lB += q.lambda * q.jLinB;
          aB += q.lambda * q.jAngB;
        }
        if (warm) {
          if (writes(r.bodyA)) {
            SolverBodyState& A = bodies[size_t(r.bodyA)];
            A.v += A.invMass * lA;
            A.w += A.invInertia * aA;
          }
          if (writes(r.bodyB)) {
            SolverBodyState& B = bodies[size_t(r.bodyB)];
            B.v += B.invMass * lB;
            B.w += B.invInertia * aB;
          }
        }
        i += n - 1;
        continue;
      }
    }
    prepareRow(r, bodies);
    r.blockSlot = -1;
    if (r.lambda == 0) continue;
    if constexpr (kFixedUntouched) {
      if (writes(r.bodyA)) {
        bodies[size_t(r.bodyA)].v += r.mJLinA * r.lambda;
        bodies[size_t(r.bodyA)].w += r.mJAngA * r.lambda;
      }
      if (writes(r.bodyB)) {
        bodies[size_t(r.bodyB)].v += r.mJLinB * r.lambda;
        bodies[size_t(r.bodyB)].w += r.mJAngB * r.lambda;
      }
    } else {
      applyImpulse(r, r.lambda, bodies);
    }
  }
  return slot;
}

// The operators of the blocks in slots [begin, end) (prepareRange recorded their first rows), after the pass:
// they read only masses, inertias and the rows' Jacobians, none of which the pass changes.
static void buildBlocks(std::vector<ConstraintRow>& rows, const std::vector<SolverBodyState>& bodies,
                        PgsBlocks& blocks, uint32_t begin, uint32_t end) {
  for (uint32_t slot = begin; slot < end; ++slot) {
    const uint32_t i = blocks.starts[slot];
    buildBlock(rows.data() + i, bodies, blocks.blocks[slot]);
    rows[i].blockSlot = int32_t(slot);
  }
}

void PgsSolver::prepare(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, PgsBlocks* blocks,
                        bool deferBlockRows) {
  // One pass over the rows: each row's M^-1 J^T and diagonal, then its warm-start impulse (row order, as the
  // sweeps' bodies expect; the blocks below read only masses and inertias, so building them afterwards gives the
  // same bits). The rows are about 300 bytes each: a second pass cost pyramid20 about 1 % (issue 18).
  //
  // DESIGN (issue 18, deferred block rows; docs/solver-internals.md "Rows prepared on first use"): the compact
  // sweeps read a manifold's normal rows only through its block (G_a, W_a) and its points; their own M^-1 J^T
  // and diagonals serve only the rare paths that leave the block (a bound hit, the shock pass's fallback
  // sweeps). With deferBlockRows they are left to those paths (ensureBlockRows), and the block's warm start is
  // applied per body: M^-1 (sum_i lambda_i J_i^T), the same impulse as the rows' one by one in another order
  // of summation (last bits).
  if (blocks) {
    blocks->starts.clear();
    // The compact manifold records (PgsSolver::iterate) describe last step's rows until iterate rebuilds them.
    blocks->manifolds.clear();
    blocks->points.clear();
    blocks->plan.clear();
    blocks->rowManifold.clear();
  }
  bool anyDeferred = false;
  const uint32_t slots = prepareRange<false>(rows, bodies, blocks, deferBlockRows, 0, rows.size(), 0, anyDeferred);
  if (blocks) {
    blocks->anyDeferred = anyDeferred;
    buildBlocks(rows, bodies, *blocks, 0, slots);
  }
}

void PgsSolver::prepare(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, PgsBlocks* blocks,
                        bool deferBlockRows, const PrepareGroups& groups) {
  // DESIGN (issue 18, two-thread scaling; docs/solver-internals.md "The contact rows by region"): the regions'
  // rows share no movable body, so each body's warm-start impulses come from one region's rows, then from the
  // rest's, in row order, on whichever thread; static and kinematic bodies, which both share, are not written.
  constexpr int R = PgsPartition::kRegions;
  SCREE_ASSERT(groups.rowEnd[R - 1] <= rows.size());
  // Slots: each group's from its first row's half (a block has two rows or more), so that the groups' blocks
  // never share a slot; the tail's after them. Holes stay unused.
  uint32_t slotBase[R + 1];
  uint32_t rowBegin = 0, slots = 0;
  for (int g = 0; g < R; ++g) {
    slotBase[g] = slots;
    slots += (groups.rowEnd[g] - rowBegin) / 2;
    rowBegin = groups.rowEnd[g];
  }
  slotBase[R] = slots;
  if (blocks) {
    blocks->starts.assign(slots, UINT32_MAX);
    if (blocks->blocks.size() < slots) blocks->blocks.resize(slots);  // grows only: reused across steps
    // Last step's compact records are made unreachable (no record starts at any row), not cleared: the
    // partitioned iterate writes each record in place on the thread that sweeps it, and a cleared vector would be
    // refilled with zeros on this thread first (928 bytes a record), which the other thread then fetches.
    blocks->rowManifold.assign(rows.size(), -1);
    blocks->plan.clear();
  }
  bool deferred[R + 1] = {};
  runTeam(groups.threads, [&](int t, int nt) {
    if (nt < groups.threads && groups.teamBusy) *groups.teamBusy = true;  // only the calling thread runs then
    for (int g = 0; g < R; ++g)
      if (g % nt == t) {
        const uint32_t end = prepareRange<true>(rows, bodies, blocks, deferBlockRows,
                                                g == 0 ? 0 : groups.rowEnd[g - 1], groups.rowEnd[g], slotBase[g],
                                                deferred[g]);
        if (blocks) buildBlocks(rows, bodies, *blocks, slotBase[g], end);
      }
  });
  // The boundary's contacts and every other row (joints) after both regions, on this thread: every body's
  // impulses are summed in row order, as by the serial pass over the same rows.
  const uint32_t end = prepareRange<false>(rows, bodies, blocks, deferBlockRows, groups.rowEnd[R - 1], rows.size(),
                                           slotBase[R], deferred[R]);
  if (blocks) buildBlocks(rows, bodies, *blocks, slotBase[R], end);
  if (blocks) {
    blocks->anyDeferred = false;
    for (const bool d : deferred) blocks->anyDeferred = blocks->anyDeferred || d;
  }
}

// One Gauss-Seidel update of row i, or of the projected-cone pair (i, i+1). Returns |delta lambda|.
static Real solveUnit(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, size_t i) {
  ConstraintRow& r = rows[i];
  if (r.pairedRow == int32_t(i) + 1) {
    // Projected cone: a scalar Gauss-Seidel update of each tangent row at the same velocity, then the pair is
    // projected radially onto the disc |lambda_t| <= mu lambda_n. Solving the 2x2 block exactly before the
    // projection would be wrong for sliding: K^-1 r couples the tangents through the point's lever arm, so the
    // projected impulse would not oppose the sliding velocity (a sliding box then drifts sideways).
    ConstraintRow& s = rows[i + 1];
    Real d1 = (r.rhs - rowVelocity(r, bodies) - r.e * r.lambda) * r.invDiag;
    Real d2 = (s.rhs - rowVelocity(s, bodies) - s.e * s.lambda) * s.invDiag;
    Real l1 = r.lambda + d1, l2 = s.lambda + d2;
    const Real lim = r.normalRow >= 0 ? frictionLimit(r.mu, boundingNormal(rows, r)) : r.hi;
    projectOntoDisc(l1, l2, lim);
    d1 = l1 - r.lambda;
    d2 = l2 - s.lambda;
    r.lambda = l1;
    s.lambda = l2;
    applyImpulse(r, d1, bodies);
    applyImpulse(s, d2, bodies);
    return std::max(std::abs(d1), std::abs(d2));
  }
  Real lo = r.lo, hi = r.hi;
  if (r.normalRow >= 0) {
    // Scaled box (and a manifold's twist row): bounds follow the current normal impulse.
    const Real lim = frictionLimit(r.mu, boundingNormal(rows, r));
    lo = -lim;
    hi = lim;
  }
  const Real delta = (r.rhs - rowVelocity(r, bodies) - r.e * r.lambda) * r.invDiag;
  const Real nl = std::clamp(r.lambda + delta, lo, hi);
  const Real d = nl - r.lambda;
  r.lambda = nl;
  if (d != 0) applyImpulse(r, d, bodies);
  return std::abs(d);
}

// One Gauss-Seidel pass over rows [begin, end), forward or backward; a manifold's normal block is one update
// (else its rows one by one) and a projected-cone pair one unit. Returns the largest |delta lambda|.
static Real sweepRows(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, size_t begin,
                      size_t end, bool forward, const PgsBlocks* blocks) {
  Real maxDelta = 0;
  if (forward) {
    for (size_t i = begin; i < end; ++i) {
      if (rows[i].blockCount > 1) {
        // A manifold's normal block (i is its first row): one block update, else its rows one by one.
        const size_t count = size_t(rows[i].blockCount);
        Real d = 0;
        if (solveNormalBlock(rows, bodies, i, -1, d, blocks)) {
          maxDelta = std::max(maxDelta, d);
        } else {
          for (size_t k = i; k < i + count; ++k) maxDelta = std::max(maxDelta, solveUnit(rows, bodies, k));
        }
        i += count - 1;
        continue;
      }
      maxDelta = std::max(maxDelta, solveUnit(rows, bodies, i));
      if (rows[i].pairedRow == int32_t(i) + 1) ++i;
    }
  } else {
    for (size_t j = end; j-- > begin;) {
      if (rows[j].blockCount > 1) {
        const size_t first = size_t(rows[j].blockBegin);
        Real d = 0;
        if (solveNormalBlock(rows, bodies, first, -1, d, blocks)) {
          maxDelta = std::max(maxDelta, d);
        } else {
          for (size_t k = j + 1; k-- > first;) maxDelta = std::max(maxDelta, solveUnit(rows, bodies, k));
        }
        j = first;
        continue;
      }
      if (j > begin && rows[j - 1].pairedRow == int32_t(j)) --j;
      maxDelta = std::max(maxDelta, solveUnit(rows, bodies, j));
    }
  }
  return maxDelta;
}

// ---- issue 18 (compact contact arrays): compact manifold sweeps ----
// DESIGN (docs/solver-internals.md "Compact manifold sweeps", "Compact contact rows"): the serial sweeps visit a
// manifold contact (contact_rows.h: [t1, t2, twist][normal block]) from one compact record, PgsBlocks::Manifold
// (928 bytes), and its 40-byte points, instead of seven 352-byte ConstraintRows and a Block. The record holds
// what the contact layout makes necessary and no more: J_linB = -J_linA, so a row's linear part is one A-side
// direction against v_A - v_B and its M^-1 J_lin^T that direction times the inverse mass (three directions serve
// the six rows: the tilt coordinates and the twist have none); the angular parts J_ang and I^-1 J_ang^T of both
// bodies as one 6-vector [A; B], dotted with (w_A; w_B) held as one 6-vector, which SSE2 (the baseline x86-64
// build) evaluates two doubles at a time; the points' block coordinates, compliances, impulses and lower bounds
// (no upper bound). The law and the visiting order are those of solveUnit and
// solvePreparedBlock; the sums run in another order, so impulses differ from the ConstraintRow path in the last
// bits. A block visit that leaves a bound (tipping, separating) writes the manifold's normal impulses back, runs
// the ConstraintRow path (solveClampedBlock, else row by row) and reads them again: rare, and one code path for
// the clamping. The records are built at the start of PgsSolver::iterate (reused storage) and the impulses
// written back at its end, so the result store keeps reading ConstraintRows; the shock pass solves a manifold
// support from the same record (solveSupportCompact). A manifold whose rows do not have the contact layout
// (fitsCompactLayout) keeps the ConstraintRow sweeps. PgsSolver::prepare clears the records, so a path that does
// not rebuild them (the hybrid and coloured sweeps) never reads last step's.
// The manifold visit's parts (VisitBodies, compactFriction and its lambdas, compactBlock's accepted update) are
// forced inline into the visit, and compactBlock's rare fallback is kept out of line. With VisitBodies writing
// (w_A; w_B) in the pairs its dots load (below), that took pyramid20's solve stage from 0.480 to 0.442-0.454 ms
// per step; the store pattern alone gave 0.467, the inlining alone nothing (interleaved rounds, issue 18,
// docs/solver-internals.md "Loads that wait on stores"). Same operations in the same order, so the same results.
#if defined(__GNUC__)
#define SCREE_VISIT_INLINE __attribute__((always_inline))
#define SCREE_VISIT_NOINLINE __attribute__((noinline))
#else
#define SCREE_VISIT_INLINE
#define SCREE_VISIT_NOINLINE
#endif

namespace {

/// True when rows [i, i + 3 + n) are a manifold of the compact form (contact_rows.cpp builds them so).
bool isCompactManifold(const std::vector<ConstraintRow>& rows, size_t i, int& nOut) {
  if (i + 3 >= rows.size()) return false;
  const ConstraintRow& t1 = rows[i];
  const ConstraintRow& t2 = rows[i + 1];
  const ConstraintRow& tw = rows[i + 2];
  const ConstraintRow& n0 = rows[i + 3];
  const int32_t nr = int32_t(i) + 3;
  const int n = t1.normalCount;
  if (n < 2 || n > kMaxNormalBlock || i + 3 + size_t(n) > rows.size()) return false;
  if (n0.blockCount != n || n0.blockBegin != nr || n0.blockSlot < 0) return false;
  const bool cone = t1.pairedRow == int32_t(i) + 1;
  if (!cone && t1.pairedRow >= 0) return false;
  for (const ConstraintRow* f : {&t1, &t2, &tw})
    if (f->normalRow != nr || f->normalCount != n || f->bodyA != t1.bodyA || f->bodyB != t1.bodyB) return false;
  if (t2.pairedRow >= 0 || tw.pairedRow >= 0) return false;
  if (t1.mu != t2.mu) return false;
  for (int k = 0; k < n; ++k) {
    const ConstraintRow& r = rows[i + 3 + size_t(k)];
    if (r.bodyA != t1.bodyA || r.bodyB != t1.bodyB || r.normalRow >= 0 || r.pairedRow >= 0) return false;
  }
  nOut = n;
  return true;
}

/// The span of one ConstraintRow sweep unit starting at row i (a block, a cone pair or one row).
size_t unitSpan(const std::vector<ConstraintRow>& rows, size_t i) {
  if (rows[i].blockCount > 1) return size_t(rows[i].blockCount);
  if (rows[i].pairedRow == int32_t(i) + 1) return 2;
  return 1;
}

/// The compact layout's extra conditions (pgs.h PgsBlocks::Manifold) on a manifold of the compact form:
/// J_linB = -J_linA on the tangent rows and the block centre, no linear part on the twist row nor (to 1e-12 of
/// the centre's) on the tilt coordinates, no upper bound on the normal rows. contact_rows.cpp
/// builds its manifolds so; anything else keeps the ConstraintRow sweeps.
bool fitsCompactLayout(const std::vector<ConstraintRow>& rows, size_t i, int n, const PgsBlocks::Block& B) {
  for (size_t k = 0; k < 2; ++k)
    if (rows[i + k].jLinB != -rows[i + k].jLinA) return false;
  if (!rows[i + 2].jLinA.isZero(0) || !rows[i + 2].jLinB.isZero(0)) return false;
  if (B.gLinB[0] != -B.gLinA[0]) return false;
  const Real tol = 1e-12 * B.gLinA[0].norm();
  for (int a = 1; a < 3; ++a)
    if (B.gLinA[a].norm() > tol || B.gLinB[a].norm() > tol) return false;
  for (int k = 0; k < n; ++k)
    if (rows[i + 3 + size_t(k)].hi < 1e300) return false;
  return true;
}

/// The manifold's sums over its points' normal impulses (PgsBlocks::Manifold::sl), from the points.
void updateSums(PgsBlocks::Manifold& m, const PgsBlocks::Point* P) {
  Real sl = 0, slu = 0, slv = 0, pos = 0;
  for (int i = 0; i < m.n; ++i) {
    const Real l = P[i].lambda, el = P[i].e * l;
    sl += el;
    slu += el * P[i].u;
    slv += el * P[i].v;
    pos += std::max<Real>(l, 0);
  }
  m.sl = sl;
  m.slu = slu;
  m.slv = slv;
  m.sumN = pos;
}

/// Writes the compact record m of the manifold contact whose rows start at row i (n normal rows; isCompactManifold
/// and fitsCompactLayout hold), its points from pb.points[point] on, each through putPoint(k, point) (which
/// appends or writes in place).
template <class PutPoint>
void writeCompact(const std::vector<ConstraintRow>& rows, const std::vector<SolverBodyState>& bodies,
                  PgsBlocks& pb, PgsBlocks::Manifold& m, uint32_t point, size_t i, int n, PutPoint&& putPoint) {
  const ConstraintRow& t1 = rows[i];
  m.a = t1.bodyA;
  m.b = t1.bodyB;
  m.imA = m.a >= 0 ? bodies[size_t(m.a)].invMass : 0.0;
  m.imB = m.b >= 0 ? bodies[size_t(m.b)].invMass : 0.0;
  m.row = uint32_t(i);
  m.block = uint32_t(rows[i + 3].blockSlot);
  m.point = point;
  m.n = n;
  m.cone = t1.pairedRow == int32_t(i) + 1;
  m.mu = t1.mu;
  m.muTwist = rows[i + 2].mu;
  for (int k = 0; k < 3; ++k) {
    const ConstraintRow& r = rows[i + size_t(k)];
    m.ang[3 + k] << r.jAngA, r.jAngB;
    m.w[3 + k] << r.mJAngA, r.mJAngB;
    m.rhs[k] = r.rhs;
    m.e[k] = r.e;
    m.invDiag[k] = r.invDiag;
    m.lambda[k] = r.lambda;
  }
  m.lin[1] = rows[i].jLinA;
  m.lin[2] = rows[i + 1].jLinA;
  const PgsBlocks::Block& B = pb.blocks[m.block];
  m.lin[0] = B.gLinA[0];
  for (int a = 0; a < 3; ++a) {
    m.ang[a] << B.gAngA[a], B.gAngB[a];
    m.w[a] << B.wAngA[a], B.wAngB[a];
    m.dRhs[a] = B.dRhs[a];
  }
  for (int k = 0; k < 6; ++k) m.sInv[k] = B.sInv[0][k];
  m.ok = B.ok[0];
  m.axisU = B.axisU;
  m.axisV = B.axisV;
  for (int k = 0; k < n; ++k) {
    const ConstraintRow& r = rows[i + 3 + size_t(k)];
    putPoint(k, PgsBlocks::Point{r.blockU, r.blockV, r.e, r.lambda, r.lo});
  }
  updateSums(m, pb.points.data() + m.point);
}

/// Appends the compact record of the manifold contact whose rows start at row i (writeCompact).
void appendCompact(const std::vector<ConstraintRow>& rows, const std::vector<SolverBodyState>& bodies,
                   PgsBlocks& pb, size_t i, int n) {
  writeCompact(rows, bodies, pb, pb.manifolds.emplace_back(), uint32_t(pb.points.size()), i, n,
               [&pb](int, const PgsBlocks::Point& q) { pb.points.push_back(q); });
}

/// Writes the impulses of record m back into its rows.
void writeBackRecord(std::vector<ConstraintRow>& rows, const PgsBlocks& pb, const PgsBlocks::Manifold& m) {
  for (int k = 0; k < 3; ++k) rows[m.row + uint32_t(k)].lambda = m.lambda[k];
  for (int k = 0; k < m.n; ++k) rows[m.row + 3 + uint32_t(k)].lambda = pb.points[m.point + uint32_t(k)].lambda;
}

/// True when the rows starting at i form a manifold contact of the compact form; n its normal rows.
bool compactUnit(const std::vector<ConstraintRow>& rows, const PgsBlocks& pb, size_t i, int& n) {
  return isCompactManifold(rows, i, n) && fitsCompactLayout(rows, i, n, pb.blocks[size_t(rows[i + 3].blockSlot)]);
}

void buildCompact(std::vector<ConstraintRow>& rows, const std::vector<SolverBodyState>& bodies, PgsBlocks& pb) {
  pb.manifolds.clear();
  pb.points.clear();
  pb.plan.clear();
  pb.rowManifold.clear();  // records in row order: compactAt searches them
  size_t runBegin = 0;
  for (size_t i = 0; i < rows.size();) {
    int n = 0;
    if (!compactUnit(rows, pb, i, n)) {
      // Swept as ConstraintRows: a deferred normal block's rows are prepared now (PgsSolver::prepare).
      if (rows[i].blockCount > 1) ensureBlockRows(rows, bodies, i, &pb);
      i += unitSpan(rows, i);
      continue;
    }
    if (runBegin < i) pb.plan.push_back({uint32_t(runBegin), uint32_t(i), -1});
    appendCompact(rows, bodies, pb, i, n);
    pb.plan.push_back({uint32_t(i), uint32_t(i) + 3 + uint32_t(n), int32_t(pb.manifolds.size() - 1)});
    i += 3 + size_t(n);
    runBegin = i;
  }
  if (runBegin < rows.size()) pb.plan.push_back({uint32_t(runBegin), uint32_t(rows.size()), -1});
}

void writeBackCompact(std::vector<ConstraintRow>& rows, const PgsBlocks& pb) {
  for (const PgsBlocks::Manifold& m : pb.manifolds)
    if (m.n >= 0) writeBackRecord(rows, pb, m);
}

using Vec6 = PgsBlocks::Vec6;


/// The two bodies' velocities during one manifold visit. Every row of a manifold acts on the same two bodies, so
/// a visit reads their velocities once into registers and stores them once: the linear ones apart (the rows'
/// linear parts act on v_A - v_B), the angular ones as one 6-vector (w_A; w_B) against the rows' [A; B] angular
/// parts. A static side reads as zero and is never stored (its inverse mass and I^-1 J are zero, so the rows
/// leave its local copy at zero).
struct VisitBodies {
  Vec3 vA, vB;
  Vec6 w;
  bool hasA, hasB;
  VisitBodies(const PgsBlocks::Manifold& m, const std::vector<SolverBodyState>& bodies)
      : hasA(m.a >= 0), hasB(m.b >= 0) {
    const Vec3 zero = Vec3::Zero();
    const Vec3& wA = hasA ? bodies[size_t(m.a)].w : zero;
    const Vec3& wB = hasB ? bodies[size_t(m.b)].w : zero;
    vA = hasA ? bodies[size_t(m.a)].v : zero;
    vB = hasB ? bodies[size_t(m.b)].v : zero;
    // (w_A; w_B) written as the three aligned pairs the rows' 6-vector dots load (w_A.z and w_B.x share one):
    // written as two 3-vectors, two of those loads each spanned two stores, which the CPU cannot forward (perf on
    // pyramid20: 6 % of the visit's samples on one such load; issue 18).
    using Vec2 = Eigen::Matrix<Real, 2, 1>;
    w.segment<2>(0) = Vec2(wA.x(), wA.y());
    w.segment<2>(2) = Vec2(wA.z(), wB.x());
    w.segment<2>(4) = Vec2(wB.y(), wB.z());
  }
  void store(const PgsBlocks::Manifold& m, std::vector<SolverBodyState>& bodies) const {
    if (hasA) {
      bodies[size_t(m.a)].v = vA;
      bodies[size_t(m.a)].w = w.head<3>();
    }
    if (hasB) {
      bodies[size_t(m.b)].v = vB;
      // w_B as the pair (w_B.y, w_B.z) the visit stored and w_B.x from the pair before: read as w.tail<3>(),
      // GCC loaded (w_B.x, w_B.y) as one pair across two stores (perf: the visit's hottest load; issue 18).
      SolverBodyState& B = bodies[size_t(m.b)];
      B.w.x() = w[3];
      B.w.tail<2>() = w.segment<2>(4);
    }
  }
  /// J v of a row with A-side linear part l and angular part [A; B] ang.
  SCREE_VISIT_INLINE Real rowVelocity(const Vec3& l, const Vec6& ang) const { return l.dot(vA - vB) + ang.dot(w); }
  /// The linear velocity change of an impulse d along the A-side direction l.
  /// Written per component: as `vA += (m.imA * d) * l`, GCC called Eigen's assignment loop out of line from
  /// the visit (a call per push, its operands through memory). The same products, so the same bits. The visit's
  /// updates of the 6-vector w are written per component for the same reason (GCC outlined them after an
  /// unrelated change elsewhere in this file, December 2026: pyramid20's sweeps took 4 % more instructions).
  SCREE_VISIT_INLINE void push(const PgsBlocks::Manifold& m, const Vec3& l, Real d) {
    const Real ka = m.imA * d, kb = m.imB * d;
    for (int k = 0; k < 3; ++k) {
      vA[k] += ka * l[k];
      vB[k] -= kb * l[k];
    }
  }
};

/// The friction rows of a compact manifold, forward (t1/t2, twist) or backward (twist, t2/t1); solveUnit's law.
SCREE_VISIT_INLINE inline Real compactFriction(PgsBlocks::Manifold& m, VisitBodies& V, bool forward) {
  Real maxDelta = 0;
  // The bound's sum of positive normal impulses, kept with the impulses (boundingNormal's sum).
  const Real sumN = m.sumN;
  // Row k (0 t1, 1 t2, 2 twist: no linear part).
  auto velocity = [&](int k) SCREE_VISIT_INLINE {
    return k < 2 ? V.rowVelocity(m.lin[1 + k], m.ang[3 + k]) : m.ang[5].dot(V.w);
  };
  auto scalar = [&](int k, Real mu) SCREE_VISIT_INLINE {
    const Real lim = frictionLimit(mu, sumN);
    const Real delta = (m.rhs[k] - velocity(k) - m.e[k] * m.lambda[k]) * m.invDiag[k];
    const Real nl = std::clamp(m.lambda[k] + delta, -lim, lim);
    const Real d = nl - m.lambda[k];
    m.lambda[k] = nl;
    for (int j = 0; j < 6; ++j) V.w[j] += m.w[3 + k][j] * d;  // per component: see push
    if (k < 2) V.push(m, m.lin[1 + k], d);
    maxDelta = std::max(maxDelta, std::abs(d));
  };
  auto pair = [&]() SCREE_VISIT_INLINE {
    Real d1 = (m.rhs[0] - velocity(0) - m.e[0] * m.lambda[0]) * m.invDiag[0];
    Real d2 = (m.rhs[1] - velocity(1) - m.e[1] * m.lambda[1]) * m.invDiag[1];
    Real l1 = m.lambda[0] + d1, l2 = m.lambda[1] + d2;
    projectOntoDisc(l1, l2, frictionLimit(m.mu, sumN));
    d1 = l1 - m.lambda[0];
    d2 = l2 - m.lambda[1];
    m.lambda[0] = l1;
    m.lambda[1] = l2;
    for (int j = 0; j < 6; ++j) V.w[j] += m.w[3][j] * d1 + m.w[4][j] * d2;  // per component: see push
    const Vec3 dl = m.lin[1] * d1 + m.lin[2] * d2;
    V.push(m, dl, 1.0);
    maxDelta = std::max(maxDelta, std::max(std::abs(d1), std::abs(d2)));
  };
  if (forward) {
    if (m.cone) pair();
    else {
      scalar(0, m.mu);
      scalar(1, m.mu);
    }
    scalar(2, m.muTwist);
  } else {
    scalar(2, m.muTwist);
    if (m.cone) pair();
    else {
      scalar(1, m.mu);
      scalar(0, m.mu);
    }
  }
  return maxDelta;
}

}  // namespace

static Real compactBlockFallback(PgsBlocks& pb, PgsBlocks::Manifold& m, std::vector<ConstraintRow>& rows,
                                 std::vector<SolverBodyState>& bodies, VisitBodies& V, bool forward);

/// The normal block of a compact manifold (solvePreparedBlock's law, both bodies free).
SCREE_VISIT_INLINE static inline Real compactBlock(PgsBlocks& pb, PgsBlocks::Manifold& m,
                                                   std::vector<ConstraintRow>& rows,
                                                   std::vector<SolverBodyState>& bodies, VisitBodies& V,
                                                   bool forward) {
  PgsBlocks::Point* P = pb.points.data() + m.point;
  const int n = m.n;
  if (m.ok) {
    // The compliances' term: the sums of e lambda, e lambda u and e lambda v, kept with the impulses.
    Real b[3];
    b[0] = m.dRhs[0] - V.rowVelocity(m.lin[0], m.ang[0]) - m.sl;
    b[1] = m.axisU ? m.dRhs[1] - m.ang[1].dot(V.w) - m.slu : 0.0;
    b[2] = m.axisV ? m.dRhs[2] - m.ang[2].dot(V.w) - m.slv : 0.0;
    const Real* Si = m.sInv;
    Real dmu[3];
    dmu[0] = Si[0] * b[0] + Si[1] * b[1] + Si[3] * b[2];
    dmu[1] = Si[1] * b[0] + Si[2] * b[1] + Si[4] * b[2];
    dmu[2] = Si[3] * b[0] + Si[4] * b[1] + Si[5] * b[2];
    if (std::isfinite(dmu[0] + dmu[1] + dmu[2])) {
      Real dl[kMaxNormalBlock];
      bool inside = true;
      for (int i = 0; i < n; ++i) {
        dl[i] = dmu[0] + dmu[1] * P[i].u + dmu[2] * P[i].v;
        inside &= P[i].lambda + dl[i] >= P[i].lo;
      }
      if (inside) {
        Real maxD = 0, sl = 0, slu = 0, slv = 0, pos = 0;
        for (int i = 0; i < n; ++i) {
          const Real l = P[i].lambda += dl[i], el = P[i].e * l;
          maxD = std::max(maxD, std::abs(dl[i]));
          sl += el;
          slu += el * P[i].u;
          slv += el * P[i].v;
          pos += std::max<Real>(l, 0);
        }
        m.sl = sl;
        m.slu = slu;
        m.slv = slv;
        m.sumN = pos;
        for (int j = 0; j < 6; ++j)  // per component, as push says; Eigen's order of the sum
          V.w[j] += (m.w[0][j] * dmu[0] + m.w[1][j] * dmu[1]) + m.w[2][j] * dmu[2];
        V.push(m, m.lin[0], dmu[0]);
        return maxD;
      }
    }
  }
  return compactBlockFallback(pb, m, rows, bodies, V, forward);
}

/// compactBlock when a bound is hit (or the block is singular): the ConstraintRow path on this manifold's normal
/// rows, on the stored velocities. Rare, so out of line.
SCREE_VISIT_NOINLINE static Real compactBlockFallback(PgsBlocks& pb, PgsBlocks::Manifold& m,
                                                           std::vector<ConstraintRow>& rows,
                                                           std::vector<SolverBodyState>& bodies, VisitBodies& V,
                                                           bool forward) {
  PgsBlocks::Point* P = pb.points.data() + m.point;
  const int n = m.n;
  V.store(m, bodies);
  const size_t first = m.row + 3;
  // The rows keep the shared body indices while the partitioned sweeps run on their own copy of the bodies
  // (PgsSolver::iterate with a partition): for this call they index the bodies the record does.
  const int32_t rowA = rows[first].bodyA, rowB = rows[first].bodyB;
  for (int i = 0; i < n; ++i) {
    ConstraintRow& r = rows[first + size_t(i)];
    r.lambda = P[i].lambda;
    r.bodyA = m.a;
    r.bodyB = m.b;
  }
  ensureBlockRows(rows, bodies, first, &pb);  // the rows' M^-1 J^T, if PgsSolver::prepare deferred them
  Real maxDelta = 0, d = 0;
  if (solveNormalBlock(rows, bodies, first, -1, d, &pb)) {
    maxDelta = d;
  } else if (forward) {
    for (size_t k = first; k < first + size_t(n); ++k) maxDelta = std::max(maxDelta, solveUnit(rows, bodies, k));
  } else {
    for (size_t k = first + size_t(n); k-- > first;) maxDelta = std::max(maxDelta, solveUnit(rows, bodies, k));
  }
  for (int i = 0; i < n; ++i) {
    ConstraintRow& r = rows[first + size_t(i)];
    P[i].lambda = r.lambda;
    r.bodyA = rowA;
    r.bodyB = rowB;
  }
  updateSums(m, P);
  V = VisitBodies(m, bodies);
  return maxDelta;
}

// One serial sweep over the plan (PgsBlocks::plan: compact manifolds and runs of ConstraintRows), forward or
// backward. Returns the largest |delta lambda| when kTrack; the sweeps whose result nobody reads (all but the
// last) compile without it: pyramid20's solve stage 0.385 -> 0.377 ms (8 interleaved rounds, issue 18). Forcing
// the visit inline into the loop instead made it slower (0.416 -> 0.432 ms).
template <bool kTrack>
static Real sweepCompact(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, PgsBlocks& pb,
                         bool forward) {
  Real maxDelta = 0;
  auto visit = [&](const PgsBlocks::Unit& u) {
    if (u.manifold < 0) {
      const Real d = sweepRows(rows, bodies, u.begin, u.end, forward, &pb);
      if constexpr (kTrack) maxDelta = std::max(maxDelta, d);
      return;
    }
    PgsBlocks::Manifold& m = pb.manifolds[size_t(u.manifold)];
    VisitBodies V(m, bodies);
    Real d;
    if (forward) {
      d = compactFriction(m, V, true);
      d = std::max(d, compactBlock(pb, m, rows, bodies, V, true));
    } else {
      d = compactBlock(pb, m, rows, bodies, V, false);
      d = std::max(d, compactFriction(m, V, false));
    }
    V.store(m, bodies);
    if constexpr (kTrack) maxDelta = std::max(maxDelta, d);
  };
  const std::vector<PgsBlocks::Unit>& plan = pb.plan;
  if (forward) {
    for (const PgsBlocks::Unit& u : plan) visit(u);
  } else {
    for (size_t k = plan.size(); k-- > 0;) visit(plan[k]);
  }
  return maxDelta;
}

Real PgsSolver::iterate(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, int iterations,
                        PgsBlocks* blocks) {
  // Symmetric Gauss-Seidel: sweeps alternate forward and backward. On chains (joints, stacks) a one-way sweep
  // carries information one link per sweep in one direction only; alternating halves the propagation time and,
  // with SPOOK's stabilisation, keeps long stiff chains stable at the default iteration count where one-way
  // sweeps left enough residual to feed an oscillation.
  Real maxDelta = 0;
  if (!blocks) {
    for (int it = 0; it < iterations; ++it) maxDelta = sweepRows(rows, bodies, 0, rows.size(), it % 2 == 0, blocks);
    return maxDelta;
  }
  buildCompact(rows, bodies, *blocks);
  // Only the last sweep's largest change is returned: the sweeps before it skip that bookkeeping (kTrack).
  for (int it = 0; it < iterations; ++it) {
    if (it + 1 < iterations) sweepCompact<false>(rows, bodies, *blocks, it % 2 == 0);
    else maxDelta = sweepCompact<true>(rows, bodies, *blocks, it % 2 == 0);
  }
  writeBackCompact(rows, *blocks);
  return maxDelta;
}

Real PgsSolver::iterate(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, int iterations,
                        const std::vector<uint32_t>& subset) {
  Real maxDelta = 0;
  const size_t n = subset.size();
  for (int it = 0; it < iterations; ++it) {
    maxDelta = 0;
    if (it % 2 == 0) {
      for (size_t k = 0; k < n; ++k) {
        const uint32_t i = subset[k];
        maxDelta = std::max(maxDelta, solveUnit(rows, bodies, i));
        if (rows[i].pairedRow == int32_t(i) + 1) ++k;
      }
    } else {
      for (size_t k = n; k-- > 0;) {
        if (k > 0 && rows[subset[k - 1]].pairedRow == int32_t(subset[k])) --k;
        maxDelta = std::max(maxDelta, solveUnit(rows, bodies, subset[k]));
      }
    }
  }
  return maxDelta;
}

// DESIGN (issue 18, docs/solver-internals.md "Sweep cost"): a support of the shock pass is one free body on a
// frozen one, so a manifold's support -- its normal block's three coordinates and its centre friction pair and
// twist -- is a 6 x 6 system on the free body's six velocities. Sweeping it converges by only about 0.6 per
// sweep (the friction at the contact plane tilts the box, which the block then undoes), so the pass ran 11-16
// sweeps per support; solving the six coordinates at once gives the sweeps' fixed point in one solve whenever it
// lies inside the bounds (every normal impulse above its bound, the friction inside mu times the new normal
// sum), as it does for resting and sliding-free supports. Otherwise (tipping, sliding, separating) the sweeps
// run as before. Returns true when the exact update was applied.
bool PgsSolver::solveSupportExactly(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies,
                                    const ShockRange& sr, const PgsBlocks& blocks) {
  constexpr int kMax = 6;
  // The range: a manifold's friction rows (first, contact_rows.cpp) and its normal block.
  int32_t nb = -1;
  for (uint32_t i = sr.begin; i < sr.begin + sr.count; ++i)
    if (rows[i].blockCount > 1) {
      nb = rows[i].blockBegin;
      break;
    }
  if (nb < 0 || rows[size_t(nb)].blockSlot < 0) return false;
  ConstraintRow* R = rows.data() + nb;
  const ConstraintRow& r0 = R[0];
  const int n = r0.blockCount;
  const int nf = int(sr.count) - n;
  if (nf < 0 || nf > kMax - 3 || nb < int32_t(sr.begin) || nb + n > int32_t(sr.begin + sr.count)) return false;
  ConstraintRow* F[kMax];
  int32_t fIndex[kMax];
  {
    int k = 0;
    for (uint32_t i = sr.begin; i < sr.begin + sr.count; ++i) {
      if (int32_t(i) >= nb && int32_t(i) < nb + n) continue;
      ConstraintRow& f = rows[i];
      if (f.normalRow != nb || f.normalCount != n || f.bodyA != r0.bodyA || f.bodyB != r0.bodyB) return false;
      fIndex[k] = int32_t(i);
      F[k++] = &f;
    }
  }
  const PgsBlocks::Block& B = blocks.blocks[size_t(r0.blockSlot)];
  const bool freeA = sr.frozen != 0;
  const int32_t fb = freeA ? r0.bodyA : r0.bodyB;
  if (fb < 0) return false;
  const int m = 3 + nf;
  // Free-body Jacobians G and M^-1 G^T of the m coordinates.
  Vec3 gl[kMax], ga[kMax], wl[kMax], wa[kMax];
  for (int a = 0; a < 3; ++a) {
    gl[a] = freeA ? B.gLinA[a] : B.gLinB[a];
    ga[a] = freeA ? B.gAngA[a] : B.gAngB[a];
    wl[a] = freeA ? B.wLinA[a] : B.wLinB[a];
    wa[a] = freeA ? B.wAngA[a] : B.wAngB[a];
  }
  for (int k = 0; k < nf; ++k) {
    const ConstraintRow& f = *F[k];
    gl[3 + k] = freeA ? f.jLinA : f.jLinB;
    ga[3 + k] = freeA ? f.jAngA : f.jAngB;
    wl[3 + k] = freeA ? f.mJLinA : f.mJLinB;
    wa[3 + k] = freeA ? f.mJAngA : f.mJAngB;
  }
  Eigen::Matrix<Real, kMax, kMax> K = Eigen::Matrix<Real, kMax, kMax>::Identity();
  Eigen::Matrix<Real, kMax, 1> b = Eigen::Matrix<Real, kMax, 1>::Zero();
  for (int a = 0; a < m; ++a)
    for (int c = 0; c <= a; ++c) K(a, c) = K(c, a) = gl[a].dot(wl[c]) + ga[a].dot(wa[c]);
  // Regularisation: the block's D E D^T, the friction rows' own e.
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c) K(a, c) += blockD(R[i], a) * R[i].e * blockD(R[i], c);
  for (int k = 0; k < nf; ++k) K(3 + k, 3 + k) += F[k]->e;
  // Residuals (velocities of both bodies, as in the sweeps).
  for (int a = 0; a < 3; ++a) b[a] = B.dRhs[a];
  if (r0.bodyA >= 0)
    for (int a = 0; a < 3; ++a) b[a] -= B.gLinA[a].dot(bodies[r0.bodyA].v) + B.gAngA[a].dot(bodies[r0.bodyA].w);
  if (r0.bodyB >= 0)
    for (int a = 0; a < 3; ++a) b[a] -= B.gLinB[a].dot(bodies[r0.bodyB].v) + B.gAngB[a].dot(bodies[r0.bodyB].w);
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) b[a] -= blockD(R[i], a) * R[i].e * R[i].lambda;
  for (int k = 0; k < nf; ++k) {
    const ConstraintRow& f = *F[k];
    b[3 + k] = f.rhs - rowVelocity(f, bodies) - f.e * f.lambda;
  }
  // A degenerate axis carries nothing (as in the block).
  for (int a = 1; a < 3; ++a)
    if (!(a == 1 ? B.axisU : B.axisV)) {
      K.row(a).setZero();
      K.col(a).setZero();
      K(a, a) = 1;
      b[a] = 0;
    }
  const Eigen::LLT<Eigen::Matrix<Real, kMax, kMax>> llt(K);
  if (llt.info() != Eigen::Success) return false;
  const Eigen::Matrix<Real, kMax, 1> x = llt.solve(b);
  if (!x.allFinite()) return false;
  // Bounds: the new normal impulses, then the friction inside mu times their new sum.
  Real nl[kMaxNormalBlock];
  Real sumN = 0;
  for (int i = 0; i < n; ++i) {
    nl[i] = R[i].lambda + x[0] + x[1] * R[i].blockU + x[2] * R[i].blockV;
    if (nl[i] < R[i].lo || nl[i] > R[i].hi) return false;
    sumN += std::max<Real>(nl[i], 0);
  }
  Real fl[kMax];
  for (int k = 0; k < nf; ++k) fl[k] = F[k]->lambda + x[3 + k];
  for (int k = 0; k < nf; ++k) {
    const ConstraintRow& f = *F[k];
    const Real lim = frictionLimit(f.mu, sumN);
    if (f.pairedRow >= 0) {
      if (k + 1 >= nf || f.pairedRow != fIndex[k + 1] || fl[k] * fl[k] + fl[k + 1] * fl[k + 1] > lim * lim) return false;
      ++k;
    } else if (std::abs(fl[k]) > lim) {
      return false;
    }
  }
  for (int i = 0; i < n; ++i) R[i].lambda = nl[i];
  for (int k = 0; k < nf; ++k) F[k]->lambda = fl[k];
  Vec3 dv = Vec3::Zero(), dw = Vec3::Zero();
  for (int a = 0; a < m; ++a) {
    dv += wl[a] * x[a];
    dw += wa[a] * x[a];
  }
  bodies[fb].v += dv;
  bodies[fb].w += dw;
  return true;
}

// The support solve above on a compact manifold record (PgsSolver::iterate): the same system, its operators
// read as 6-vectors, the impulses read from and written to the ConstraintRows (the shock pass's state).
namespace {
/// Solves K x = b for a symmetric positive definite 6 x 6 K (lower triangle read) by an unrolled L D L^T
/// factorisation; false when a pivot is not positive (as Eigen::LLT reports). Written out because Eigen's
/// general LLT was 0.39 M of pyramid20's 10.3 M instructions per step (one solve per shock support). L D L^T
/// rather than Cholesky: the factorisation's critical path is then six divisions instead of six square roots
/// followed by six divisions (the support solve was 11 % of pyramid20's step by perf samples; issue 18).
bool ldltSolve6(const Real K[6][6], const Real b[6], Real x[6]) {
  Real L[6][6], U[6][6], inv[6];  // U[i][k] = L[i][k] d_k
  for (int j = 0; j < 6; ++j) {
    Real d = K[j][j];
    for (int k = 0; k < j; ++k) d -= U[j][k] * L[j][k];
    if (!(d > 0)) return false;
    inv[j] = 1 / d;
    for (int i = j + 1; i < 6; ++i) {
      Real s = K[i][j];
      for (int k = 0; k < j; ++k) s -= U[i][k] * L[j][k];
      U[i][j] = s;
      L[i][j] = s * inv[j];
    }
  }
  Real y[6];
  for (int i = 0; i < 6; ++i) {
    Real s = b[i];
    for (int k = 0; k < i; ++k) s -= L[i][k] * y[k];
    y[i] = s;
  }
  for (int i = 6; i-- > 0;) {
    Real s = y[i] * inv[i];
    for (int k = i + 1; k < 6; ++k) s -= L[k][i] * x[k];
    x[i] = s;
  }
  return std::isfinite(x[0] + x[1] + x[2] + x[3] + x[4] + x[5]);
}

bool solveSupportCompact(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies,
                         const PgsSolver::ShockRange& sr, const PgsBlocks& pb, const PgsBlocks::Manifold& m) {
  constexpr int kM = 6;
  const int n = m.n;
  if (sr.begin != m.row || sr.count != uint32_t(3 + n)) return false;
  const bool freeA = sr.frozen != 0;
  const int32_t fb = freeA ? m.a : m.b;
  if (fb < 0) return false;
  const PgsBlocks::Point* P = pb.points.data() + m.point;
  ConstraintRow* F = rows.data() + m.row;
  ConstraintRow* R = F + 3;
  // The six rows on the free body (rows 0..2 the block's coordinates, 3..5 the friction rows): G = [lin; ang],
  // W = M^-1 G^T. Rows 0, 3 and 4 have a linear part (the B side's is the A side's negated, which the product
  // G W^T does not see); the angular parts are the free side's half of the record's [A; B] 6-vectors.
  const Real im = freeA ? m.imA : m.imB;
  const int side = freeA ? 0 : 3;
  constexpr int kLinRow[3] = {0, 3, 4};
  Real K[kM][kM];
  for (int a = 0; a < kM; ++a) {
    const Real* ga = m.ang[a].data() + side;
    for (int c = 0; c <= a; ++c) {
      const Real* wc = m.w[c].data() + side;
      K[a][c] = ga[0] * wc[0] + ga[1] * wc[1] + ga[2] * wc[2];
    }
  }
  for (int p = 0; p < 3; ++p)
    for (int q = 0; q <= p; ++q) K[kLinRow[p]][kLinRow[q]] += im * m.lin[p].dot(m.lin[q]);
  // Regularisation: the block's D E D^T, the friction rows' own e.
  const Real* se = pb.blocks[m.block].se;  // D E D^T, packed lower (buildBlock)
  for (int a = 0, k = 0; a < 3; ++a)
    for (int c = 0; c <= a; ++c, ++k) K[a][c] += se[k];
  Real b[kM];
  for (int a = 0; a < 3; ++a) b[a] = m.dRhs[a];
  for (int i = 0; i < n; ++i) {
    const Real D[3] = {1.0, P[i].u, P[i].v};
    const Real el = P[i].e * R[i].lambda;
    for (int a = 0; a < 3; ++a) b[a] -= D[a] * el;
  }
  for (int k = 0; k < 3; ++k) K[3 + k][3 + k] += m.e[k];
  // Residuals (velocities of both bodies, as in the sweeps).
  const VisitBodies V(m, bodies);
  b[0] -= V.rowVelocity(m.lin[0], m.ang[0]);
  b[1] -= m.ang[1].dot(V.w);
  b[2] -= m.ang[2].dot(V.w);
  b[3] = m.rhs[0] - V.rowVelocity(m.lin[1], m.ang[3]);
  b[4] = m.rhs[1] - V.rowVelocity(m.lin[2], m.ang[4]);
  b[5] = m.rhs[2] - m.ang[5].dot(V.w);
  for (int k = 0; k < 3; ++k) b[3 + k] -= m.e[k] * F[k].lambda;
  // A degenerate axis carries nothing (as in the block).
  for (int a = 1; a < 3; ++a)
    if (!(a == 1 ? m.axisU : m.axisV)) {
      for (int c = 0; c < kM; ++c) K[a][c] = K[c][a] = 0;
      K[a][a] = 1;
      b[a] = 0;
    }
  Real x[kM];
  if (!ldltSolve6(K, b, x)) return false;
  // Bounds: the new normal impulses, then the friction inside mu times their new sum.
  Real nl[kMaxNormalBlock];
  Real sumN = 0;
  for (int i = 0; i < n; ++i) {
    nl[i] = R[i].lambda + x[0] + x[1] * P[i].u + x[2] * P[i].v;
    if (nl[i] < P[i].lo) return false;
    sumN += std::max<Real>(nl[i], 0);
  }
  Real fl[3];
  for (int k = 0; k < 3; ++k) fl[k] = F[k].lambda + x[3 + k];
  const Real lim = frictionLimit(m.mu, sumN);
  if (m.cone) {
    if (fl[0] * fl[0] + fl[1] * fl[1] > lim * lim) return false;
  } else if (std::abs(fl[0]) > lim || std::abs(fl[1]) > lim) {
    return false;
  }
  if (std::abs(fl[2]) > frictionLimit(m.muTwist, sumN)) return false;
  for (int i = 0; i < n; ++i) R[i].lambda = nl[i];
  for (int k = 0; k < 3; ++k) F[k].lambda = fl[k];
  Vec6 dw = Vec6::Zero();
  for (int a = 0; a < kM; ++a) dw += m.w[a] * x[a];
  const Vec3 dl = m.lin[0] * x[0] + m.lin[1] * x[3] + m.lin[2] * x[4];
  bodies[size_t(fb)].v += (freeA ? im : -im) * dl;
  bodies[size_t(fb)].w += dw.segment<3>(side);
  return true;
}

/// The compact manifold whose rows start at `row`, or null (records sorted by row, or PgsBlocks::rowManifold).
const PgsBlocks::Manifold* compactAt(const PgsBlocks& pb, uint32_t row) {
  if (!pb.rowManifold.empty())
    return row < pb.rowManifold.size() && pb.rowManifold[row] >= 0 ? &pb.manifolds[size_t(pb.rowManifold[row])]
                                                                   : nullptr;
  auto it = std::lower_bound(pb.manifolds.begin(), pb.manifolds.end(), row,
                             [](const PgsBlocks::Manifold& m, uint32_t r) { return m.row < r; });
  return it != pb.manifolds.end() && it->row == row ? &*it : nullptr;
}
}  // namespace

// One range swept to convergence (issue 18, sweep scheduling: a function of its own so that the partitioned shock
// pass at the end of this file runs the same law).
void PgsSolver::shockRange(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies,
                           const ShockRange& sr, int maxSweeps, const PgsBlocks* blocks) {
  auto solveFrozen = [&](ConstraintRow& r, int frozen, Real lo, Real hi) -> Real {
    // Diagonal with only the free body's mass.
    Real k = r.e;
    if (frozen != 0 && r.bodyA >= 0) k += r.jLinA.dot(r.mJLinA) + r.jAngA.dot(r.mJAngA);
    if (frozen != 1 && r.bodyB >= 0) k += r.jLinB.dot(r.mJLinB) + r.jAngB.dot(r.mJAngB);
    if (!(k > 0)) return 0;
    const Real delta = (r.rhs - rowVelocity(r, bodies) - r.e * r.lambda) / k;
    const Real nl = std::clamp(r.lambda + delta, lo, hi);
    const Real d = nl - r.lambda;
    r.lambda = nl;
    if (d != 0) {
      if (frozen != 0 && r.bodyA >= 0) {
        bodies[r.bodyA].v += r.mJLinA * d;
        bodies[r.bodyA].w += r.mJAngA * d;
      }
      if (frozen != 1 && r.bodyB >= 0) {
        bodies[r.bodyB].v += r.mJLinB * d;
        bodies[r.bodyB].w += r.mJAngB * d;
      }
    }
    return d;
  };
  auto sweepRange = [&](const ShockRange& sr, Real& change, Real& scale) {
    // Normals (rows without a normalRow link) first, then the friction rows bounded by them.
    for (uint32_t i = sr.begin; i < sr.begin + sr.count; ++i) {
      if (rows[i].normalRow >= 0 || rows[i].pairedRow >= 0) continue;
      if (rows[i].blockCount > 1 && rows[i].blockBegin == int32_t(i)) {
        // A manifold's normal block, solved as in the sweeps (solveNormalBlock) with the lower body frozen.
        const uint32_t count = uint32_t(rows[i].blockCount);
        Real d = 0;
        if (solveNormalBlock(rows, bodies, i, sr.frozen, d, blocks)) {
          change = std::max(change, d);
          for (uint32_t k = i; k < i + count; ++k) scale = std::max(scale, std::abs(rows[k].lambda));
          i += count - 1;
          continue;
        }
      }
      change = std::max(change, std::abs(solveFrozen(rows[i], sr.frozen, rows[i].lo, rows[i].hi)));
      scale = std::max(scale, std::abs(rows[i].lambda));
    }
    for (uint32_t i = sr.begin; i < sr.begin + sr.count; ++i) {
      ConstraintRow& r = rows[i];
      if (r.normalRow < 0) continue;
      const Real lim = frictionLimit(r.mu, boundingNormal(rows, r));
      if (r.pairedRow == int32_t(i) + 1) {
        ConstraintRow& s = rows[i + 1];
        change = std::max(change, std::abs(solveFrozen(r, sr.frozen, -lim, lim)));
        change = std::max(change, std::abs(solveFrozen(s, sr.frozen, -lim, lim)));
        const Real mag = std::sqrt(r.lambda * r.lambda + s.lambda * s.lambda);
        if (mag > lim) {
          // Project the pair back onto the disc and undo the excess on the free body.
          const Real sc = mag > 0 ? lim / mag : 0;
          const Real d1 = r.lambda * sc - r.lambda, d2 = s.lambda * sc - s.lambda;
          r.lambda += d1;
          s.lambda += d2;
          for (auto [row, d] : {std::pair<ConstraintRow*, Real>{&r, d1}, {&s, d2}}) {
            if (sr.frozen != 0 && row->bodyA >= 0) {
              bodies[row->bodyA].v += row->mJLinA * d;
              bodies[row->bodyA].w += row->mJAngA * d;
            }
            if (sr.frozen != 1 && row->bodyB >= 0) {
              bodies[row->bodyB].v += row->mJLinB * d;
              bodies[row->bodyB].w += row->mJAngB * d;
            }
          }
        }
        ++i;
      } else {
        change = std::max(change, std::abs(solveFrozen(r, sr.frozen, -lim, lim)));
      }
    }
  };
  if (blocks) {
    // DESIGN (issue 18, compact contact arrays): a manifold support reads the compact record the sweeps used.
    if (const PgsBlocks::Manifold* m = compactAt(*blocks, sr.begin)) {
      if (solveSupportCompact(rows, bodies, sr, *blocks, *m)) return;
    } else if (solveSupportExactly(rows, bodies, sr, *blocks)) {
      return;
    }
  }
  ensureBlockRows(rows, bodies, sr.begin, sr.begin + sr.count, blocks);  // the sweeps read the rows' M^-1 J^T
  for (int sweep = 0; sweep < maxSweeps; ++sweep) {
    Real change = 0, scale = 0;
    sweepRange(sr, change, scale);
    // Converged: the support's impulses moved by less than kShockTolerance of their size.
    if (change <= kShockTolerance * scale) break;
  }
}

namespace {
inline void recordRange(const std::vector<ConstraintRow>& rows, const PgsSolver::ShockRange& sr,
                        const PgsSolver::ShockRecord& record) {
  if (!record.lambda || sr.begin >= record.end) return;
  for (uint32_t i = sr.begin; i < sr.begin + sr.count; ++i) record.lambda[i] = rows[i].lambda;
}
}  // namespace

void PgsSolver::shockPass(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies,
                          const std::vector<ShockRange>& ranges, int maxSweeps, const PgsBlocks* blocks,
                          const ShockRecord& record) {
  for (const ShockRange& sr : ranges) {
    recordRange(rows, sr, record);
    shockRange(rows, bodies, sr, maxSweeps, blocks);
  }
}

// ---- issue 18 (sweep scheduling): graph-coloured sweeps (pgs.h PgsColouring) ----
// DESIGN (docs/solver-internals.md "Coloured sweeps"): greedy colouring in the serial sweep's unit order, the
// lowest colour neither of a unit's movable bodies holds yet (a 64-bit mask per body), then a stable counting
// sort of the units by colour. A body's velocity is the only state two units share (a unit's friction rows read
// only its own normal rows), so units of one colour commute exactly and the thread count cannot change a bit.
// Static bodies are read by many units of one colour (pyramid20's ground by all 20 bottom boxes); the sweeps
// add zero impulses to them, which would still be concurrent writes, so each such unit reads a private copy.
namespace {
inline bool movable(const SolverBodyState& b) { return b.invMass > 0 || !b.invInertia.isZero(0); }
}  // namespace

void PgsSolver::colour(const std::vector<ConstraintRow>& rows, const std::vector<SolverBodyState>& bodies,
                       PgsColouring& c) {
  const size_t nu = c.units.size();
  c.bodyMask.assign(bodies.size(), 0);
  c.unitColour.resize(nu);
  constexpr uint8_t kNone = 64;
  uint32_t count[kNone + 1] = {};
  for (size_t u = 0; u < nu; ++u) {
    const PgsColouring::Unit& un = c.units[u];
    uint64_t used = 0;
    for (uint32_t i = un.begin; i < un.begin + un.count; ++i)
      for (const int32_t b : {rows[i].bodyA, rows[i].bodyB})
        if (b >= 0 && movable(bodies[size_t(b)])) used |= c.bodyMask[size_t(b)];
    uint8_t col = kNone;
    if (~used != 0) col = uint8_t(std::countr_zero(~used));
    c.unitColour[u] = col;
    ++count[col];
    if (col == kNone) continue;
    for (uint32_t i = un.begin; i < un.begin + un.count; ++i)
      for (const int32_t b : {rows[i].bodyA, rows[i].bodyB})
        if (b >= 0 && movable(bodies[size_t(b)])) c.bodyMask[size_t(b)] |= uint64_t(1) << col;
  }
  int numColours = 0;
  for (int k = 0; k < kNone; ++k)
    if (count[k]) numColours = k + 1;
  c.lastGroupSerial = count[kNone] > 0;
  const int groups = numColours + (c.lastGroupSerial ? 1 : 0);
  c.colourStart.assign(size_t(groups) + 1, 0);
  for (int k = 0; k < numColours; ++k) c.colourStart[size_t(k) + 1] = c.colourStart[size_t(k)] + count[k];
  if (c.lastGroupSerial) c.colourStart[size_t(groups)] = c.colourStart[size_t(numColours)] + count[kNone];
  uint32_t next[kNone + 1];
  for (int k = 0; k < numColours; ++k) next[k] = c.colourStart[size_t(k)];
  next[kNone] = c.colourStart[size_t(numColours)];
  c.sorted.resize(nu);
  for (size_t u = 0; u < nu; ++u) c.sorted[next[c.unitColour[u]]++] = c.units[u];
}

Real PgsSolver::iterate(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, int iterations,
                        const PgsBlocks* blocks, PgsColouring& c) {
  // The coloured sweeps read every row: any normal block whose rows PgsSolver::prepare deferred is prepared
  // first (solve_stage.cpp does not defer for this path; a caller that did pays here).
  ensureBlockRows(rows, bodies, 0, rows.size(), blocks);
  // Private copies of static bodies: one per (unit, side) that reads one.
  const size_t numBodies = bodies.size();
  c.remapped.clear();
  for (const PgsColouring::Unit& un : c.sorted) {
    int32_t original[2] = {-1, -1}, copy[2] = {-1, -1};
    for (uint32_t i = un.begin; i < un.begin + un.count; ++i)
      for (int side = 0; side < 2; ++side) {
        int32_t& b = side == 0 ? rows[i].bodyA : rows[i].bodyB;
        if (b < 0 || movable(bodies[size_t(b)])) continue;
        c.remapped.push_back({i, side, b});
        if (b != original[side]) {
          original[side] = b;
          copy[side] = int32_t(bodies.size());
          const SolverBodyState body = bodies[size_t(b)];
          bodies.push_back(body);
        }
        b = copy[side];
      }
  }
  const int groups = int(c.colourStart.size()) - 1;
  const int parallelGroups = groups - (c.lastGroupSerial ? 1 : 0);
  Real maxDelta = 0;
  const PgsColouring::Unit* units = c.sorted.data();
  const uint32_t* start = c.colourStart.data();
  // Threads pay off only with enough units per colour; the result is the same either way.
  const bool parallel = c.sorted.size() >= 64;
#pragma omp parallel if (parallel)
  {
    Real local = 0;
    for (int it = 0; it < iterations; ++it) {
      const bool forward = it % 2 == 0;
      local = 0;
      for (int g = 0; g < groups; ++g) {
        const int k = forward ? g : groups - 1 - g;
        if (k >= parallelGroups) {
#pragma omp single
          for (uint32_t u = start[k]; u < start[k + 1]; ++u)
            local = std::max(local, sweepRows(rows, bodies, units[u].begin, units[u].begin + units[u].count,
                                              forward, blocks));
          // (implicit barrier)
          continue;
        }
#pragma omp for schedule(static)
        for (int64_t u = int64_t(start[k]); u < int64_t(start[k + 1]); ++u)
          local = std::max(local, sweepRows(rows, bodies, units[u].begin, units[u].begin + units[u].count,
                                            forward, blocks));
        // (implicit barrier: the next colour sees this one's velocities)
      }
    }
#pragma omp critical(scree_pgs_coloured_max)
    maxDelta = std::max(maxDelta, local);
  }
  // Back to the shared static bodies.
  for (const PgsColouring::Remap& r : c.remapped) (r.side == 0 ? rows[r.row].bodyA : rows[r.row].bodyB) = r.body;
  bodies.resize(numBodies);
  return maxDelta;
}

// ---- issue 18 (sweep scheduling): partitioned sweeps (pgs.h PgsPartition; the cut in pgs_partition.cpp) ----
// DESIGN (docs/solver-internals.md "Partitioned sweeps"): a forward sweep visits region 0's units, region 1's,
// then the boundary's; a backward sweep the boundary's, then the regions', all reversed. The regions share no
// movable body, so region 0 and region 1 commute exactly and run on two threads at once; on one thread they run
// one after the other with the same bits. The boundary runs on thread 0 between barriers. Since the sweeps
// alternate direction, a forward sweep's boundary is followed by the next backward sweep's boundary and a
// backward sweep's regions by the next forward sweep's regions, each on the same thread, so every sweep needs
// one barrier (none when the boundary is empty). Manifold contacts are visited from the compact records
// (PgsBlocks::Manifold), as in the serial sweeps: before this, the partitioned sweeps visited ConstraintRows,
// which made their solve stage about 40 % slower than the serial one on one thread (pyramid20, 0.86 against
// 0.62 ms). The threads are the persistent team (scree/core/parallel.h runTeam), not an OpenMP region: see there.
//
// DESIGN (memory layout; docs/solver-internals.md "Partitioned sweeps: each thread's own cache lines"): the sweeps
// run on their own copy of the bodies (PgsPartition::local): region 0's movable bodies, the static and kinematic
// bodies its units (and the boundary's) touch, a gap of 1 KB, then region 1's likewise. The compact records and
// their points are laid out region 0, region 1, boundary, with a gap record after each group; a record's
// bodies are local indices, and the rows of the other units are re-indexed for the sweeps (compactBlock's
// fallback maps its manifold's rows for its call). At the end the movable bodies are copied back and every index
// points at the shared bodies again. Why: in the shared arrays the two regions' bodies and records alternate
// (bodies are numbered as the scene made them, records in contact order), and a line of one region sits next
// to a line of the other. Although no line was written by both threads, pyramid20's region sweeps ran at less
// than half speed on two threads: 0.33 ms per thread per step for half the units, against 0.27 ms for all of
// them on one thread (perf: the time in the loads of bodies and of the records' body indices). Spacing the
// bodies 256 bytes apart and the records 128 bytes apart cured it (0.15 ms per thread), and 64-byte alignment
// alone did not, so the lines a thread reads were taken from the other thread's cache by their neighbours
// (the L2 fetches lines in pairs). The local layout gives the same separation without padding every body:
// region sweeps 0.15-0.18 ms per thread. Static bodies get a private copy per region, so that no two threads store
// to one body even when adding zero. The result is the serial sweeps' over the units in partition order, bit
// for bit (test_unit_compact_sweeps).
namespace {
/// One unit: its compact manifold record, or its ConstraintRows.
inline Real visitUnit(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies,
                      const PgsPartition::Unit& un, int32_t manifold, bool forward, PgsBlocks* blocks) {
  if (manifold < 0) return sweepRows(rows, bodies, un.begin, un.begin + un.count, forward, blocks);
  PgsBlocks::Manifold& m = blocks->manifolds[size_t(manifold)];
  VisitBodies V(m, bodies);
  Real d;
  if (forward) {
    d = compactFriction(m, V, true);
    d = std::max(d, compactBlock(*blocks, m, rows, bodies, V, true));
  } else {
    d = compactBlock(*blocks, m, rows, bodies, V, false);
    d = std::max(d, compactFriction(m, V, false));
  }
  V.store(m, bodies);
  return d;
}

Real sweepUnits(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies,
                const PgsPartition::Unit* order, const int32_t* manifold, uint32_t first, uint32_t last,
                bool forward, PgsBlocks* blocks) {
  Real m = 0;
  if (forward) {
    for (uint32_t u = first; u < last; ++u)
      m = std::max(m, visitUnit(rows, bodies, order[u], manifold[u], true, blocks));
  } else {
    for (uint32_t u = last; u-- > first;) m = std::max(m, visitUnit(rows, bodies, order[u], manifold[u], false, blocks));
  }
  return m;
}

/// Threads for a partitioned stage: at most one per region and PgsPartition::maxThreads; 1 for small work (the
/// result is the same either way).
int partitionThreads(bool worthIt, const PgsPartition& p) {
  const int cap = p.maxThreads > 0 ? p.maxThreads : scree::getNumThreads();
  return worthIt ? std::max(1, std::min(PgsPartition::kRegions, cap)) : 1;
}
}  // namespace

Real PgsSolver::iterate(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies, int iterations,
                        PgsBlocks* blocks, PgsPartition& p) {
  constexpr int R = PgsPartition::kRegions;
  const size_t nb = bodies.size();
  const uint32_t* split = p.split;
  // Group g's units: region g's, and for region 0 the boundary's too (thread 0 sweeps both).
  auto forUnitsOf = [&](int g, auto&& f) {
    for (uint32_t u = split[g]; u < split[g + 1]; ++u) f(u);
    if (g == 0)
      for (uint32_t u = split[R]; u < split[R + 1]; ++u) f(u);
  };
  auto movableBody = [&](int32_t b) { return size_t(b) < p.bodyRegion.size() && p.bodyRegion[size_t(b)] >= 0; };
  // The bodies' local layout (PgsPartition::local): per region its movable bodies, the static and kinematic
  // bodies its units touch (private copies), then a gap; region g's slots are [slots[g], slots[g + 1]).
  constexpr int kGapBodies = 8;    // 1 KB: more than the two-line pairs the L2 prefetcher fetches together
  constexpr int kGapPoints = 32;   // about 1 KB of PgsBlocks::Point likewise
  size_t slots[R + 1];
  p.globalOf.clear();
  p.localOf.assign(size_t(R) * nb, -1);
  for (int g = 0; g < R; ++g) {
    slots[g] = p.globalOf.size();
    for (size_t b = 0; b < nb; ++b)
      if (movableBody(int32_t(b)) && p.bodyRegion[b] == g) {
        for (int h = 0; h < R; ++h) p.localOf[size_t(h) * nb + b] = int32_t(p.globalOf.size());
        p.globalOf.push_back(int32_t(b));
      }
    forUnitsOf(g, [&](uint32_t u) {
      const ConstraintRow& r = rows[p.order[u].begin];  // every row of a unit acts on the same two bodies
      for (const int32_t b : {r.bodyA, r.bodyB})
        if (b >= 0 && size_t(b) < nb && !movableBody(b) && p.localOf[size_t(g) * nb + size_t(b)] < 0) {
          p.localOf[size_t(g) * nb + size_t(b)] = int32_t(p.globalOf.size());
          p.globalOf.push_back(b);
        }
    });
    p.globalOf.insert(p.globalOf.end(), kGapBodies, -1);
  }
  slots[R] = p.globalOf.size();
  p.local.resize(p.globalOf.size());
  // Each unit's compact record (-1: its ConstraintRows), laid out group by group (region 0, region 1, boundary)
  // with a gap record and kGapPoints points after each group, so that no cache line (nor the line the prefetcher
  // pairs with it) holds records of two threads. Unit u of group g owns record u + g (a unit that is no compact
  // manifold leaves its record unused, n = -1) and, when it may be one (3 + n rows, n >= 2), n points from its
  // group's running count: the places follow from the units alone, so each thread fills its own groups' records.
  const size_t nu = p.order.size();
  p.unitManifold.assign(nu, -1);
  uint32_t pointBase[R + 2] = {};
  auto unitPoints = [](const PgsPartition::Unit& un) { return un.count >= 5 ? un.count - 3 : 0u; };
  if (blocks) {
    PgsBlocks& pb = *blocks;
    pb.plan.clear();
    pb.rowManifold.assign(rows.size(), -1);
    pb.manifolds.resize(nu + R + 1);
    for (int g = 0; g <= R; ++g) {
      uint32_t points = 0;
      for (uint32_t u = split[g]; u < split[g + 1]; ++u) points += unitPoints(p.order[u]);
      pointBase[g + 1] = pointBase[g] + points + kGapPoints;
      pb.manifolds[split[g + 1] + uint32_t(g)].n = -1;  // the gap after group g, never visited
    }
    pb.points.resize(pointBase[R + 1]);
  }
  // DESIGN (issue 18, two-thread scaling; docs/solver-internals.md "Each thread lays out and takes down its
  // region"): the local bodies, the records and the re-indexed rows of a group are written on the thread that
  // sweeps the group, and its impulses and velocities written back there, so that a region's rows (built and
  // prepared on its thread, contact_rows.cpp and PgsSolver::prepare) and its records stay in that thread's cache.
  // Stop 45 and before, the program thread read every row to lay out the records and wrote every row's impulse
  // back, so the second region's rows crossed between the cores twice per step. Same operations on the same data
  // in the same order per record and per body, so the same bits on any thread count.
  // Units [first, last) of group g; their points follow the units of the group before them.
  auto layOut = [&](int g, uint32_t first, uint32_t last) {
    const size_t view = size_t(g < R ? g : 0) * nb;
    uint32_t point = pointBase[g];
    for (uint32_t u = split[g]; u < first; ++u) point += unitPoints(p.order[u]);
    for (uint32_t u = first; u < last; ++u) {
      const uint32_t i = p.order[u].begin;
      int n = 0;
      if (blocks && compactUnit(rows, *blocks, i, n) && 3 + uint32_t(n) == p.order[u].count) {
        PgsBlocks& pb = *blocks;
        const int32_t record = int32_t(u) + g;
        p.unitManifold[u] = record;
        pb.rowManifold[i] = record;
        PgsBlocks::Manifold& m = pb.manifolds[size_t(record)];
        writeCompact(rows, bodies, pb, m, point, i, n,
                     [&pb, point](int k, const PgsBlocks::Point& q) { pb.points[point + uint32_t(k)] = q; });
        point += uint32_t(n);
        if (m.a >= 0 && size_t(m.a) < nb) m.a = p.localOf[view + size_t(m.a)];
        if (m.b >= 0 && size_t(m.b) < nb) m.b = p.localOf[view + size_t(m.b)];
        continue;
      }
      if (blocks) blocks->manifolds[u + uint32_t(g)].n = -1;
      point += unitPoints(p.order[u]);
      // Swept as ConstraintRows: a deferred normal block's rows are prepared first, on the shared bodies; then the
      // rows index the local layout until the end of the sweeps (a compact record's rows keep the shared
      // indices: compactBlock's fallback maps them for its call).
      ensureBlockRows(rows, bodies, i, i + p.order[u].count, blocks);
      for (uint32_t r = i; r < i + p.order[u].count; ++r)
        for (int32_t* b : {&rows[r].bodyA, &rows[r].bodyB})
          if (*b >= 0 && size_t(*b) < nb) *b = p.localOf[view + size_t(*b)];
    }
  };
  // Back to the shared indices (the shock pass reads them) and the impulses into the rows.
  auto toShared = [&](int32_t& b) {
    if (b >= 0 && size_t(b) < p.globalOf.size()) b = p.globalOf[size_t(b)];
  };
  auto takeDown = [&](uint32_t first, uint32_t last) {
    for (uint32_t u = first; u < last; ++u) {
      if (p.unitManifold[u] >= 0) {
        PgsBlocks::Manifold& m = blocks->manifolds[size_t(p.unitManifold[u])];
        writeBackRecord(rows, *blocks, m);
        toShared(m.a);
        toShared(m.b);
        continue;
      }
      for (uint32_t i = p.order[u].begin; i < p.order[u].begin + p.order[u].count; ++i) {
        toShared(rows[i].bodyA);
        toShared(rows[i].bodyB);
      }
    }
  };
  std::vector<SolverBodyState>& lb = p.local;
  const PgsPartition::Unit* order = p.order.data();
  const int32_t* manifold = p.unitManifold.data();
  const bool boundary = split[R + 1] > split[R];
  const int threads = partitionThreads(nu >= 64, p);
  Real lastSweep[R] = {};
  TeamBarrier barrier(threads);
  int ran = threads;
  runTeam(threads, [&](int t, int nt) {
    if (nt < threads) p.teamBusy = true;  // only the calling thread runs then (nt == 1)
    if (t == 0) ran = nt;
    auto owns = [&](int g) { return g % nt == t; };
    // The boundary's units of this thread: with phases and two threads, its share of each phase
    // (PgsPartition::boundaryPhases); else all of them for thread 0. The phases are in the serial order, so one
    // thread sweeping the boundary whole keeps the same order.
    const bool shared = p.boundaryPhases > 0 && nt > 1;
    const int phases = shared ? p.boundaryPhases : 1;
    auto boundaryShare = [&](int c, uint32_t& first, uint32_t& last) {
      if (!shared) {
        first = split[R];
        last = t == 0 ? split[R + 1] : split[R];
        return;
      }
      const uint32_t cb = p.boundarySplit[c], ce = p.boundarySplit[c + 1], mid = p.boundaryMid[c];
      first = t == 0 ? cb : mid;
      last = t == 0 ? mid : ce;
    };
    // Lay out: this thread's regions' local bodies, then its groups' records and rows. The boundary's first
    // visit comes after the first sweep's barrier, when the other region's local bodies are in place.
    for (int g = 0; g < R; ++g)
      if (owns(g))
        for (size_t k = slots[g]; k < slots[g + 1]; ++k)
          lb[k] = p.globalOf[k] >= 0 ? bodies[size_t(p.globalOf[k])] : SolverBodyState{};
    for (int g = 0; g < R; ++g)
      if (owns(g)) layOut(g, split[g], split[g + 1]);
    for (int c = 0; c < phases; ++c) {
      uint32_t first, last;
      boundaryShare(c, first, last);
      layOut(R, first, last);
    }
    Real local = 0;
    auto regions = [&](bool forward) {
      for (int g = 0; g < R; ++g)
        if (owns(g))
          local = std::max(local, sweepUnits(rows, lb, order, manifold, split[g], split[g + 1], forward, blocks));
    };
    auto boundaryUnits = [&](int c, bool forward) {
      uint32_t first, last;
      boundaryShare(c, first, last);
      if (first < last) local = std::max(local, sweepUnits(rows, lb, order, manifold, first, last, forward, blocks));
    };
    // A forward sweep: the regions, then the boundary phase by phase; a backward sweep the reverse. The last
    // phase of a forward sweep and the first of the next backward sweep are the same units on the same threads,
    // so no barrier between them.
    for (int it = 0; it < iterations; ++it) {
      const bool forward = it % 2 == 0;
      local = 0;
      if (forward) {
        regions(true);
        if (boundary && nt > 1) barrier.wait();
        for (int c = 0; c < phases; ++c) {
          if (c > 0) barrier.wait();
          boundaryUnits(c, true);
        }
      } else {
        for (int c = phases; c-- > 0;) {
          boundaryUnits(c, false);
          if (c > 0) barrier.wait();
        }
        if (boundary && nt > 1) barrier.wait();
        regions(false);
      }
    }
    if (t < R) lastSweep[t] = local;
    // Take down: the groups' impulses and indices (no other thread reads them), then, once the boundary's last
    // sweep is over (a forward sweep ends with it), the regions' movable bodies (the static copies changed
    // nothing).
    for (int g = 0; g < R; ++g)
      if (owns(g)) takeDown(split[g], split[g + 1]);
    for (int c = 0; c < phases; ++c) {
      uint32_t first, last;
      boundaryShare(c, first, last);
      takeDown(first, last);
    }
    if (boundary && nt > 1 && iterations > 0 && (iterations - 1) % 2 == 0) barrier.wait();
    for (int g = 0; g < R; ++g)
      if (owns(g))
        for (size_t k = slots[g]; k < slots[g + 1]; ++k)
          if (p.globalOf[k] >= 0 && movableBody(p.globalOf[k])) bodies[size_t(p.globalOf[k])] = lb[k];
  });
  p.threadsRan = std::max(p.threadsRan, ran);
  Real maxDelta = 0;
  for (int t = 0; t < R; ++t) maxDelta = std::max(maxDelta, lastSweep[t]);
  return maxDelta;
}

// DESIGN (docs/solver-internals.md "Partitioned sweeps"): a shock range writes only its free body and reads its
// frozen one, whose writers (the ranges where it is free) all come earlier in the support order. So each range
// runs after the earlier ranges of its free body -- kept by giving every range of one free body to the same
// thread, in order -- and after the last range whose free body is its frozen one. Ranges go to the thread of
// their free body's region; a range whose frozen body belongs to the other thread waits (spinning on that
// thread's count of finished ranges) for that writer. Every range then sees exactly the velocities the serial
// pass shows it: the result is the serial shockPass's, bit for bit, on any number of threads.
// DESIGN (stop 49, the counts published): a thread used to publish its count of finished ranges after every range.
// Each publish is a store to a line the other thread is reading while it waits, so about 200 of them per pass in
// pyramid20 (one per support) kept taking that line between the cores. A waiter needs only the count its range
// waits for, so only the ranges whose end some range of the other list waits for publish; the counts are the same,
// so is every range's wait, and so are the bits. pyramid20 partitioned on two threads (bench_rigid_stages, an Intel
// Xeon KVM guest, 11 interleaved rounds in two runs, medians of 3 repetitions): 0.451 ms per step against 0.464
// (median of the rounds), faster in 7 of the 11 (6 of 6 in one run, 1 of 5 in the other): a small gain.
void PgsSolver::shockSchedule(const std::vector<ShockRange>& ranges, size_t nb, PgsPartition& p) {
  constexpr int R = PgsPartition::kRegions;
  auto listOf = [&](int32_t b) {
    return b >= 0 && size_t(b) < p.bodyRegion.size() && p.bodyRegion[size_t(b)] > 0 ? int(p.bodyRegion[size_t(b)]) : 0;
  };
  for (int r = 0; r < R; ++r) {
    p.shockList[r].clear();
    p.shockWait[r].clear();
    p.shockPublish[r].clear();
  }
  p.shockDone.assign(nb, 0);
  for (uint32_t k = 0; k < ranges.size(); ++k) {
    const ShockRange& sr = ranges[k];
    const int32_t freeB = sr.freeBody, frozenB = sr.frozenBody;
    const int l = listOf(freeB);
    uint32_t wait = 0;
    if (frozenB >= 0 && size_t(frozenB) < nb && listOf(frozenB) != l) wait = p.shockDone[size_t(frozenB)];
    p.shockList[l].push_back(k);
    p.shockWait[l].push_back(wait);
    if (freeB >= 0 && size_t(freeB) < nb) p.shockDone[size_t(freeB)] = uint32_t(p.shockList[l].size());
    p.shockPublish[l].push_back(0);
    if (wait > 0) p.shockPublish[1 - l][wait - 1] = 1;
  }
}

void PgsSolver::shockPass(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& bodies,
                          const std::vector<ShockRange>& ranges, int maxSweeps, const PgsBlocks* blocks,
                          PgsPartition& p, const ShockRecord& record) {
  constexpr int R = PgsPartition::kRegions;
  const int threads = partitionThreads(ranges.size() >= 16, p);
  if (threads < 2) {
    shockPass(rows, bodies, ranges, maxSweeps, blocks, record);
    p.threadsRan = std::max(p.threadsRan, 1);
    return;
  }
  shockSchedule(ranges, bodies.size(), p);
  struct alignas(64) Counter {
    std::atomic<uint32_t> v{0};
  };
  Counter done[R];
  int ran = threads;
  runTeam(threads, [&](int t, int nt) {
    if (t == 0) ran = nt;
    if (nt < R) {
      // Fewer threads than lists (the team was busy): the serial pass (the same bits).
      p.teamBusy = true;  // only the calling thread runs then (nt == 1)
      if (t == 0) shockPass(rows, bodies, ranges, maxSweeps, blocks, record);
    } else if (t < R) {
      const int other = 1 - t;
      const std::vector<uint32_t>& list = p.shockList[t];
      const std::vector<uint32_t>& wait = p.shockWait[t];
      const std::vector<uint8_t>& publishes = p.shockPublish[t];
      for (size_t j = 0; j < list.size(); ++j) {
        recordRange(rows, ranges[list[j]], record);  // its own rows: no wait needed
        waitAtLeast(done[other].v, wait[j]);
        shockRange(rows, bodies, ranges[list[j]], maxSweeps, blocks);
        if (publishes[j]) publish(done[t].v, uint32_t(j + 1));
      }
    }
  });
  p.threadsRan = std::max(p.threadsRan, ran);
}

}  // namespace scree::detail
