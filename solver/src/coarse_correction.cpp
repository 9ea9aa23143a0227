// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Two-level (coarse) correction of contact loads between PGS sweeps: coarse_correction.h holds the design.
#include "coarse_correction.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "contact_rows.h"

namespace scree::detail {

// A = the triplets summed (duplicates in triplet order), then each diagonal times 1 + kRegularisation. While the
// triplets' (row, column) sequence is last call's, their values are added straight into the kept matrix's value
// array (tripletSlot_): the same sums in the same order as Eigen's setFromTriplets, so the same bits, without its
// sort, its temporary row-major copy and their allocations (setFromTriplets was about a sixth of the correction's
// time, docs/solver-internals.md "Coarse correction").
void CoarseCorrection::assemble(int m) {
  const size_t nt = triplets_.size();
  bool same = keptRows_ == m && tripletKey_.size() == nt;
  for (size_t t = 0; same && t < nt; ++t)
    same = tripletKey_[t].first == triplets_[t].row() && tripletKey_[t].second == triplets_[t].col();
  if (!same) {
    A_.resize(m, m);
    A_.setFromTriplets(triplets_.begin(), triplets_.end());
    tripletKey_.resize(nt);
    tripletSlot_.resize(nt);
    for (size_t t = 0; t < nt; ++t) {
      const int r = triplets_[t].row(), c = triplets_[t].col();
      tripletKey_[t] = {r, c};
      const int* begin = A_.innerIndexPtr() + A_.outerIndexPtr()[c];
      const int* end = A_.innerIndexPtr() + A_.outerIndexPtr()[c + 1];
      tripletSlot_[t] = int(std::lower_bound(begin, end, r) - A_.innerIndexPtr());
    }
    diagonalSlot_.resize(size_t(m));
    for (int j = 0; j < m; ++j) {
      const int* begin = A_.innerIndexPtr() + A_.outerIndexPtr()[j];
      const int* end = A_.innerIndexPtr() + A_.outerIndexPtr()[j + 1];
      diagonalSlot_[size_t(j)] = int(std::lower_bound(begin, end, j) - A_.innerIndexPtr());
    }
    keptRows_ = m;
  } else {
    // setFromTriplets starts each entry from its first triplet's value; 0 + x is x, so the sums agree.
    Real* value = A_.valuePtr();
    std::fill(value, value + A_.nonZeros(), Real(0));
    for (size_t t = 0; t < nt; ++t) value[tripletSlot_[t]] += triplets_[t].value();
  }
  for (int j = 0; j < m; ++j) A_.valuePtr()[diagonalSlot_[size_t(j)]] *= 1 + kRegularisation;
}

namespace {

/// What is left of row q's equation J v + e lambda = rhs.
Real rowResidual(const ConstraintRow& q, const std::vector<SolverBodyState>& sb) {
  return q.rhs - rowVelocity(q, sb) - q.e * q.lambda;
}

/// Applies impulse d along row q through the bodies' masses and inertias (not the row's M^-1 J^T, which
/// PgsSolver::prepare leaves unset on deferred block rows: pgs.cpp's applyImpulse cannot serve here).
void applyImpulse(const ConstraintRow& q, Real d, std::vector<SolverBodyState>& sb) {
  if (d == 0) return;
  if (q.bodyA >= 0) {
    SolverBodyState& b = sb[size_t(q.bodyA)];
    b.v += b.invMass * q.jLinA * d;
    b.w += b.invInertia * q.jAngA * d;
  }
  if (q.bodyB >= 0) {
    SolverBodyState& b = sb[size_t(q.bodyB)];
    b.v += b.invMass * q.jLinB * d;
    b.w += b.invInertia * q.jAngB * d;
  }
}

/// Sum of a friction row's normal impulses (each clamped at 0), with the per-row changes delta where given.
Real normalSum(const ConstraintRow& q, const std::vector<ConstraintRow>& rows, const std::vector<int>* slot,
               const std::vector<Real>* delta) {
  Real n = 0;
  for (int k = 0; k < q.normalCount; ++k) {
    const size_t i = size_t(q.normalRow + k);
    Real l = rows[i].lambda;
    if (slot && (*slot)[i] >= 0) l += (*delta)[size_t((*slot)[i])];
    n += std::max(l, Real(0));
  }
  return n;
}

}  // namespace

void CoarseCorrection::addGroup(const std::vector<ConstraintRow>& rows, const std::vector<SolverBodyState>& sb,
                                uint32_t coupling, Kind kind) {
  const uint32_t b0 = entryBegin_.back();
  Vec3 la = Vec3::Zero(), aa = Vec3::Zero(), lb = Vec3::Zero(), ab = Vec3::Zero();
  Real res = 0;
  for (uint32_t t = b0; t < entries_.size(); ++t) {
    const ConstraintRow& q = rows[entries_[t].first];
    const Real w = entries_[t].second;
    la += w * q.jLinA;
    aa += w * q.jAngA;
    lb += w * q.jLinB;
    ab += w * q.jAngB;
    res += w * rowResidual(q, sb);
  }
  const ConstraintRow& q0 = rows[entries_[b0].first];
  coupling_.push_back(coupling);
  kind_.push_back(kind);
  linA_.push_back(la);
  angA_.push_back(aa);
  linB_.push_back(lb);
  angB_.push_back(ab);
  residual_.push_back(res);
  bodyA_.push_back(q0.bodyA);
  bodyB_.push_back(q0.bodyB);
  entryBegin_.push_back(uint32_t(entries_.size()));
}

CoarseCorrection::Result CoarseCorrection::apply(std::vector<ConstraintRow>& rows, std::vector<SolverBodyState>& sb,
                                                 const std::vector<CouplingRange>& couplings) {
  Result result;
  entryBegin_.assign(1, 0);
  entries_.clear();
  coupling_.clear();
  kind_.clear();
  linA_.clear();
  angA_.clear();
  linB_.clear();
  angB_.clear();
  residual_.clear();
  bodyA_.clear();
  bodyB_.clear();

  // ---- the coarse groups, manifold by manifold (a manifold's groups are consecutive) ----
  for (uint32_t k = 0; k < couplings.size(); ++k) {
    const CouplingRange& cr = couplings[k];
    if (cr.joint) continue;
    Real load = 0;
    int n = 0;
    Vec3 mean = Vec3::Zero();
    for (uint32_t i = cr.begin; i < cr.begin + cr.count; ++i) {
      const ConstraintRow& q = rows[i];
      if (q.friction) continue;
      load += q.lambda;
      mean += q.jAngA;
      ++n;
    }
    if (n == 0 || !(load > 0)) continue;
    for (uint32_t i = cr.begin; i < cr.begin + cr.count; ++i)
      if (!rows[i].friction) entries_.push_back({i, Real(1)});
    addGroup(rows, sb, k, LOAD);
    if (n >= 2) {
      // The points' offsets from the manifold's centre, turned by 90 degrees about the normal: jAngA_i - mean =
      // (centre-to-point) x normal for body A. Their principal axes are the manifold's.
      mean /= Real(n);
      Mat3 spread = Mat3::Zero();
      for (uint32_t i = cr.begin; i < cr.begin + cr.count; ++i) {
        if (rows[i].friction) continue;
        const Vec3 g = rows[i].jAngA - mean;
        spread += g * g.transpose();
      }
      const Eigen::SelfAdjointEigenSolver<Mat3> es(spread);
      const Vec3 ev = es.eigenvalues();  // ascending; ev[0] ~ 0 (the normal)
      constexpr Real kSquare = 1.5 * 1.5;  // spread ratio below which both axes get a tilt
      for (int ax = 2; ax >= 1; --ax) {
        if (!(ev[ax] > 1e-12 * (1 + ev[2]))) continue;
        if (ax == 1 && ev[2] > kSquare * ev[1]) continue;
        const Vec3 a = es.eigenvectors().col(ax);
        const Real scale = std::sqrt(Real(n) / ev[ax]);  // sum of the weights' squares = n
        for (uint32_t i = cr.begin; i < cr.begin + cr.count; ++i)
          if (!rows[i].friction) entries_.push_back({i, (rows[i].jAngA - mean).dot(a) * scale});
        addGroup(rows, sb, k, TILT);
      }
    }
    for (uint32_t i = cr.begin; i < cr.begin + cr.count; ++i) {
      const ConstraintRow& q = rows[i];
      // Manifold tangent rows only (the twist row has no linear part), and only while they stick.
      if (!q.friction || q.jLinA.squaredNorm() == 0 || q.normalRow < 0) continue;
      Real t = std::abs(q.lambda);
      if (q.pairedRow >= 0) t = std::hypot(q.lambda, rows[size_t(q.pairedRow)].lambda);
      if (!(t < 0.999 * q.mu * normalSum(q, rows, nullptr, nullptr))) continue;
      entries_.push_back({i, Real(1)});
      addGroup(rows, sb, k, FRICTION);
    }
  }
  const int m = int(coupling_.size());
  result.unknowns = m;
  if (m == 0) return result;

  // ---- the coarse operator P^T (J M^-1 J^T + E) P, lower triangle ----
  triplets_.clear();
  for (int g0 = 0; g0 < m;) {  // compliance: a manifold's groups share its rows
    int g1 = g0;
    while (g1 < m && coupling_[size_t(g1)] == coupling_[size_t(g0)]) ++g1;
    for (int g = g0; g < g1; ++g)
      for (int h = g0; h <= g; ++h) {
        Real v = 0;
        for (uint32_t a = entryBegin_[size_t(g)]; a < entryBegin_[size_t(g) + 1]; ++a)
          for (uint32_t b = entryBegin_[size_t(h)]; b < entryBegin_[size_t(h) + 1]; ++b)
            if (entries_[a].first == entries_[b].first)
              v += entries_[a].second * entries_[b].second * rows[entries_[a].first].e;
        if (g == h) v += 1e-12;  // a group between a kinematic body and the world: e alone
        triplets_.emplace_back(g, h, v);  // kept when 0 too: the pattern then does not depend on the values
      }
    g0 = g1;
  }
  byBody_.resize(sb.size());
  for (auto& l : byBody_) l.clear();
  for (int j = 0; j < m; ++j) {
    if (bodyA_[size_t(j)] >= 0 && sb[size_t(bodyA_[size_t(j)])].invMass > 0) byBody_[size_t(bodyA_[size_t(j)])].push_back({j, 0});
    if (bodyB_[size_t(j)] >= 0 && sb[size_t(bodyB_[size_t(j)])].invMass > 0) byBody_[size_t(bodyB_[size_t(j)])].push_back({j, 1});
  }
  for (size_t b = 0; b < sb.size(); ++b) {
    const SolverBodyState& B = sb[b];
    for (const auto& [j, sj] : byBody_[b]) {
      const Vec3 wl = B.invMass * (sj ? linB_[size_t(j)] : linA_[size_t(j)]);
      const Vec3 wa = B.invInertia * (sj ? angB_[size_t(j)] : angA_[size_t(j)]);
      for (const auto& [k, sk] : byBody_[b]) {
        if (k > j) continue;
        const Vec3& lk = sk ? linB_[size_t(k)] : linA_[size_t(k)];
        const Vec3& ak = sk ? angB_[size_t(k)] : angA_[size_t(k)];
        triplets_.emplace_back(j, k, lk.dot(wl) + ak.dot(wa));
      }
    }
  }
  assemble(m);
  // Symbolic analysis only when the pattern changed (the contact set of a resting scene holds for many steps).
  const bool same = analysed_ && int(patternOuter_.size()) == m + 1 &&
                    std::equal(patternOuter_.begin(), patternOuter_.end(), A_.outerIndexPtr()) &&
                    int(patternInner_.size()) == A_.nonZeros() &&
                    std::equal(patternInner_.begin(), patternInner_.end(), A_.innerIndexPtr());
  if (!same) {
    ldlt_.analyzePattern(A_);
    patternOuter_.assign(A_.outerIndexPtr(), A_.outerIndexPtr() + m + 1);
    patternInner_.assign(A_.innerIndexPtr(), A_.innerIndexPtr() + A_.nonZeros());
    analysed_ = true;
    result.analysed = true;
  }
  // The numeric factorisation only when A changed: within a step the Jacobians and masses are fixed, so the
  // second correction of a step gets the same operator, bit for bit, whenever its groups are the first's (a
  // resting scene: the same loaded manifolds and the same sticking rows). A refinement leaves the factor of its
  // held system, so the next call factors again.
  const bool sameValues = same && factorOfA_ && int(factoredValues_.size()) == A_.nonZeros() &&
                          std::equal(factoredValues_.begin(), factoredValues_.end(), A_.valuePtr());
  if (!sameValues) {
    factorOfA_ = false;
    ldlt_.factorize(A_);
    if (ldlt_.info() != Eigen::Success) {
      analysed_ = false;
      return result;
    }
    factoredValues_.assign(A_.valuePtr(), A_.valuePtr() + A_.nonZeros());
    factorOfA_ = true;
    result.factorised = true;
  }
  const Eigen::Map<const Eigen::Matrix<Real, Eigen::Dynamic, 1>> r(residual_.data(), m);
  Eigen::Matrix<Real, Eigen::Dynamic, 1> mu = ldlt_.solve(r);
  if (!mu.allFinite()) return result;

  // ---- rows the correction may change: every entry's row and the partners of friction rows ----
  touched_.clear();
  lambda0_.clear();
  residual0_.clear();
  slot_.assign(rows.size(), -1);
  auto touch = [&](uint32_t i) {
    if (slot_[i] >= 0) return;
    slot_[i] = int(touched_.size());
    touched_.push_back(i);
    lambda0_.push_back(rows[i].lambda);
    residual0_.push_back(rowResidual(rows[i], sb));
  };
  for (const auto& [i, w] : entries_) {
    touch(i);
    if (rows[i].friction && rows[i].pairedRow >= 0) touch(uint32_t(rows[i].pairedRow));
  }
  auto computeDelta = [&]() {
    delta_.assign(touched_.size(), 0);
    for (int g = 0; g < m; ++g)
      for (uint32_t a = entryBegin_[size_t(g)]; a < entryBegin_[size_t(g) + 1]; ++a)
        delta_[size_t(slot_[entries_[a].first])] += entries_[a].second * mu[g];
  };

  // ---- bounds by refinement: groups that would leave their bounds are fixed, the rest solved again ----
  // A manifold that separates (its load group's residual < 0: it wants less load) and would go below zero is
  // released: its load change is fixed at -load (its points' mean to zero) and its tilts at no change. Only
  // when none separates are the other violated manifolds held at no change (tilts first, then the load): a
  // contact below a separating one is usually pulled below zero only through it (measured on two boxes, the
  // top one flying off: holding both left the lower box's load wrong). Friction groups pushed out of their cone
  // are held at no change.
  fixed_.assign(size_t(m), 0);
  target_.assign(size_t(m), 0);
  bool settled = false;
  for (int round = 0;; ++round) {
    computeDelta();
    bool any = false, released = false;
    for (int pass = 0; pass < 2 && !released; ++pass)
      for (int g = 0; g < m; ++g) {
        if (kind_[size_t(g)] != LOAD || fixed_[size_t(g)]) continue;
        bool below = false;
        for (uint32_t a = entryBegin_[size_t(g)]; a < entryBegin_[size_t(g) + 1] && !below; ++a) {
          const uint32_t i = entries_[a].first;
          below = rows[i].lambda + delta_[size_t(slot_[i])] < rows[i].lo;
        }
        if (!below) continue;
        if (pass == 0 && !(residual_[size_t(g)] < 0)) continue;
        bool tilts = false;
        for (int h = g + 1; h < m && coupling_[size_t(h)] == coupling_[size_t(g)]; ++h)
          if (kind_[size_t(h)] == TILT && !fixed_[size_t(h)]) fixed_[size_t(h)] = tilts = true;
        if (pass == 0) {
          Real load = 0;
          for (uint32_t a = entryBegin_[size_t(g)]; a < entryBegin_[size_t(g) + 1]; ++a) load += rows[entries_[a].first].lambda;
          fixed_[size_t(g)] = 1;
          target_[size_t(g)] = -load / Real(entryBegin_[size_t(g) + 1] - entryBegin_[size_t(g)]);
          released = true;
        } else if (!tilts) {
          fixed_[size_t(g)] = 1;
        }
        any = true;
      }
    for (int g = 0; g < m; ++g) {
      if (kind_[size_t(g)] != FRICTION || fixed_[size_t(g)]) continue;
      const uint32_t i = entries_[entryBegin_[size_t(g)]].first;
      const ConstraintRow& q = rows[i];
      Real t = std::abs(q.lambda + delta_[size_t(slot_[i])]);
      if (q.pairedRow >= 0) {
        const size_t p = size_t(q.pairedRow);
        t = std::hypot(t, rows[p].lambda + delta_[size_t(slot_[p])]);
      }
      if (t > q.mu * normalSum(q, rows, &slot_, &delta_)) {
        fixed_[size_t(g)] = 1;
        any = true;
      }
    }
    if (!any) {
      settled = true;
      break;
    }
    if (round == kRounds) break;
    ++result.refinements;
    held_ = A_;
    Eigen::Matrix<Real, Eigen::Dynamic, 1> rh = r;
    for (int g = 0; g < m; ++g)
      if (fixed_[size_t(g)]) {  // mu_g = target_g up to 1e-8 of the group's own stiffness
        held_.coeffRef(g, g) *= 1e8;
        rh[g] = held_.coeff(g, g) * target_[size_t(g)];
      }
    factorOfA_ = false;
    ldlt_.factorize(held_);
    if (ldlt_.info() != Eigen::Success) return result;
    mu = ldlt_.solve(rh);
    if (!mu.allFinite()) return result;
  }
  // Still leaving its bounds after kRounds refinements: the contact set is changing faster than the coarse space
  // follows (a collapsing pile). Clamping such a correction and scaling it by the descent guard gave pyramid30
  // (which the correction does not hold) boxes thrown at 28 m/s, where the plain sweeps' collapse stays under
  // 7 m/s; so the correction is skipped and the sweeps go on alone.
  if (!settled) {
    result.skipped = true;
    return result;
  }

  // ---- apply: normal rows clamped at their bound, then friction rows against the new loads, cone projected ----
  v0_.resize(sb.size());
  w0_.resize(sb.size());
  for (size_t b = 0; b < sb.size(); ++b) {
    v0_[b] = sb[b].v;
    w0_[b] = sb[b].w;
  }
  for (size_t t = 0; t < touched_.size(); ++t) {
    ConstraintRow& q = rows[touched_[t]];
    if (q.friction) continue;
    const Real l = std::max(q.lambda + delta_[t], q.lo);
    applyImpulse(q, l - q.lambda, sb);
    q.lambda = l;
  }
  for (size_t t = 0; t < touched_.size(); ++t) {
    ConstraintRow& q = rows[touched_[t]];
    if (!q.friction || delta_[t] == 0) continue;
    const Real bound = q.mu * normalSum(q, rows, nullptr, nullptr);
    const Real l = std::clamp(q.lambda + delta_[t], -bound, bound);
    applyImpulse(q, l - q.lambda, sb);
    q.lambda = l;
  }
  for (size_t t = 0; t < touched_.size(); ++t) {
    ConstraintRow& q = rows[touched_[t]];
    if (!q.friction || q.pairedRow < int32_t(touched_[t])) continue;  // each pair once, from its first row
    ConstraintRow& p = rows[size_t(q.pairedRow)];
    const Real bound = q.mu * normalSum(q, rows, nullptr, nullptr), len = std::hypot(q.lambda, p.lambda);
    if (len > bound && len > 0) {
      const Real f = bound / len;
      applyImpulse(q, q.lambda * f - q.lambda, sb);
      q.lambda *= f;
      applyImpulse(p, p.lambda * f - p.lambda, sb);
      p.lambda *= f;
    }
  }

  // ---- descent guard: f(alpha) - f(0) = alpha^2 d^T A d / 2 - alpha d^T r along the applied change d ----
  Real dAd = 0, dr = 0;
  for (size_t t = 0; t < touched_.size(); ++t) {
    const ConstraintRow& q = rows[touched_[t]];
    const Real d = q.lambda - lambda0_[t];
    Real jdv = 0;
    if (q.bodyA >= 0) {
      const size_t a = size_t(q.bodyA);
      jdv += q.jLinA.dot(sb[a].v - v0_[a]) + q.jAngA.dot(sb[a].w - w0_[a]);
    }
    if (q.bodyB >= 0) {
      const size_t b = size_t(q.bodyB);
      jdv += q.jLinB.dot(sb[b].v - v0_[b]) + q.jAngB.dot(sb[b].w - w0_[b]);
    }
    dAd += d * (jdv + q.e * d);
    dr += d * residual0_[t];
  }
  result.alpha = (dr > 0 && dAd > 0) ? std::min(Real(1), dr / dAd) : Real(0);
  if (result.alpha < 1) {
    const Real alpha = result.alpha;
    for (size_t t = 0; t < touched_.size(); ++t) {
      ConstraintRow& q = rows[touched_[t]];
      q.lambda = lambda0_[t] + alpha * (q.lambda - lambda0_[t]);
    }
    for (size_t b = 0; b < sb.size(); ++b) {
      sb[b].v = v0_[b] + alpha * (sb[b].v - v0_[b]);
      sb[b].w = w0_[b] + alpha * (sb[b].w - w0_[b]);
    }
  }
  return result;
}

}  // namespace scree::detail
