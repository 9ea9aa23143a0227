// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scree/solver/direct.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#ifdef SCREE_WITH_SUITESPARSE
#include <cholmod.h>
#endif

namespace scree::detail {

namespace {
constexpr Real kInf = 1e299;  // |bound| beyond this is unbounded (rows use +-1e300)
inline Real frictionLimit(Real mu, Real lambdaN) {
  if (std::isinf(mu)) return 1e300;
  return mu * std::max<Real>(lambdaN, 0);
}
}  // namespace

#ifdef SCREE_WITH_SUITESPARSE

struct DirectSolver::Impl {
  cholmod_common cm;
  // One cached matrix, pattern and factor per form (index 0 Schur, 1 KKT).
  struct FormCache {
    cholmod_sparse* A = nullptr;
    cholmod_factor* L = nullptr;
    std::vector<int> p, i;  // pattern of the factorised matrix
  } cache[2];
  cholmod_dense* B = nullptr;
  cholmod_dense *X = nullptr, *Y = nullptr, *E = nullptr;

  // Scratch, reused across steps.
  struct Side {
    int32_t body;  // local body index
    Vec3 jl, ja, mjl, mja;
  };
  std::vector<int32_t> rowLocal, bodyLocal;
  std::vector<int32_t> bodyGlobal;
  std::vector<Side> side[2];
  std::vector<uint8_t> numSides;
  std::vector<std::vector<std::pair<int32_t, int8_t>>> bodyRows;  // per local body: (local row, side)
  std::vector<Vec3> vf, wf, vc, wc;
  std::vector<Mat3> inertia;
  std::vector<Real> lam, lamOld, lo, hi, eReg, ad, w, b, scratch;
  std::vector<Real> rhs;  // row rhs minus the row velocity of its kinematic (non-dynamic) sides, which stays fixed
  std::vector<int8_t> state;
  std::vector<int32_t> normalLocal;
  std::vector<int> p, i, diagPos;
  std::vector<Real> x0;
  std::vector<int> mark, idx;
  std::vector<std::pair<Real, int>> viol;
  std::vector<Real> usedLo, usedHi;

  Impl() {
    cholmod_start(&cm);
    cm.print = 0;
    cm.nmethods = 1;
    cm.method[0].ordering = CHOLMOD_AMD;
    cm.postorder = 1;
  }
  ~Impl() {
    for (auto& c : cache) {
      if (c.L) cholmod_free_factor(&c.L, &cm);
      if (c.A) cholmod_free_sparse(&c.A, &cm);
    }
    if (B) cholmod_free_dense(&B, &cm);
    if (X) cholmod_free_dense(&X, &cm);
    if (Y) cholmod_free_dense(&Y, &cm);
    if (E) cholmod_free_dense(&E, &cm);
    cholmod_finish(&cm);
  }
};

namespace {
/// Symbolic analysis in the cheaper of two orderings: AMD with postordering (the constructor's setting) or the
/// rows' own order. DESIGN (issue 18, chain20's cost; docs/solver-internals.md "Direct solve: natural ordering
/// where it fills no more"): with any permutation CHOLMOD's simplicial factorisation first forms A(p,p) by two
/// transposes (cholmod_ptranspose, cholmod_transpose_sym), on every factorisation. On a chain, a tree or a
/// banded system the rows' own order fills no more than AMD, and then those transposes are pure overhead: on
/// chain20 they were 16 % of the step's instructions (callgrind), the same as the factorisation itself. So the
/// natural order is kept whenever its factorisation needs at most kNaturalSlack times AMD's flops (the analysis
/// reports both; a transpose costs about one pass over A, a factorisation at least that). The choice is made
/// when the pattern changes (the analysis is cached with it), and does not depend on the values.
constexpr double kNaturalSlack = 1.25;
cholmod_factor* analyzeCheapest(cholmod_sparse* A, cholmod_common& cm) {
  const int ordering = cm.method[0].ordering, postorder = cm.postorder;
  cm.method[0].ordering = CHOLMOD_NATURAL;
  cm.postorder = 0;
  cholmod_factor* natural = cholmod_analyze(A, &cm);
  const double flNatural = natural && cm.status == CHOLMOD_OK ? cm.fl : -1;
  cm.method[0].ordering = ordering;
  cm.postorder = postorder;
  cholmod_factor* amd = cholmod_analyze(A, &cm);
  const double flAmd = amd && cm.status == CHOLMOD_OK ? cm.fl : -1;
  if (natural && flNatural >= 0 && (flAmd < 0 || flNatural <= kNaturalSlack * flAmd)) {
    if (amd) cholmod_free_factor(&amd, &cm);
    return natural;
  }
  if (natural) cholmod_free_factor(&natural, &cm);
  return amd;
}
}  // namespace

DirectSolver::DirectSolver() : impl_(std::make_unique<Impl>()) {}
DirectSolver::~DirectSolver() = default;
bool DirectSolver::available() { return true; }

DirectSolver::Result DirectSolver::solve(std::vector<ConstraintRow>& rows, const std::vector<uint32_t>& set,
                                         std::vector<SolverBodyState>& bodies, const Settings& settings) {
  using Clock = std::chrono::steady_clock;
  Impl& m = *impl_;
  Result res;
  const int n = int(set.size());
  if (n == 0) return res;

  // ---- local numbering of rows and dynamic bodies ----
  m.rowLocal.assign(rows.size(), -1);
  for (int k = 0; k < n; ++k) m.rowLocal[set[k]] = k;
  m.bodyLocal.assign(bodies.size(), -1);
  m.bodyGlobal.clear();
  m.side[0].resize(n);
  m.side[1].resize(n);
  m.numSides.assign(n, 0);
  m.rhs.resize(n);
  for (int k = 0; k < n; ++k) {
    const ConstraintRow& r = rows[set[k]];
    m.rhs[k] = r.rhs;
    for (int s = 0; s < 2; ++s) {
      const int32_t bi = s == 0 ? r.bodyA : r.bodyB;
      if (bi < 0) continue;
      if (!(bodies[bi].invMass > 0)) {
        // Kinematic body (static: zero velocity): not an unknown, but its velocity is part of J v.
        m.rhs[k] -= (s == 0 ? r.jLinA : r.jLinB).dot(bodies[bi].v) + (s == 0 ? r.jAngA : r.jAngB).dot(bodies[bi].w);
        continue;
      }
      if (m.bodyLocal[bi] < 0) {
        m.bodyLocal[bi] = int32_t(m.bodyGlobal.size());
        m.bodyGlobal.push_back(bi);
      }
      Impl::Side& sd = m.side[m.numSides[k]++][k];
      sd.body = m.bodyLocal[bi];
      sd.jl = s == 0 ? r.jLinA : r.jLinB;
      sd.ja = s == 0 ? r.jAngA : r.jAngB;
      sd.mjl = s == 0 ? r.mJLinA : r.mJLinB;
      sd.mja = s == 0 ? r.mJAngA : r.mJAngB;
    }
    if (m.numSides[k] == 2 && m.side[0][k].body > m.side[1][k].body) std::swap(m.side[0][k], m.side[1][k]);
  }
  const int nb = int(m.bodyGlobal.size());
  if (m.bodyRows.size() < size_t(nb)) m.bodyRows.resize(nb);
  for (int b = 0; b < nb; ++b) m.bodyRows[b].clear();
  for (int k = 0; k < n; ++k)
    for (int s = 0; s < m.numSides[k]; ++s) m.bodyRows[m.side[s][k].body].push_back({k, int8_t(s)});

  // ---- velocities without the set's impulses; bounds; regularisation ----
  m.vf.resize(nb);
  m.wf.resize(nb);
  for (int b = 0; b < nb; ++b) {
    m.vf[b] = bodies[m.bodyGlobal[b]].v;
    m.wf[b] = bodies[m.bodyGlobal[b]].w;
  }
  m.lam.resize(n);
  m.lamOld.resize(n);
  m.lo.resize(n);
  m.hi.resize(n);
  m.eReg.resize(n);
  m.ad.resize(n);
  m.w.resize(n);
  m.b.resize(n);
  m.state.assign(n, 0);
  m.normalLocal.assign(n, -1);
  bool anyBounded = false;
  for (int k = 0; k < n; ++k) {
    const ConstraintRow& r = rows[set[k]];
    m.lamOld[k] = m.lam[k] = r.lambda;
    for (int s = 0; s < m.numSides[k]; ++s) {
      const Impl::Side& sd = m.side[s][k];
      m.vf[sd.body] -= sd.mjl * r.lambda;
      m.wf[sd.body] -= sd.mja * r.lambda;
    }
    const Real kdiag = r.diag - r.e;
    m.eReg[k] = r.e > 0 ? r.e : (kdiag > 0 ? 1e-9 * kdiag : 1.0);
    m.ad[k] = kdiag + m.eReg[k];
    if (r.normalRow >= 0) {
      m.normalLocal[k] = m.rowLocal[r.normalRow];
      anyBounded |= !std::isinf(r.mu);
    } else {
      anyBounded |= r.lo > -kInf || r.hi < kInf;
    }
  }
  auto updateBounds = [&] {
    for (int k = 0; k < n; ++k) {
      const ConstraintRow& r = rows[set[k]];
      if (r.normalRow >= 0) {
        const Real ln = m.normalLocal[k] >= 0 ? m.lam[m.normalLocal[k]] : rows[r.normalRow].lambda;
        const Real lim = frictionLimit(r.mu, ln);
        m.lo[k] = -lim;
        m.hi[k] = lim;
      } else {
        m.lo[k] = r.lo;
        m.hi[k] = r.hi;
      }
    }
  };
  updateBounds();
  // Warm start of the active set: rows at a bound last step start held there.
  for (int k = 0; k < n; ++k) {
    if (m.lo[k] > -kInf && m.lam[k] <= m.lo[k]) m.state[k] = -1;
    else if (m.hi[k] < kInf && m.lam[k] >= m.hi[k]) m.state[k] = 1;
  }

  // ---- choose the form ----
  size_t schurNnz = size_t(n), kktNnz = size_t(9 * nb);
  for (int b = 0; b < nb; ++b) schurNnz += m.bodyRows[b].size() * (m.bodyRows[b].size() - 1) / 2;
  for (int k = 0; k < n; ++k) kktNnz += 1 + 6 * m.numSides[k];
  Solver::DirectForm form = settings.form;
  if (form == Solver::AUTO) form = Real(schurNnz) > kktRatio * Real(kktNnz) ? Solver::KKT : Solver::SCHUR;
  res.form = form;
  const bool kkt = form == Solver::KKT;
  const int N = kkt ? 6 * nb + n : n;
  const int rowBase = kkt ? 6 * nb : 0;

  // ---- pattern and unmodified values (upper triangle, CSC, sorted) ----
  m.p.assign(N + 1, 0);
  m.i.clear();
  m.x0.clear();
  m.diagPos.assign(N, -1);
  if (!kkt) {
    m.scratch.assign(n, 0);
    m.mark.assign(n, 0);
    std::vector<int>& idx = m.idx;
    for (int j = 0; j < n; ++j) {
      idx.clear();
      for (int s = 0; s < m.numSides[j]; ++s) {
        const Impl::Side& sj = m.side[s][j];
        for (const auto& [i, si] : m.bodyRows[sj.body]) {
          if (i > j) break;
          const Impl::Side& s2 = m.side[si][i];
          const Real v = sj.jl.dot(s2.mjl) + sj.ja.dot(s2.mja);
          if (!m.mark[i]) {
            m.mark[i] = 1;
            m.scratch[i] = 0;
            idx.push_back(i);
          }
          m.scratch[i] += v;
        }
      }
      if (!m.mark[j]) {
        m.mark[j] = 1;
        m.scratch[j] = 0;
        idx.push_back(j);
      }
      // A column holds the rows that share a body with row j, as two ascending runs (one per side). Usually
      // a handful (a ball joint's 3 rows on each of its two links): insertion sort, since std::sort's set-up
      // on so few was 1.7 % of chain20's step (callgrind, issue 18). Longer columns (a particle lump's bodies
      // carry dozens of rows) keep std::sort. Distinct integers: the same order either way.
      if (idx.size() <= 24) {
        for (size_t a = 1; a < idx.size(); ++a) {
          const int v = idx[a];
          size_t b = a;
          for (; b > 0 && idx[b - 1] > v; --b) idx[b] = idx[b - 1];
          idx[b] = v;
        }
      } else {
        std::sort(idx.begin(), idx.end());
      }
      for (int i : idx) {
        if (i == j) {
          m.diagPos[j] = int(m.i.size());
          m.x0.push_back(m.ad[j]);  // K_jj + e (regularised)
        } else {
          m.x0.push_back(m.scratch[i]);
        }
        m.i.push_back(i);
        m.mark[i] = 0;
      }
      m.p[j + 1] = int(m.i.size());
    }
  } else {
    m.inertia.resize(nb);
    for (int b = 0; b < nb; ++b) {
      const SolverBodyState& s = bodies[m.bodyGlobal[b]];
      m.inertia[b] = s.invInertia.inverse();
      const Real mass = 1.0 / s.invMass;
      for (int d = 0; d < 6; ++d) {
        const int c = 6 * b + d;
        if (d < 3) {
          m.i.push_back(c);
          m.x0.push_back(mass);
        } else {
          for (int d2 = 3; d2 <= d; ++d2) {
            m.i.push_back(6 * b + d2);
            m.x0.push_back(m.inertia[b](d2 - 3, d - 3));
          }
        }
        m.diagPos[c] = int(m.i.size()) - 1;
        m.p[c + 1] = int(m.i.size());
      }
    }
    for (int k = 0; k < n; ++k) {
      for (int s = 0; s < m.numSides[k]; ++s) {
        const Impl::Side& sd = m.side[s][k];
        for (int d = 0; d < 3; ++d) {
          m.i.push_back(6 * sd.body + d);
          m.x0.push_back(-sd.jl[d]);
        }
        for (int d = 0; d < 3; ++d) {
          m.i.push_back(6 * sd.body + 3 + d);
          m.x0.push_back(-sd.ja[d]);
        }
      }
      m.diagPos[rowBase + k] = int(m.i.size());
      m.i.push_back(rowBase + k);
      m.x0.push_back(-m.eReg[k]);
      m.p[rowBase + k + 1] = int(m.i.size());
    }
  }
  const size_t nnz = m.i.size();

  // ---- CHOLMOD matrix and symbolic analysis (cached while the pattern holds) ----
  Impl::FormCache& fc = m.cache[kkt ? 1 : 0];
  const bool samePattern = fc.L && fc.p == m.p && fc.i == m.i;
  if (!fc.A || fc.A->nzmax < nnz || fc.A->ncol != size_t(N)) {
    if (fc.A) cholmod_free_sparse(&fc.A, &m.cm);
    fc.A = cholmod_allocate_sparse(N, N, std::max<size_t>(nnz, 1), 1, 1, 1, CHOLMOD_REAL, &m.cm);
  }
  cholmod_sparse* A = fc.A;
  std::copy(m.p.begin(), m.p.end(), static_cast<int*>(A->p));
  std::copy(m.i.begin(), m.i.end(), static_cast<int*>(A->i));
  Real* Ax = static_cast<Real*>(A->x);
  if (!samePattern) {
    if (fc.L) cholmod_free_factor(&fc.L, &m.cm);
    m.cm.supernodal = kkt ? CHOLMOD_SIMPLICIAL : CHOLMOD_AUTO;
    m.cm.final_ll = kkt ? 0 : 1;
    std::copy(m.x0.begin(), m.x0.end(), Ax);
    fc.L = analyzeCheapest(A, m.cm);
    fc.p = m.p;
    fc.i = m.i;
    res.symbolicAnalyses = 1;
    if (!fc.L) {
      res.converged = false;
      return res;
    }
  }
  if (!m.B || m.B->nrow != size_t(N)) {
    if (m.B) cholmod_free_dense(&m.B, &m.cm);
    m.B = cholmod_zeros(N, 1, CHOLMOD_REAL, &m.cm);
  }
  Real* Bx = static_cast<Real*>(m.B->x);

  m.vc.resize(nb);
  m.wc.resize(nb);
  // Velocities with the given impulses of the rows selected by `which` (0: all, 1: held rows only).
  auto velocities = [&](bool heldOnly) {
    for (int b = 0; b < nb; ++b) {
      m.vc[b] = m.vf[b];
      m.wc[b] = m.wf[b];
    }
    for (int k = 0; k < n; ++k) {
      if (heldOnly && m.state[k] == 0) continue;
      const Real l = m.lam[k];
      for (int s = 0; s < m.numSides[k]; ++s) {
        const Impl::Side& sd = m.side[s][k];
        m.vc[sd.body] += sd.mjl * l;
        m.wc[sd.body] += sd.mja * l;
      }
    }
  };
  auto rowVel = [&](int k) {
    Real jv = 0;
    for (int s = 0; s < m.numSides[k]; ++s) {
      const Impl::Side& sd = m.side[s][k];
      jv += sd.jl.dot(m.vc[sd.body]) + sd.ja.dot(m.wc[sd.body]);
    }
    return jv;
  };
  auto computeW = [&] {
    velocities(false);
    for (int k = 0; k < n; ++k) {
      m.w[k] = rowVel(k) + m.eReg[k] * m.lam[k] - m.rhs[k];
    }
  };

  // One numeric factorisation and solve with the current active set (held rows at their current bounds).
  auto factorAndSolve = [&]() -> bool {
    for (int k = 0; k < n; ++k)
      if (m.state[k] != 0) m.lam[k] = m.state[k] < 0 ? m.lo[k] : m.hi[k];
    velocities(true);
    // Values with held rows' lines replaced by the identity (diagonal kept), and the right-hand side.
    std::copy(m.x0.begin(), m.x0.end(), Ax);
    if (!kkt) {
      // Without held rows (joints without limits: every row free) there are no lines to clear.
      if (std::any_of(m.state.begin(), m.state.end(), [](int8_t st) { return st != 0; }))
        for (int j = 0; j < n; ++j)
          for (int q = m.p[j]; q < m.p[j + 1]; ++q)
            if (q != m.diagPos[j] && (m.state[j] != 0 || m.state[m.i[q]] != 0)) Ax[q] = 0;
      for (int k = 0; k < n; ++k)
        Bx[k] = m.state[k] != 0 ? m.ad[k] * m.lam[k] : m.rhs[k] - rowVel(k);
    } else {
      for (int k = 0; k < n; ++k)
        if (m.state[k] != 0)
          for (int q = m.p[rowBase + k]; q < m.diagPos[rowBase + k]; ++q) Ax[q] = 0;
      for (int b = 0; b < nb; ++b) {
        const Real mass = 1.0 / bodies[m.bodyGlobal[b]].invMass;
        const Vec3 pl = mass * m.vc[b], pa = m.inertia[b] * m.wc[b];
        for (int d = 0; d < 3; ++d) {
          Bx[6 * b + d] = pl[d];
          Bx[6 * b + 3 + d] = pa[d];
        }
      }
      for (int k = 0; k < n; ++k)
        Bx[rowBase + k] = m.state[k] != 0 ? -m.eReg[k] * m.lam[k] : -m.rhs[k];
    }
    m.cm.supernodal = kkt ? CHOLMOD_SIMPLICIAL : CHOLMOD_AUTO;
    m.cm.final_ll = kkt ? 0 : 1;
    const auto t0 = Clock::now();
    cholmod_factorize(A, fc.L, &m.cm);
    res.factorSeconds += std::chrono::duration<double>(Clock::now() - t0).count();
    ++res.factorisations;
    if (m.cm.status != CHOLMOD_OK) {
      // Not (quasi-)definite: drop the cached analysis and let the caller fall back.
      cholmod_free_factor(&fc.L, &m.cm);
      fc.p.clear();
      return false;
    }
    cholmod_solve2(CHOLMOD_A, fc.L, m.B, nullptr, &m.X, nullptr, &m.Y, &m.E, &m.cm);
    const Real* x = static_cast<const Real*>(m.X->x);
    for (int k = 0; k < n; ++k)
      if (m.state[k] == 0) m.lam[k] = x[rowBase + k];
    return true;
  };

  // Outer passes: friction bounds frozen at mu * lambda_n of the last pass (a box LCP with fixed bounds inside,
  // which block pivoting with Murty's fallback solves in finitely many steps since A is positive definite), until
  // the bounds stop moving.
  bool converged = false, failed = false;
  const int maxIter = std::max(1, settings.maxPivots);
  auto& viol = m.viol;
  auto& usedLo = m.usedLo;
  auto& usedHi = m.usedHi;
  // The passes share the factorisation cap (maxPivots) with the pivoting inside them; no separate pass cap (a
  // cap of 10 passes made a 512-particle glued lump's landing on a finite-friction ground fall back to PGS,
  // where it converges in 24 factorisations).
  while (!failed && !converged && res.factorisations < maxIter) {
    int bestInfeasible = std::numeric_limits<int>::max(), noImprove = 0;
    bool inner = false;
    while (res.factorisations < maxIter) {
      if (!factorAndSolve()) {
        failed = true;
        break;
      }
      if (!anyBounded) {
        inner = true;
        break;
      }
      computeW();
      Real scale = 1e-300;
      for (int k = 0; k < n; ++k) scale = std::max(scale, std::abs(m.lam[k]));
      const Real tol = 1e-10 * scale;
      viol.clear();
      for (int k = 0; k < n; ++k) {
        Real v = 0;
        if (m.state[k] == 0) v = std::max(m.lo[k] - m.lam[k], m.lam[k] - m.hi[k]);
        else if (m.state[k] < 0) v = m.lo[k] < m.hi[k] ? -m.w[k] / m.ad[k] : 0;
        else v = m.lo[k] < m.hi[k] ? m.w[k] / m.ad[k] : 0;
        if (v > tol) viol.push_back({v, k});
      }
      if (viol.empty()) {
        inner = true;
        break;
      }
      const int count = int(viol.size());
      if (count < bestInfeasible) {
        bestInfeasible = count;
        noImprove = 0;
      } else {
        ++noImprove;
      }
      if (noImprove >= 3) viol = {*std::max_element(viol.begin(), viol.end())};
      for (const auto& [v, k] : viol) {
        (void)v;
        if (m.state[k] == 0) m.state[k] = m.lam[k] < m.lo[k] ? -1 : 1;
        else m.state[k] = 0;
        ++res.pivots;
      }
    }
    if (!inner) break;
    // New friction bounds from this pass's normals.
    usedLo = m.lo;
    usedHi = m.hi;
    updateBounds();
    Real scale = 1e-300, moved = 0;
    for (int k = 0; k < n; ++k) {
      scale = std::max(scale, std::abs(m.lam[k]));
      if (m.normalLocal[k] >= 0)
        moved = std::max({moved, std::abs(m.lo[k] - usedLo[k]), std::abs(m.hi[k] - usedHi[k])});
    }
    if (moved <= 1e-10 * scale) converged = true;
    // Held rows sit on the new bounds (rows held at a degenerate bound lo = hi, friction without normal force,
    // start free); free rows now outside them are held at the nearer one.
    for (int k = 0; k < n; ++k)
      if (m.state[k] != 0 && m.normalLocal[k] >= 0 && usedLo[k] == usedHi[k]) m.state[k] = 0;
    for (int k = 0; k < n; ++k)
      if (m.state[k] == 0 && (m.lam[k] < m.lo[k] || m.lam[k] > m.hi[k])) {
        m.state[k] = m.lam[k] < m.lo[k] ? -1 : 1;
        ++res.pivots;
      }
  }
  res.converged = converged;
  if (!converged) {
    // Pivot cap or factorisation failure: an intermediate active set can be far from the solution (impulses of
    // rows held at the wrong bound), so nothing is written back; the caller solves the set from the impulses it
    // came with (warm start).
    m.lam = m.lamOld;
    m.state.assign(n, 0);
    updateBounds();
    computeW();
    Real resid = 0;
    for (int k = 0; k < n; ++k)
      resid = std::max(resid, std::abs(m.lam[k] - std::clamp(m.lam[k] - m.w[k] / m.ad[k], m.lo[k], m.hi[k])));
    res.residual = resid;
    return res;
  }

  // Projected-cone pairs stay a scaled box here: projecting them onto the disc afterwards would break the
  // solution's complementarity.
  updateBounds();
  for (int k = 0; k < n; ++k) m.lam[k] = std::clamp(m.lam[k], m.lo[k], m.hi[k]);
  computeW();
  Real resid = 0;
  for (int k = 0; k < n; ++k) {
    const Real proj = std::clamp(m.lam[k] - m.w[k] / m.ad[k], m.lo[k], m.hi[k]);
    resid = std::max(resid, std::abs(m.lam[k] - proj));
  }
  res.residual = resid;

  // Write back: impulses and velocities.
  for (int k = 0; k < n; ++k) rows[set[k]].lambda = m.lam[k];
  for (int b = 0; b < nb; ++b) {
    bodies[m.bodyGlobal[b]].v = m.vc[b];
    bodies[m.bodyGlobal[b]].w = m.wc[b];
  }
  return res;
}

#else  // !SCREE_WITH_SUITESPARSE

struct DirectSolver::Impl {};
DirectSolver::DirectSolver() : impl_(std::make_unique<Impl>()) {}
DirectSolver::~DirectSolver() = default;
bool DirectSolver::available() { return false; }
DirectSolver::Result DirectSolver::solve(std::vector<ConstraintRow>&, const std::vector<uint32_t>&,
                                         std::vector<SolverBodyState>&, const Settings&) {
  Result r;
  r.converged = false;
  return r;
}

#endif

}  // namespace scree::detail
