// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scree/collide/particle_collider.h"

#include <algorithm>
#include <climits>
#include <cmath>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define SCREE_PAIR_AVX2 1
#endif

#include "scree/collide/narrowphase.h"
#include "scree/collide/shapes.h"
#include "scree/core/rigid_body.h"

#ifdef SCREE_WITH_OPENMP
#include <omp.h>
#endif

namespace scree::detail {

namespace {
// Particles per work chunk. Chunks, not threads, own output buffers: the merged order is independent of the
// thread count.
constexpr size_t kChunk = 512;
// Loops over fewer chunks than this run on the calling thread: a fork/join costs more than a few chunks of work,
// and far more when the machine is busy (a thread that has to wait for its descheduled peer). The chunks and
// their merge order are the same either way, so the results do not change.
constexpr size_t kParallelChunks = 4;
// The dense grid is used while the live cells' padded bounding box has at most this many cells per particle
// (plus 4096): its cell-start array is then a few times the particle arrays at most.
constexpr size_t kDenseCellsPerParticle = 32;
// Two-speed grid (see "Two-speed grid" in the header): a particle is slow when its speed relative to the
// reference velocity, times h, is at most kSlowShare largest radii.
constexpr Real kSlowShare = 0.25;

#if defined(__GNUC__)
#define SCREE_PAIR_INLINE __attribute__((always_inline))
#else
#define SCREE_PAIR_INLINE
#endif

// ---- Four-wide candidate filter (see "Candidate filter" in the header) ------------------------------------------
// The pair search's cheap reject, four candidates at a time in 256-bit AVX2 registers, over the structure-of-
// arrays copy of the sorted entries: bit l of the result is set unless candidate k0 + l is certainly rejected,
// i.e. unless dist2 >= far^2 (1 + 1e-12) with
//   dist2 = (dx^2 + dy^2) + dz^2   (Eigen's order for a 3-vector's squaredNorm),
//   far   = (r_i + r_j) + min((w_i + w_j) + margin, reach),
// the scalar test's operations in its order (no FMA: the function is compiled for AVX2 only). The 1e-12 makes
// the filter conservative even if one of these roundings differed: every candidate it keeps still goes through
// the scalar test, which alone decides, so the pairs found are the scalar search's whatever the filter does.
// A NaN distance is kept (the scalar test's comparison is false for it too). At most 64 candidates per call.
#ifdef SCREE_PAIR_AVX2
__attribute__((target("avx2"))) uint64_t pairFilterAvx2(const double* sx, const double* sy, const double* sz,
                                                        const double* sr, const double* sw, uint32_t k0,
                                                        uint32_t count, double xi, double yi, double zi, double ri,
                                                        double wi, double margin, double reach) {
  const __m256d vx = _mm256_set1_pd(xi), vy = _mm256_set1_pd(yi), vz = _mm256_set1_pd(zi);
  const __m256d vr = _mm256_set1_pd(ri), vw = _mm256_set1_pd(wi), vm = _mm256_set1_pd(margin);
  const __m256d vreach = _mm256_set1_pd(reach), slack = _mm256_set1_pd(1 + 1e-12);
  uint64_t keep = 0;
  for (uint32_t l = 0; l < count; l += 4) {
    const uint32_t k = k0 + l;
    const __m256d dx = _mm256_sub_pd(vx, _mm256_loadu_pd(sx + k));
    const __m256d dy = _mm256_sub_pd(vy, _mm256_loadu_pd(sy + k));
    const __m256d dz = _mm256_sub_pd(vz, _mm256_loadu_pd(sz + k));
    const __m256d d2 = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)),
                                     _mm256_mul_pd(dz, dz));
    const __m256d rr = _mm256_add_pd(vr, _mm256_loadu_pd(sr + k));
    const __m256d ww = _mm256_add_pd(_mm256_add_pd(vw, _mm256_loadu_pd(sw + k)), vm);
    const __m256d far = _mm256_add_pd(rr, _mm256_min_pd(ww, vreach));
    const __m256d lim = _mm256_mul_pd(_mm256_mul_pd(far, far), slack);
    // Not (d2 >= lim), true for NaN: kept.
    const unsigned bits = unsigned(_mm256_movemask_pd(_mm256_cmp_pd(d2, lim, _CMP_NGE_UQ)));
    keep |= uint64_t(bits) << l;
  }
  // Lanes past the run (they read the next entries or the arrays' padding) are dropped.
  return count >= 64 ? keep : keep & ((uint64_t(1) << count) - 1);
}
#endif

// Cell coordinate of a position component; clamped so that a particle far away (1e9 cells) cannot overflow
// the integer conversion (it only shares a cell with other far-away particles).
inline int32_t cellCoord(Real x, Real invCell) {
  return int32_t(std::clamp<Real>(std::floor(x * invCell), -1e9, 1e9));
}

inline uint64_t hashCell(int64_t x, int64_t y, int64_t z) {
  return uint64_t(x) * 73856093ull ^ uint64_t(y) * 19349663ull ^ uint64_t(z) * 83492791ull;
}
int threadIndex() {
#ifdef SCREE_WITH_OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}
int maxThreads() {
#ifdef SCREE_WITH_OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}
}  // namespace

struct ParticleCollider::Impl {
  Real cell = 1, invCell = 1;
  size_t tableMask = 0;
  std::vector<int32_t> cx, cy, cz;          // [size()] cell coordinates per dense particle
  std::vector<uint32_t> bucketOf;           // [size()] hash bucket per particle
  std::vector<uint32_t> bucketStart;        // [table + 1] prefix sums
  std::vector<uint32_t> sorted;             // particles by bucket, dense order within a bucket
  // The pair search's copy of each sorted entry: its cell and centre next to its index, so a bucket is scanned
  // contiguously (no indirection into the particle arrays for the candidates that are rejected).
  struct Entry {
    Vec3 x;
    Real r;
    Real w;  // the speed bound w_j (see the pair search)
    int32_t cx, cy, cz;
    uint32_t j;
    uint32_t fast;  // 1: searches its own partners (w_j > the slow bound)
  };
  std::vector<Entry> entries;               // [sorted.size()]
  // The entries' centres, radii and speed bounds as structure of arrays for the four-wide candidate filter,
  // [sorted.size() + 4]: the filter's last load of a run may read up to three entries past it.
  std::vector<double> sx, sy, sz, sr, sw;
  bool usedFilter = false;  // the last collide() ran the four-wide filter
  std::vector<std::vector<ParticleContact>> chunkOut;  // per chunk
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> chunkPairs;  // per chunk: pairs (lower, higher) found
  std::vector<uint32_t> pairStart;  // [size() + 1] first pair of each lower particle in pairB
  std::vector<uint32_t> pairB;      // the pairs' higher particles, by lower particle
  // Per-thread probe sphere for the geometry narrowphase.
  std::vector<std::shared_ptr<Sphere>> probeShapes;
  std::vector<std::unique_ptr<Geometry>> probes;
  std::vector<std::vector<ContactPoint>> scratch;
  std::vector<uint32_t> candidates;
  // ---- dense grid (see "Dense grid" in collide()) ----
  // When the live particles' cells span a box of at most kDenseCellsPerParticle cells per particle, the
  // buckets are the box's cells themselves (no hash, no collisions): bucketOf is the cell's index in (z, y, x)
  // order with one empty padding cell on each side in x and y and one layer on top in z, so the cells of the
  // half stencil are 5 contiguous runs (own row, row y+1, and the three rows of layer z+1).
  bool dense = false;
  int32_t lo[3] = {0, 0, 0}, hi[3] = {-1, -1, -1};  // live cells' bounds (cell coordinates)
  int64_t nx = 0, nxy = 0;                          // padded row length and layer size
  std::vector<uint32_t> posOf;                      // [size()] index of a particle in sorted (dense grid only)
  // ---- two-speed grid ----
  Real gcell = 1, ginvCell = 1;  // the grid's cell (cell/invCell above are the reported 2 maxR + reach)
  std::vector<Real> w;           // [size()] speed bounds
  std::vector<uint32_t> fastList;  // the fast live particles, ascending
  std::vector<Vec3> xLast;       // positions of the last collide (localityOrder's cells)
  std::vector<Real> vScratch;    // median of the velocities

  int64_t denseCell(int64_t x, int64_t y, int64_t z) const {
    return ((z - lo[2]) * (nxy / nx) + (y - lo[1] + 1)) * nx + (x - lo[0] + 1);
  }
  template <class F>
  void forCell(int64_t x, int64_t y, int64_t z, F&& f) const {
    if (dense) {
      if (x < lo[0] || x > hi[0] || y < lo[1] || y > hi[1] || z < lo[2] || z > hi[2]) return;
      const size_t c = size_t(denseCell(x, y, z));
      for (uint32_t k = bucketStart[c]; k < bucketStart[c + 1]; ++k) f(sorted[k]);
      return;
    }
    const size_t b = hashCell(x, y, z) & tableMask;
    for (uint32_t k = bucketStart[b]; k < bucketStart[b + 1]; ++k) {
      const uint32_t j = sorted[k];
      if (cx[j] == x && cy[j] == y && cz[j] == z) f(j);
    }
  }
};

ParticleCollider::ParticleCollider() : impl_(std::make_unique<Impl>()) {}
ParticleCollider::~ParticleCollider() = default;

void ParticleCollider::collide(const GranularBodySystem& ps, const std::vector<GeometryRef>& geometries, Real h) {
  Impl& m = *impl_;
  // pp_ keeps last step's elements until its resize below: every element is then overwritten whole, so growing
  // it value-initialises only the new tail (clearing it here made the resize value-initialise all ~25,000
  // contacts, 4 MB written twice per step).
  pg_.clear();
  const size_t n = ps.size();
  if (n == 0) {
    pp_.clear();
    return;
  }
  const auto& x = ps.positions();
  const auto& v = ps.velocities();
  const auto& r = ps.radii();

  // ---- grid --------------------------------------------------------------------------------------------------
  Real maxR = 0, maxV = 0;
  for (size_t i = 0; i < n; ++i) {
    maxR = std::max(maxR, r[i]);
    maxV = std::max(maxV, v[i].squaredNorm());
  }
  maxV = std::sqrt(maxV);
  // Pair margin reach: relative speed of two particles is at most 2 maxV; capped at one diameter (see header).
  const Real reach = std::min(2 * maxV * h + margin_, 2 * maxR);
  // The reported cell (getCellSize, localityOrder): the largest distance of a pair in contact.
  m.cell = 2 * maxR + reach;
  m.invCell = 1.0 / m.cell;
  m.xLast.assign(x.begin(), x.end());
  // Two-speed grid (header). Reference velocity u: the median of the live particles' velocities, component by
  // component (an element of the data: exact, and the same on any thread count). Speed bound of a particle:
  //   w_i = h |v_i - u| (1 + 1e-9),  so  h |v_i - v_j| <= w_i + w_j  (triangle inequality; the 1e-9 is far more
  // than the rounding of either side, so the bound holds in floating point too).
  Vec3 u = Vec3::Zero();
  for (int ax = 0; ax < 3; ++ax) {
    auto& q = m.vScratch;
    q.clear();
    for (size_t i = 0; i < n; ++i)
      if (ps.isAliveDense(i)) q.push_back(v[i][ax]);
    if (q.empty()) continue;
    std::nth_element(q.begin(), q.begin() + long(q.size() / 2), q.end());
    u[ax] = q[q.size() / 2];
  }
  m.w.resize(n);
  for (size_t i = 0; i < n; ++i) m.w[i] = h * (v[i] - u).norm() * (1 + 1e-9);
  // Slow particles (w <= slowW): any two of them are within the grid cell when in contact, so they find each
  // other through the half stencil. When the reach itself fits (a pile at rest), every particle is slow.
  const Real slowW = kSlowShare * maxR;
  const Real slowReach = std::min(2 * slowW + margin_, reach);
  const bool twoSpeed = reach > slowReach;
  m.gcell = (2 * maxR + slowReach) * (1 + 1e-9);
  m.ginvCell = 1.0 / m.gcell;
  m.cx.resize(n);
  m.cy.resize(n);
  m.cz.resize(n);
  m.bucketOf.resize(n);
#pragma omp parallel for schedule(static) if (n >= kParallelChunks * kChunk)
  for (size_t i = 0; i < n; ++i) {
    m.cx[i] = cellCoord(x[i].x(), m.ginvCell);
    m.cy[i] = cellCoord(x[i].y(), m.ginvCell);
    m.cz[i] = cellCoord(x[i].z(), m.ginvCell);
  }
  // Dense grid: the live cells' bounding box, padded, when it is small enough (a particle flung far away makes
  // it large: then the hashed grid). Both give the same contact list (the pairs are sorted below).
  m.lo[0] = m.lo[1] = m.lo[2] = INT32_MAX;
  m.hi[0] = m.hi[1] = m.hi[2] = INT32_MIN;
  for (size_t i = 0; i < n; ++i) {
    if (!ps.isAliveDense(i)) continue;
    m.lo[0] = std::min(m.lo[0], m.cx[i]);
    m.hi[0] = std::max(m.hi[0], m.cx[i]);
    m.lo[1] = std::min(m.lo[1], m.cy[i]);
    m.hi[1] = std::max(m.hi[1], m.cy[i]);
    m.lo[2] = std::min(m.lo[2], m.cz[i]);
    m.hi[2] = std::max(m.hi[2], m.cz[i]);
  }
  size_t table = 64;
  m.dense = false;
  if (m.lo[0] <= m.hi[0]) {
    const int64_t ex = int64_t(m.hi[0]) - m.lo[0] + 3, ey = int64_t(m.hi[1]) - m.lo[1] + 3,
                  ez = int64_t(m.hi[2]) - m.lo[2] + 2;
    // Checked factor by factor: each extent is below 2e9 + 3, so no product below overflows int64.
    const int64_t limit = int64_t(kDenseCellsPerParticle * n) + 4096;
    if (ex <= limit && ey <= limit && ez <= limit && ex * ey <= limit && ex * ey * ez <= limit) {
      m.dense = true;
      m.nx = ex;
      m.nxy = ex * ey;
      table = size_t(ex * ey * ez);
    }
  }
  if (m.dense) {
#pragma omp parallel for schedule(static) if (n >= kParallelChunks * kChunk)
    for (size_t i = 0; i < n; ++i)
      m.bucketOf[i] = ps.isAliveDense(i) ? uint32_t(m.denseCell(m.cx[i], m.cy[i], m.cz[i])) : 0;
    m.posOf.resize(n);
  } else {
    while (table < 2 * n) table <<= 1;
    m.tableMask = table - 1;
#pragma omp parallel for schedule(static) if (n >= kParallelChunks * kChunk)
    for (size_t i = 0; i < n; ++i) m.bucketOf[i] = uint32_t(hashCell(m.cx[i], m.cy[i], m.cz[i]) & m.tableMask);
  }
  // The four-wide candidate filter runs on the dense grid's runs (the hashed grid, a rare fallback, keeps the
  // scalar test alone).
  const bool useFilter = m.dense && pairFilterActive();
  m.usedFilter = useFilter;
  m.bucketStart.assign(table + 1, 0);
  for (size_t i = 0; i < n; ++i)
    if (ps.isAliveDense(i)) ++m.bucketStart[m.bucketOf[i] + 1];
  for (size_t b = 0; b < table; ++b) m.bucketStart[b + 1] += m.bucketStart[b];
  m.sorted.resize(m.bucketStart[table]);
  m.fastList.clear();
  {
    std::vector<uint32_t>& fill = m.candidates;  // reuse as a cursor array
    fill.assign(m.bucketStart.begin(), m.bucketStart.end() - 1);
    for (size_t i = 0; i < n; ++i)
      if (ps.isAliveDense(i)) m.sorted[fill[m.bucketOf[i]]++] = uint32_t(i);
    m.entries.resize(m.sorted.size());
    if (useFilter) {
      for (auto* a : {&m.sx, &m.sy, &m.sz, &m.sr, &m.sw}) a->assign(m.sorted.size() + 4, 0.0);
    }
    for (size_t k = 0; k < m.sorted.size(); ++k) {
      const uint32_t j = m.sorted[k];
      const uint32_t fast = twoSpeed && m.w[j] > slowW ? 1u : 0u;
      m.entries[k] = {x[j], r[j], m.w[j], m.cx[j], m.cy[j], m.cz[j], j, fast};
      if (m.dense) m.posOf[j] = uint32_t(k);
      if (useFilter) {
        m.sx[k] = x[j].x();
        m.sy[k] = x[j].y();
        m.sz[k] = x[j].z();
        m.sr[k] = r[j];
        m.sw[k] = m.w[j];
      }
    }
    for (size_t i = 0; i < n; ++i)
      if (twoSpeed && ps.isAliveDense(i) && m.w[i] > slowW) m.fastList.push_back(uint32_t(i));
  }

  // ---- particle pairs ----------------------------------------------------------------------------------------
  // Slow particles: half stencil. A slow particle looks at its own cell (partners of higher index only) and the
  // 13 neighbour cells that come after its own in (z, y, x) order, so each pair of cells is visited from one
  // side only, and it skips fast partners (they find it). A pair found from the higher particle's side is
  // stored as (lower, higher); the pairs are then put in (a, b) order by a counting sort on a and a sort of each
  // a's few partners, and the contacts are computed from a's side (d = x_a - x_b): the same contact list in the
  // same order, bit for bit, whichever particle found the pair.
  // Fast particles (w_i > slowW): a full search of every cell within R_i = r_i + maxR + min(2 w_i + margin,
  // reach) (the farthest partner of speed bound <= w_i), taking slow partners and fast partners of lower bound
  // (equal bounds: of higher index), so each pair with a fast particle is found once, by its faster particle.
  const size_t numChunks = (n + kChunk - 1) / kChunk;
  if (m.chunkPairs.size() < numChunks) m.chunkPairs.resize(numChunks);
#pragma omp parallel for schedule(dynamic, 1) if (numChunks >= kParallelChunks)
  for (size_t c = 0; c < numChunks; ++c) {
    auto& out = m.chunkPairs[c];
    out.clear();
    const size_t end = std::min(n, (c + 1) * kChunk);
    for (size_t i = c * kChunk; i < end; ++i) {
      if (!ps.isAliveDense(i)) continue;
      const Vec3 xi = x[i];
      const Real ri = r[i];
      const Real wi = m.w[i];
      const bool fastI = twoSpeed && wi > slowW;
      // Position of the centre within its cell, in cells.
      const Vec3 f = xi * m.ginvCell - Vec3(m.cx[i], m.cy[i], m.cz[i]);
      // A candidate j at entry e: the same tests whichever grid found it.
      auto test = [&](const Impl::Entry& e) SCREE_PAIR_INLINE {
        const uint32_t j = e.j;
        const Vec3 d = xi - e.x;  // the negative of x_j - x_i: the same squared norm
        const Real dist2 = d.squaredNorm();
        // Cheap reject first: beyond ri + rj + min(w_i + w_j + margin, reach) the pair cannot touch (the bound
        // above; floating-point addition is monotone, so far >= lim below and the reject never drops a pair the
        // exact test keeps); the relative speed (a square root) is read only for the rest.
        const Real far = ri + e.r + std::min(wi + e.w + margin_, reach);
        if (dist2 >= far * far) return;
        const Real pairMargin = std::min(h * (v[i] - v[j]).norm() + margin_, reach);
        const Real lim = ri + e.r + pairMargin;
        if (dist2 >= lim * lim) return;
        out.push_back(j > i ? std::make_pair(uint32_t(i), j) : std::make_pair(j, uint32_t(i)));
      };
      // Calls f(entry) for the run [k0, k1) of the sorted entries: all of them, or (the four-wide filter on)
      // only those the cheap reject does not certainly drop. f makes the full test either way.
      auto scanRun = [&](uint32_t k0, uint32_t k1, auto&& f) SCREE_PAIR_INLINE {
#ifdef SCREE_PAIR_AVX2
        if (useFilter) {
          for (uint32_t b0 = k0; b0 < k1; b0 += 64) {
            const uint32_t count = std::min<uint32_t>(64, k1 - b0);
            uint64_t keep = pairFilterAvx2(m.sx.data(), m.sy.data(), m.sz.data(), m.sr.data(), m.sw.data(), b0,
                                           count, xi.x(), xi.y(), xi.z(), ri, wi, margin_, reach);
            while (keep) {
              f(m.entries[b0 + uint32_t(__builtin_ctzll(keep))]);
              keep &= keep - 1;
            }
          }
          return;
        }
#endif
        for (uint32_t k = k0; k < k1; ++k) f(m.entries[k]);
      };
      if (fastI) {
        auto take = [&](const Impl::Entry& e) SCREE_PAIR_INLINE {
          if (e.j == i) return;
          if (e.fast && (e.w > wi || (e.w == wi && e.j < i))) return;
          test(e);
        };
        // Reach in cells, with 1e-6 cell of slack for the rounding of the cell coordinates.
        const Real reachCells = (ri + maxR + std::min(2 * wi + margin_, reach)) * m.ginvCell * (1 + 1e-9) + 1e-6;
        const Real reach2 = reachCells * reachCells;
        const int K = int(std::ceil(reachCells));
        // Squared distance in cells from the centre to the slab at offset o along an axis.
        auto gap2 = [&](int ax, int o) {
          const Real g = o < 0 ? f[ax] + Real(-o - 1) : o > 0 ? Real(1) - f[ax] + Real(o - 1) : Real(0);
          const Real gp = std::max<Real>(g, 0);
          return gp * gp;
        };
        for (int dz = -K; dz <= K; ++dz) {
          const Real gz = gap2(2, dz);
          if (gz >= reach2) continue;
          for (int dy = -K; dy <= K; ++dy) {
            const Real gyz = gz + gap2(1, dy);
            if (gyz >= reach2) continue;
            int x0 = -K, x1 = K;
            while (x0 < 0 && gyz + gap2(0, x0) >= reach2) ++x0;
            while (x1 > 0 && gyz + gap2(0, x1) >= reach2) --x1;
            const int64_t qy = int64_t(m.cy[i]) + dy, qz = int64_t(m.cz[i]) + dz;
            if (m.dense) {
              if (qy < m.lo[1] || qy > m.hi[1] || qz < m.lo[2] || qz > m.hi[2]) continue;
              const int64_t qx0 = std::max<int64_t>(int64_t(m.cx[i]) + x0, m.lo[0]);
              const int64_t qx1 = std::min<int64_t>(int64_t(m.cx[i]) + x1, m.hi[0]);
              if (qx0 > qx1) continue;
              const uint32_t k0 = m.bucketStart[size_t(m.denseCell(qx0, qy, qz))];
              const uint32_t k1 = m.bucketStart[size_t(m.denseCell(qx1, qy, qz)) + 1];
              scanRun(k0, k1, take);
              continue;
            }
            for (int dx = x0; dx <= x1; ++dx) {
              const int64_t qx = int64_t(m.cx[i]) + dx;
              const size_t b = hashCell(qx, qy, qz) & m.tableMask;
              for (uint32_t k = m.bucketStart[b]; k < m.bucketStart[b + 1]; ++k) {
                const Impl::Entry& e = m.entries[k];
                if (e.cx != qx || e.cy != qy || e.cz != qz) continue;
                take(e);
              }
            }
          }
        }
        continue;
      }
      auto takeSlow = [&](const Impl::Entry& e) SCREE_PAIR_INLINE {
        if (e.fast) return;
        test(e);
      };
      // A neighbour cell whose nearest point is at least one cell (more than r_i + r_j + the slow reach) away
      // holds no partner, so it is not visited (about a quarter of them).
      Real gap2[3][3];  // [axis][offset + 1]: squared distance (cells) to the neighbour slab along the axis
      for (int ax = 0; ax < 3; ++ax) {
        const Real lo = std::max<Real>(f[ax], 0), hi = std::max<Real>(1 - f[ax], 0);
        gap2[ax][0] = lo * lo;
        gap2[ax][1] = 0;
        gap2[ax][2] = hi * hi;
      }
      if (m.dense) {
        // Dense grid: the own cell after i's entry (the partners of higher index: a cell's entries are in
        // dense order) and, when in reach, the cell x+1 of the same row; then the rows (y+1, z) and
        // (y-1..y+1, z+1), each from x-1 to x+1 trimmed by the same one-cell rule. A row is one contiguous run.
        const int64_t c = int64_t(m.bucketOf[i]);
        const uint32_t own1 = m.bucketStart[size_t(c) + (gap2[0][2] < 1 ? 2 : 1)];
        scanRun(m.posOf[i] + 1, own1, takeSlow);
        for (int dz = 0; dz <= 1; ++dz)
          for (int dy = dz == 0 ? 1 : -1; dy <= 1; ++dy) {
            const Real g = gap2[1][dy + 1] + gap2[2][dz + 1];
            if (g >= 1) continue;
            const int64_t row = c + dz * m.nxy + dy * m.nx;
            const uint32_t k0 = m.bucketStart[size_t(row + (g + gap2[0][0] < 1 ? -1 : 0))];
            const uint32_t k1 = m.bucketStart[size_t(row + (g + gap2[0][2] < 1 ? 2 : 1))];
            scanRun(k0, k1, takeSlow);
          }
        continue;
      }
      for (int dz = 0; dz <= 1; ++dz)
        for (int dy = dz == 0 ? 0 : -1; dy <= 1; ++dy)
          for (int dx = dz == 0 && dy == 0 ? 0 : -1; dx <= 1; ++dx) {
            if (gap2[0][dx + 1] + gap2[1][dy + 1] + gap2[2][dz + 1] >= 1) continue;
            const bool own = dx == 0 && dy == 0 && dz == 0;
            const int64_t qx = int64_t(m.cx[i]) + dx, qy = int64_t(m.cy[i]) + dy, qz = int64_t(m.cz[i]) + dz;
            const size_t b = hashCell(qx, qy, qz) & m.tableMask;
            for (uint32_t k = m.bucketStart[b]; k < m.bucketStart[b + 1]; ++k) {
              const Impl::Entry& e = m.entries[k];
              if ((own && e.j <= i) || e.cx != qx || e.cy != qy || e.cz != qz) continue;
              takeSlow(e);
            }
          }
    }
  }
  // Counting sort by a, then each a's partners in ascending order.
  m.pairStart.assign(n + 1, 0);
  for (size_t c = 0; c < numChunks; ++c)
    for (const auto& [a, b] : m.chunkPairs[c]) ++m.pairStart[a + 1];
  for (size_t i = 0; i < n; ++i) m.pairStart[i + 1] += m.pairStart[i];
  const size_t total = m.pairStart[n];
  m.pairB.resize(total);
  {
    std::vector<uint32_t>& fill = m.candidates;  // reuse as a cursor array
    fill.assign(m.pairStart.begin(), m.pairStart.end() - 1);
    for (size_t c = 0; c < numChunks; ++c)
      for (const auto& [a, b] : m.chunkPairs[c]) m.pairB[fill[a]++] = b;
  }
  pp_.resize(total);
#pragma omp parallel for schedule(dynamic, 1) if (numChunks >= kParallelChunks)
  for (size_t c = 0; c < numChunks; ++c) {
    const size_t end = std::min(n, (c + 1) * kChunk);
    for (size_t i = c * kChunk; i < end; ++i) {
      const uint32_t k0 = m.pairStart[i], k1 = m.pairStart[i + 1];
      if (k0 == k1) continue;
      // Order this particle's contacts by partner so the list does not depend on the hash layout.
      // A particle has a handful of partners: an insertion sort (std::sort's set-up cost more than the sort;
      // the partners are distinct, so the order is the same).
      if (k1 - k0 <= 24) {
        uint32_t* pb = m.pairB.data();
        for (uint32_t k = k0 + 1; k < k1; ++k) {
          const uint32_t val = pb[k];
          uint32_t q = k;
          while (q > k0 && pb[q - 1] > val) {
            pb[q] = pb[q - 1];
            --q;
          }
          pb[q] = val;
        }
      } else {
        std::sort(m.pairB.begin() + k0, m.pairB.begin() + k1);
      }
      const Vec3 xi = x[i];
      const Real ri = r[i];
      for (uint32_t k = k0; k < k1; ++k) {
        const uint32_t j = m.pairB[k];
        const Vec3 d = xi - x[j];
        const Real dist = std::sqrt(d.squaredNorm());
        // Built whole and assigned: pp_[k] may hold last step's contact (and a listener's overrides).
        ParticleContact pc;
        pc.a = uint32_t(i);
        pc.b = int32_t(j);
        // Coincident centres: any unit normal will do; pick +z so the result is deterministic.
        pc.normal = dist > 1e-12 * (ri + r[j]) ? Vec3(d / dist) : Vec3::UnitZ();
        pc.depth = ri + r[j] - dist;
        // Midway between the two surfaces.
        pc.point = xi - pc.normal * (ri - 0.5 * pc.depth);
        pp_[k] = pc;
      }
    }
  }

  // ---- particles vs geometries -------------------------------------------------------------------------------
  const int nt = maxThreads();
  if (int(m.probes.size()) < nt) {
    for (int t = int(m.probes.size()); t < nt; ++t) {
      m.probeShapes.push_back(std::make_shared<Sphere>(1.0));
      m.probes.push_back(std::make_unique<Geometry>(m.probeShapes.back(), "particle probe"));
    }
    m.scratch.resize(size_t(nt));
  }
  Aabb cloud;
  for (size_t i = 0; i < n; ++i)
    if (ps.isAliveDense(i)) cloud.expand(x[i]);
  cloud.inflate(maxR + maxV * h + margin_);
  for (const GeometryRef& gref : geometries) {
    const Geometry& g = *gref;
    if (!g.getEnableCollisions()) continue;
    if (!hasCollider(Shape::SPHERE, g.getShape()->getType())) continue;
    const RigidBody* body = g.getRigidBody();
    const Vec3 vBody = body ? body->getVelocity() : Vec3::Zero();
    const Real bodyReach = body ? (body->getVelocity().norm() + body->getAngularVelocity().norm() *
                                                                     0.5 * g.getBoundingBox().extent().norm()) * h
                                : 0.0;
    Aabb box = g.getBoundingBox();
    box.inflate(maxR + maxV * h + bodyReach + margin_);
    if (!box.overlaps(cloud)) continue;
    // Candidates: cells the clipped box covers, or every particle when that is cheaper.
    Aabb clip;
    clip.lo = box.lo.cwiseMax(cloud.lo);
    clip.hi = box.hi.cwiseMin(cloud.hi);
    const Vec3 cells = ((clip.hi - clip.lo) * m.ginvCell).array() + 2.0;
    auto& cand = m.candidates;
    cand.clear();
    if (cells.x() * cells.y() * cells.z() < Real(n)) {
      const int64_t x0 = cellCoord(clip.lo.x(), m.ginvCell), x1 = cellCoord(clip.hi.x(), m.ginvCell);
      const int64_t y0 = cellCoord(clip.lo.y(), m.ginvCell), y1 = cellCoord(clip.hi.y(), m.ginvCell);
      const int64_t z0 = cellCoord(clip.lo.z(), m.ginvCell), z1 = cellCoord(clip.hi.z(), m.ginvCell);
      for (int64_t cz = z0; cz <= z1; ++cz)
        for (int64_t cy = y0; cy <= y1; ++cy)
          for (int64_t cx = x0; cx <= x1; ++cx) m.forCell(cx, cy, cz, [&](uint32_t j) { cand.push_back(j); });
      std::sort(cand.begin(), cand.end());
    } else {
      for (size_t i = 0; i < n; ++i)
        if (ps.isAliveDense(i)) cand.push_back(uint32_t(i));
    }
    if (cand.empty()) continue;
    const Aabb gBox = g.getBoundingBox();
    const size_t nc = cand.size();
    const size_t numGChunks = (nc + kChunk - 1) / kChunk;
    if (m.chunkOut.size() < numGChunks) m.chunkOut.resize(numGChunks);
#pragma omp parallel for schedule(dynamic, 1) if (numGChunks >= kParallelChunks)
    for (size_t c = 0; c < numGChunks; ++c) {
      auto& out = m.chunkOut[c];
      out.clear();
      const int t = threadIndex();
      Geometry& probe = *m.probes[size_t(t)];
      Sphere& probeShape = *m.probeShapes[size_t(t)];
      auto& pts = m.scratch[size_t(t)];
      const size_t end = std::min(nc, (c + 1) * kChunk);
      for (size_t k = c * kChunk; k < end; ++k) {
        const uint32_t i = cand[k];
        const Real pm = h * (v[i] - vBody).norm() + bodyReach + margin_;
        Aabb pb;
        pb.expand(x[i]);
        pb.inflate(r[i] + pm);
        if (!pb.overlaps(gBox)) continue;
        probeShape.setRadius(r[i]);
        probe.setPosition(x[i]);
        pts.clear();
        collideGeometries(probe, g, pm, pts);
        for (const ContactPoint& p : pts) {
          ParticleContact pc;
          pc.a = i;
          pc.b = -1;
          pc.geometry = &g;
          pc.point = p.point;
          pc.normal = p.normal;
          pc.depth = p.depth;
          pc.featureId = p.featureId;
          pc.sensor = g.isSensor();
          out.push_back(pc);
        }
      }
    }
    for (size_t c = 0; c < numGChunks; ++c) pg_.insert(pg_.end(), m.chunkOut[c].begin(), m.chunkOut[c].end());
  }
}

// ---- four-wide candidate filter: switches (header, "Candidate filter") ----
namespace {
bool& pairFilterEnabled() {
  static bool on = true;
  return on;
}
}  // namespace
bool ParticleCollider::pairFilterAvailable() {
#ifdef SCREE_PAIR_AVX2
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
#else
  return false;
#endif
}
void ParticleCollider::setPairFilterEnabled(bool on) { pairFilterEnabled() = on; }
bool ParticleCollider::pairFilterActive() { return pairFilterEnabled() && pairFilterAvailable(); }
bool ParticleCollider::usedPairFilter() const { return impl_->usedFilter; }

Real ParticleCollider::getCellSize() const { return impl_->cell; }
size_t ParticleCollider::getNumFastParticles() const { return impl_->fastList.size(); }

std::vector<uint32_t> ParticleCollider::localityOrder(const GranularBodySystem& ps) const {
  const Impl& m = *impl_;
  const size_t n = ps.size();
  std::vector<uint32_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = uint32_t(i);
  if (m.xLast.size() != n) return order;
  // The cells of the reported cell size (2 maxR + reach), not the two-speed grid's: the order is the same as
  // before that grid existed, so results do not change.
  std::vector<int32_t> cx(n), cy(n), cz(n);
  for (size_t i = 0; i < n; ++i) {
    cx[i] = cellCoord(m.xLast[i].x(), m.invCell);
    cy[i] = cellCoord(m.xLast[i].y(), m.invCell);
    cz[i] = cellCoord(m.xLast[i].z(), m.invCell);
  }
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    if (cz[a] != cz[b]) return cz[a] < cz[b];
    if (cy[a] != cy[b]) return cy[a] < cy[b];
    return cx[a] < cx[b];
  });
  return order;
}

}  // namespace scree::detail
