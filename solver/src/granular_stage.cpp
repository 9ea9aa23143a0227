// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include <limits>
#include "granular_stage.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <sstream>

#ifndef SCREE_PACKET_RUN
#define SCREE_PACKET_RUN 2
#endif

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif

#include "contact_law.h"
#include "scree/solver/direct.h"
#include "scree/solver/spook.h"

namespace scree::detail {

namespace {
// Parallel loops below this many items run serially (the fork/join would cost more than the work); results
// are the same either way.
constexpr size_t kParallelMin = 2048;
constexpr int kMaxSlabs = 64;

// The unit solve's small lambdas (relative velocity, gain, impulse) are called several times per unit; GCC
// kept the impulse one out of line (about 6 % of the trench bench, bench/bench_terrain_dig.cpp). Same code
// either way, so forcing it inline changes no result.
#if defined(__GNUC__)
#define SCREE_UNIT_INLINE __attribute__((always_inline))
#else
#define SCREE_UNIT_INLINE
#endif

/// The rolling-resistance rows of a unit for relative angular velocity wr (a's minus b's): updates the unit's
/// accumulated rolling impulses (disc bound rollMu * normal impulse) and returns the angular impulse on a (b gets
/// its negative). Shared by the general and the centred unit solve.
template <class U>
SCREE_UNIT_INLINE inline Vec3 rollingImpulse(U& u, const Vec3& wr) {
  const Real lim = u.rollMu * std::max<Real>(u.lN, 0);
  Real l1 = 0, l2 = 0;  // a zero bound (no normal impulse: a separated or speculative contact) leaves no torque
  if (lim != 0) {
    l1 = u.lR1 + (-u.t1.dot(wr) - u.eT * u.lR1) * u.kR;
    l2 = u.lR2 + (-u.t2.dot(wr) - u.eT * u.lR2) * u.kR;
    projectOntoDisc(l1, l2, lim);
  }
  const Vec3 T = (l1 - u.lR1) * u.t1 + (l2 - u.lR2) * u.t2;
  u.lR1 = l1;
  u.lR2 = l2;
  return T;
}

/// Warm-start key of a particle: the low 32 bits of its id (its slot, stable while it lives).
uint64_t slotKey(const GranularBodySystem& ps, size_t dense) { return uint64_t(ps.idLowOfDense(dense)); }

/// Order-preserving map of a finite height to an unsigned key (-0 is taken as +0: equal for operator<).
uint64_t heightKey(Real h) {
  static_assert(sizeof(Real) == sizeof(uint64_t));
  const uint64_t u = std::bit_cast<uint64_t>(h + 0.0);  // -0 + 0 = +0
  return (u >> 63) ? ~u : u | (uint64_t(1) << 63);
}

/// Sorts (heightKey, code) pairs pushed in increasing code order into (height, code) order, as std::sort on
/// (height, code) did: a stable LSD radix sort (8-bit digits, a digit that all keys share is skipped), which
/// keeps equal heights in code order. Fewer mispredicted branches than std::sort here (the shock order has
/// 10,000-20,000 entries in the trench bench). The heights are finite (integrate stops a particle before its
/// position turns non-finite).
void sortByHeight(std::vector<std::pair<uint64_t, uint32_t>>& v, std::vector<std::pair<uint64_t, uint32_t>>& tmp) {
  const size_t n = v.size();
  if (n < 64) {
    std::sort(v.begin(), v.end());
    return;
  }
  tmp.resize(n);
  auto* src = &v;
  auto* dst = &tmp;
  for (int shift = 0; shift < 64; shift += 8) {
    uint32_t count[257] = {};
    for (const auto& e : *src) ++count[((e.first >> shift) & 0xff) + 1];
    if (count[(((*src)[0].first >> shift) & 0xff) + 1] == n) continue;  // all share this digit
    for (int d = 0; d < 256; ++d) count[d + 1] += count[d];
    for (const auto& e : *src) (*dst)[count[(e.first >> shift) & 0xff]++] = e;
    std::swap(src, dst);
  }
  if (src != &v) v.swap(tmp);
}

/// One stable LSD radix pass set (8-bit digits; a digit all elements share is skipped) over the bits
/// [0, bits) of digitKey(element), from src into tmp and back; the result ends in v.
template <class T, class KeyOf>
void radixSortBy(std::vector<T>& v, std::vector<T>& tmp, int bits, KeyOf digitKey) {
  const size_t n = v.size();
  tmp.resize(n);
  auto* src = &v;
  auto* dst = &tmp;
  for (int shift = 0; shift < bits; shift += 8) {
    uint32_t count[257] = {};
    for (const auto& e : *src) ++count[((digitKey(e) >> shift) & 0xff) + 1];
    if (count[((digitKey((*src)[0]) >> shift) & 0xff) + 1] == n) continue;  // all share this digit
    for (int d = 0; d < 256; ++d) count[d + 1] += count[d];
    for (const auto& e : *src) (*dst)[count[(digitKey(e) >> shift) & 0xff]++] = e;
    std::swap(src, dst);
  }
  if (src != &v) v.swap(tmp);
}

// ---- Four-wide sweep ---------------------------------------------------------------------------------------
// Issue 16, trench speed (docs/terrain.md, "Digging cost", sixth round). The centred Gauss-Seidel update
// (solveCentred<-1>) was 41 % of the trench bench, bound by each unit's own arithmetic. Four centred units that
// share no particle are solved at once, one per lane of 256-bit AVX2 registers, in double precision.
// WHY the results are bit-identical to the scalar sweep in unit order:
//  - order: each slab's units get a dependency level (one more than the highest level of the slab's earlier
//    units that share a particle with it) and are swept level by level. Units of one level share no particle,
//    so they commute exactly; any two units sharing a particle keep their order (reversed, with the level order,
//    in backward sweeps). A level is cut into packets of four centred units plus single (scalar) units.
//  - arithmetic: each lane performs the scalar code's IEEE operations in the same order (the dot products as
//    (x + y) + z, as Eigen evaluates them here); the kernel is compiled for AVX2 without FMA, so nothing is
//    contracted; std::max and the branches become compare-and-blend with the same predicates (a skipped update
//    is a blend that keeps the old value, so not even the sign of a zero changes).
// Packets exclude units with infinite friction or rolling bounds (the glued DIRECT bonds) and non-centred
// units. The kernel is chosen at run time (__builtin_cpu_supports), so the build runs on any x86-64; elsewhere,
// or without AVX2, the scalar sweep runs in unit order. test_unit_granular_system compares both bit for bit.
bool gVectorSweepEnabled = true;
bool gWideSweepEnabled = true;  // setAvx512SweepEnabled
std::atomic<uint64_t> gWideUnits{0};  // wideUnitsTotal
std::atomic<uint64_t> gPackedUnits{0};  // packedUnitsTotal
// Packets per kernel call (1-4): independent packets of one level solved together overlap their latencies.
constexpr size_t kPacketRun = SCREE_PACKET_RUN;

#if defined(__x86_64__) && defined(__GNUC__)
#define SCREE_SWEEP_AVX2 1
#define SCREE_AVX2 __attribute__((target("avx2")))
using P4 = __m256d;

SCREE_AVX2 inline void load3(const Vec3* arr, const uint32_t* idx, P4& X, P4& Y, P4& Z) {
  const double* p0 = arr[idx[0]].data();
  const double* p1 = arr[idx[1]].data();
  const double* p2 = arr[idx[2]].data();
  const double* p3 = arr[idx[3]].data();
  const __m128d r0 = _mm_loadu_pd(p0), r1 = _mm_loadu_pd(p1), r2 = _mm_loadu_pd(p2), r3 = _mm_loadu_pd(p3);
  X = _mm256_set_m128d(_mm_unpacklo_pd(r2, r3), _mm_unpacklo_pd(r0, r1));
  Y = _mm256_set_m128d(_mm_unpackhi_pd(r2, r3), _mm_unpackhi_pd(r0, r1));
  Z = _mm256_set_pd(p3[2], p2[2], p1[2], p0[2]);
}

SCREE_AVX2 inline void store3(Vec3* arr, const uint32_t* idx, P4 X, P4 Y, P4 Z) {
  const __m128d x01 = _mm256_castpd256_pd128(X), x23 = _mm256_extractf128_pd(X, 1);
  const __m128d y01 = _mm256_castpd256_pd128(Y), y23 = _mm256_extractf128_pd(Y, 1);
  alignas(32) double z[4];
  _mm256_store_pd(z, Z);
  double* p0 = arr[idx[0]].data();
  double* p1 = arr[idx[1]].data();
  double* p2 = arr[idx[2]].data();
  double* p3 = arr[idx[3]].data();
  _mm_storeu_pd(p0, _mm_unpacklo_pd(x01, y01));
  _mm_storeu_pd(p1, _mm_unpackhi_pd(x01, y01));
  _mm_storeu_pd(p2, _mm_unpacklo_pd(x23, y23));
  _mm_storeu_pd(p3, _mm_unpackhi_pd(x23, y23));
  p0[2] = z[0];
  p1[2] = z[1];
  p2[2] = z[2];
  p3[2] = z[3];
}

SCREE_AVX2 inline P4 add(P4 a, P4 b) { return _mm256_add_pd(a, b); }
SCREE_AVX2 inline P4 sub(P4 a, P4 b) { return _mm256_sub_pd(a, b); }
SCREE_AVX2 inline P4 mul(P4 a, P4 b) { return _mm256_mul_pd(a, b); }
/// mask ? b : a
SCREE_AVX2 inline P4 sel(P4 a, P4 b, P4 mask) { return _mm256_blendv_pd(a, b, mask); }
/// (x0 y0 + x1 y1) + x2 y2, as Eigen's Vec3::dot in the scalar code
SCREE_AVX2 inline P4 dot3(P4 ax, P4 ay, P4 az, P4 bx, P4 by, P4 bz) {
  return add(add(mul(ax, bx), mul(ay, by)), mul(az, bz));
}
/// projectOntoDisc (contact_law.h), lane by lane.
SCREE_AVX2 inline void projectDisc4(P4& l1, P4& l2, P4 lim) {
  const P4 zero = _mm256_setzero_pd();
  const P4 mag2 = add(mul(l1, l1), mul(l2, l2));
  const P4 over = _mm256_cmp_pd(mag2, mul(lim, lim), _CMP_GT_OQ);
  const P4 mag = _mm256_sqrt_pd(mag2);
  const P4 s = sel(zero, _mm256_div_pd(lim, mag), _mm256_cmp_pd(mag, zero, _CMP_GT_OQ));
  l1 = sel(l1, mul(l1, s), over);
  l2 = sel(l2, mul(l2, s), over);
}

/// The state of one packet in the kernel: its particles' velocities, inverse masses and inertias (read from the
/// particle arrays by index, not stored in the packet: 128 fewer bytes per packet to stream), and what the
/// later updates need.
struct LaneState {
  P4 vax, vay, vaz, vbx, vby, vbz, wax, way, waz, wbx, wby, wbz;
  P4 ima, imb, iIa, iIb;  // the particles' inverse masses and inertias (read from the particle arrays)
  P4 lNpos;  // max(lambda_n, 0) after the normal update
  P4 absD;   // |delta lambda_n|
};

SCREE_AVX2 inline P4 gather4(const Real* arr, const uint32_t* idx) {
  return _mm256_set_pd(arr[idx[3]], arr[idx[2]], arr[idx[1]], arr[idx[0]]);
}

SCREE_AVX2 inline void stageLoad(const GranularStage::Packet& p, const Vec3* v, const Vec3* w, const Real* invM,
                                 const Real* invI, LaneState& s) {
  s.ima = gather4(invM, p.a);
  s.imb = gather4(invM, p.b);
  s.iIa = gather4(invI, p.a);
  s.iIb = gather4(invI, p.b);
  load3(v, p.a, s.vax, s.vay, s.vaz);
  load3(v, p.b, s.vbx, s.vby, s.vbz);
  load3(w, p.a, s.wax, s.way, s.waz);
  load3(w, p.b, s.wbx, s.wby, s.wbz);
}

SCREE_AVX2 inline void stageStore(const GranularStage::Packet& p, Vec3* v, Vec3* w, const LaneState& s) {
  store3(v, p.a, s.vax, s.vay, s.vaz);
  store3(v, p.b, s.vbx, s.vby, s.vbz);
  store3(w, p.a, s.wax, s.way, s.waz);
  store3(w, p.b, s.wbx, s.wby, s.wbz);
}

/// The normal row of solveCentred<-1>, lane by lane.
SCREE_AVX2 inline void stageNormal(GranularStage::Packet& p, LaneState& s) {
  using G = GranularStage;
  auto F = [&](int k) SCREE_AVX2 { return _mm256_load_pd(p.f[k]); };
  const P4 zero = _mm256_setzero_pd();
  const P4 nx = F(G::kNx), ny = F(G::kNy), nz = F(G::kNz);
  const P4 ima = s.ima, imb = s.imb;
  const P4 lN = F(G::kLN);
  const P4 vn = dot3(nx, ny, nz, sub(s.vax, s.vbx), sub(s.vay, s.vby), sub(s.vaz, s.vbz));
  P4 nl = add(lN, mul(sub(sub(F(G::kRhsN), vn), mul(F(G::kEN), lN)), F(G::kKN)));
  const P4 lo = F(G::kLoN);
  nl = sel(nl, lo, _mm256_cmp_pd(nl, lo, _CMP_LT_OQ));  // std::max(nl, lo)
  const P4 d = sub(nl, lN);
  _mm256_store_pd(p.f[G::kLN], nl);
  const P4 moved = _mm256_cmp_pd(d, zero, _CMP_NEQ_UQ);
  const P4 px = mul(d, nx), py = mul(d, ny), pz = mul(d, nz);
  s.vax = sel(s.vax, add(s.vax, mul(ima, px)), moved);
  s.vay = sel(s.vay, add(s.vay, mul(ima, py)), moved);
  s.vaz = sel(s.vaz, add(s.vaz, mul(ima, pz)), moved);
  s.vbx = sel(s.vbx, sub(s.vbx, mul(imb, px)), moved);
  s.vby = sel(s.vby, sub(s.vby, mul(imb, py)), moved);
  s.vbz = sel(s.vbz, sub(s.vbz, mul(imb, pz)), moved);
  s.lNpos = sel(nl, zero, _mm256_cmp_pd(nl, zero, _CMP_LT_OQ));  // std::max(lN, 0)
  s.absD = _mm256_andnot_pd(_mm256_set1_pd(-0.0), d);
}

/// The friction rows (packets hold finite mu only: frictionLimit = mu max(lN, 0)).
SCREE_AVX2 inline void stageFriction(GranularStage::Packet& p, LaneState& s) {
  using G = GranularStage;
  auto F = [&](int k) SCREE_AVX2 { return _mm256_load_pd(p.f[k]); };
  const P4 zero = _mm256_setzero_pd();
  const P4 t1x = F(G::kT1x), t1y = F(G::kT1y), t1z = F(G::kT1z);
  const P4 t2x = F(G::kT2x), t2y = F(G::kT2y), t2z = F(G::kT2z);
  const P4 eT = F(G::kET);
  const P4 mu = F(G::kMu);
  const P4 lim = mul(mu, s.lNpos);
  const P4 lT1 = F(G::kLT1), lT2 = F(G::kLT2);
  const P4 la = F(G::kLa), lb = F(G::kLb), sigma = F(G::kSigma);
  const P4 dvx = sub(s.vax, s.vbx), dvy = sub(s.vay, s.vby), dvz = sub(s.vaz, s.vbz);
  const P4 Lx = add(mul(la, s.wax), mul(lb, s.wbx)), Ly = add(mul(la, s.way), mul(lb, s.wby)),
           Lz = add(mul(la, s.waz), mul(lb, s.wbz));
  const P4 vt1 = sub(dot3(t1x, t1y, t1z, dvx, dvy, dvz), mul(sigma, dot3(Lx, Ly, Lz, t2x, t2y, t2z)));
  const P4 vt2 = add(dot3(t2x, t2y, t2z, dvx, dvy, dvz), mul(sigma, dot3(Lx, Ly, Lz, t1x, t1y, t1z)));
  const P4 kT = F(G::kKT);
  P4 l1 = add(lT1, mul(sub(sub(zero, vt1), mul(eT, lT1)), kT));  // rhsT1 = +0 (see packable)
  P4 l2 = add(lT2, mul(sub(sub(zero, vt2), mul(eT, lT2)), kT));
  projectDisc4(l1, l2, lim);
  const P4 bounded = _mm256_cmp_pd(lim, zero, _CMP_NEQ_UQ);  // a zero bound leaves no friction
  l1 = sel(zero, l1, bounded);
  l2 = sel(zero, l2, bounded);
  const P4 has = _mm256_cmp_pd(mu, zero, _CMP_GT_OQ);  // mu > 0, else no friction rows at all
  l1 = sel(lT1, l1, has);
  l2 = sel(lT2, l2, has);
  const P4 d1 = sub(l1, lT1), d2 = sub(l2, lT2);
  _mm256_store_pd(p.f[G::kLT1], l1);
  _mm256_store_pd(p.f[G::kLT2], l2);
  const P4 moved = _mm256_or_pd(_mm256_cmp_pd(d1, zero, _CMP_NEQ_UQ), _mm256_cmp_pd(d2, zero, _CMP_NEQ_UQ));
  const P4 px = add(mul(d1, t1x), mul(d2, t2x)), py = add(mul(d1, t1y), mul(d2, t2y)),
           pz = add(mul(d1, t1z), mul(d2, t2z));
  const P4 qx = mul(sigma, sub(mul(d1, t2x), mul(d2, t1x))), qy = mul(sigma, sub(mul(d1, t2y), mul(d2, t1y))),
           qz = mul(sigma, sub(mul(d1, t2z), mul(d2, t1z)));  // n x P
  const P4 ima = s.ima, imb = s.imb;
  const P4 iia = mul(s.iIa, la), iib = mul(s.iIb, lb);  // as solveCentred's
  s.vax = sel(s.vax, add(s.vax, mul(ima, px)), moved);
  s.vay = sel(s.vay, add(s.vay, mul(ima, py)), moved);
  s.vaz = sel(s.vaz, add(s.vaz, mul(ima, pz)), moved);
  s.wax = sel(s.wax, sub(s.wax, mul(iia, qx)), moved);
  s.way = sel(s.way, sub(s.way, mul(iia, qy)), moved);
  s.waz = sel(s.waz, sub(s.waz, mul(iia, qz)), moved);
  s.vbx = sel(s.vbx, sub(s.vbx, mul(imb, px)), moved);
  s.vby = sel(s.vby, sub(s.vby, mul(imb, py)), moved);
  s.vbz = sel(s.vbz, sub(s.vbz, mul(imb, pz)), moved);
  s.wbx = sel(s.wbx, sub(s.wbx, mul(iib, qx)), moved);
  s.wby = sel(s.wby, sub(s.wby, mul(iib, qy)), moved);
  s.wbz = sel(s.wbz, sub(s.wbz, mul(iib, qz)), moved);
}

/// The rolling rows (rollingImpulse; packets hold finite rollMu only).
SCREE_AVX2 inline void stageRolling(GranularStage::Packet& p, LaneState& s) {
  using G = GranularStage;
  auto F = [&](int k) SCREE_AVX2 { return _mm256_load_pd(p.f[k]); };
  const P4 zero = _mm256_setzero_pd();
  const P4 signBit = _mm256_set1_pd(-0.0);
  const P4 t1x = F(G::kT1x), t1y = F(G::kT1y), t1z = F(G::kT1z);
  const P4 t2x = F(G::kT2x), t2y = F(G::kT2y), t2z = F(G::kT2z);
  const P4 eT = F(G::kET);
  const P4 rollMu = F(G::kRollMu), kR = F(G::kKR);
  const P4 has = _mm256_and_pd(_mm256_cmp_pd(rollMu, zero, _CMP_GT_OQ), _mm256_cmp_pd(kR, zero, _CMP_GT_OQ));
  const P4 lim = mul(rollMu, s.lNpos);
  const P4 lR1 = F(G::kLR1), lR2 = F(G::kLR2);
  const P4 rx = sub(s.wax, s.wbx), ry = sub(s.way, s.wby), rz = sub(s.waz, s.wbz);
  const P4 neg1 = _mm256_xor_pd(dot3(t1x, t1y, t1z, rx, ry, rz), signBit);
  const P4 neg2 = _mm256_xor_pd(dot3(t2x, t2y, t2z, rx, ry, rz), signBit);
  P4 l1 = add(lR1, mul(sub(neg1, mul(eT, lR1)), kR));
  P4 l2 = add(lR2, mul(sub(neg2, mul(eT, lR2)), kR));
  projectDisc4(l1, l2, lim);
  const P4 bounded = _mm256_cmp_pd(lim, zero, _CMP_NEQ_UQ);
  l1 = sel(zero, l1, bounded);
  l2 = sel(zero, l2, bounded);
  const P4 c1 = sub(l1, lR1), c2 = sub(l2, lR2);
  const P4 tx = add(mul(c1, t1x), mul(c2, t2x)), ty = add(mul(c1, t1y), mul(c2, t2y)),
           tz = add(mul(c1, t1z), mul(c2, t2z));
  _mm256_store_pd(p.f[G::kLR1], sel(lR1, l1, has));
  _mm256_store_pd(p.f[G::kLR2], sel(lR2, l2, has));
  const P4 iA = s.iIa, iB = s.iIb;
  s.wax = sel(s.wax, add(s.wax, mul(iA, tx)), has);
  s.way = sel(s.way, add(s.way, mul(iA, ty)), has);
  s.waz = sel(s.waz, add(s.waz, mul(iA, tz)), has);
  s.wbx = sel(s.wbx, sub(s.wbx, mul(iB, tx)), has);
  s.wby = sel(s.wby, sub(s.wby, mul(iB, ty)), has);
  s.wbz = sel(s.wbz, sub(s.wbz, mul(iB, tz)), has);
}

/// solveCentred<-1> of kN packets at once (4 kN units whose 8 kN particles are all distinct): each stage runs
/// for every packet before the next stage, so the packets' independent dependency chains (square root and
/// division in each disc projection) overlap in the core. Returns the largest |delta lambda_n|.
template <int kN>
SCREE_AVX2 __attribute__((noinline)) Real solvePacketsAvx2(GranularStage::Packet* p, Vec3* v, Vec3* w,
                                                          const Real* invM, const Real* invI) {
  LaneState s[kN];
  for (int q = 0; q < kN; ++q) stageLoad(p[q], v, w, invM, invI, s[q]);
  for (int q = 0; q < kN; ++q) stageNormal(p[q], s[q]);
  for (int q = 0; q < kN; ++q) stageFriction(p[q], s[q]);
  for (int q = 0; q < kN; ++q) stageRolling(p[q], s[q]);
  for (int q = 0; q < kN; ++q) stageStore(p[q], v, w, s[q]);
  P4 m = s[0].absD;
  for (int q = 1; q < kN; ++q) m = _mm256_max_pd(m, s[q].absD);
  alignas(32) double ad[4];
  _mm256_store_pd(ad, m);
  return std::max(std::max(ad[0], ad[1]), std::max(ad[2], ad[3]));
}

// ---- Eight-wide sweep (issue 16, trench speed, seventh round) --------------------------------------------
// Where the CPU has AVX-512 (this machine's Zen 5 executes 512-bit operations at full width), a run of two
// packets of one level (8 units with 16 distinct particles) is solved in the eight lanes of 512-bit registers:
// lanes 0-3 are the first packet's, 4-7 the second's. The packet layout and the schedule are the four-wide
// sweep's; every lane does the same IEEE operations in the same order as the four-wide kernel (and so as the
// scalar code): the stages below are stageNormal, stageFriction and stageRolling with 512-bit operations and
// mask-register blends of the same predicates. AVX-512 includes FMA, so this file is compiled with
// -ffp-contract=off (solver/CMakeLists.txt): no multiply-add is contracted, in any kernel.
#define SCREE_AVX512 __attribute__((target("avx512f")))
using P8 = __m512d;
using M8 = __mmask8;

// Halves and concatenation by __builtin_shufflevector, and the square root by its all-lanes masked form: GCC 12's
// _mm512_extractf64x4_pd, _mm512_insertf64x4 and _mm512_sqrt_pd raise false -Wuninitialized warnings.
SCREE_AVX512 inline P4 lo4(P8 x) { return __builtin_shufflevector(x, x, 0, 1, 2, 3); }
SCREE_AVX512 inline P4 hi4(P8 x) { return __builtin_shufflevector(x, x, 4, 5, 6, 7); }
SCREE_AVX512 inline P8 join8(P4 lo, P4 hi) { return __builtin_shufflevector(lo, hi, 0, 1, 2, 3, 4, 5, 6, 7); }
SCREE_AVX512 inline P8 add8(P8 a, P8 b) { return _mm512_add_pd(a, b); }
SCREE_AVX512 inline P8 sub8(P8 a, P8 b) { return _mm512_sub_pd(a, b); }
SCREE_AVX512 inline P8 mul8(P8 a, P8 b) { return _mm512_mul_pd(a, b); }
/// m ? b : a
SCREE_AVX512 inline P8 sel8(P8 a, P8 b, M8 m) { return _mm512_mask_blend_pd(m, a, b); }
SCREE_AVX512 inline P8 dot8(P8 ax, P8 ay, P8 az, P8 bx, P8 by, P8 bz) {
  return add8(add8(mul8(ax, bx), mul8(ay, by)), mul8(az, bz));
}
SCREE_AVX512 inline P8 neg8(P8 a) {  // flips the sign bit, as the scalar unary minus
  return _mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(a), _mm512_set1_epi64(int64_t(1) << 63)));
}
SCREE_AVX512 inline void projectDisc8(P8& l1, P8& l2, P8 lim) {
  const P8 zero = _mm512_setzero_pd();
  const P8 mag2 = add8(mul8(l1, l1), mul8(l2, l2));
  const M8 over = _mm512_cmp_pd_mask(mag2, mul8(lim, lim), _CMP_GT_OQ);
  const P8 mag = _mm512_maskz_sqrt_pd(M8(0xFF), mag2);
  const P8 s = sel8(zero, _mm512_div_pd(lim, mag), _mm512_cmp_pd_mask(mag, zero, _CMP_GT_OQ));
  l1 = sel8(l1, mul8(l1, s), over);
  l2 = sel8(l2, mul8(l2, s), over);
}
/// Field k of two packets (lanes 0-3, 4-7), and back.
SCREE_AVX512 inline P8 field8(const GranularStage::Packet* p, int k) {
  return join8(_mm256_load_pd(p[0].f[k]), _mm256_load_pd(p[1].f[k]));
}
SCREE_AVX512 inline void storeField8(GranularStage::Packet* p, int k, P8 x) {
  _mm256_store_pd(p[0].f[k], lo4(x));
  _mm256_store_pd(p[1].f[k], hi4(x));
}
SCREE_AVX512 inline void load3x8(const Vec3* arr, const uint32_t* idx0, const uint32_t* idx1, P8& X, P8& Y, P8& Z) {
  P4 x0, y0, z0, x1, y1, z1;
  load3(arr, idx0, x0, y0, z0);
  load3(arr, idx1, x1, y1, z1);
  X = join8(x0, x1);
  Y = join8(y0, y1);
  Z = join8(z0, z1);
}
SCREE_AVX512 inline void store3x8(Vec3* arr, const uint32_t* idx0, const uint32_t* idx1, P8 X, P8 Y, P8 Z) {
  store3(arr, idx0, lo4(X), lo4(Y), lo4(Z));
  store3(arr, idx1, hi4(X), hi4(Y), hi4(Z));
}

struct LaneState8 {
  P8 vax, vay, vaz, vbx, vby, vbz, wax, way, waz, wbx, wby, wbz;
  P8 ima, imb, iIa, iIb;
  P8 lNpos, absD;
};

SCREE_AVX512 inline void stageLoad8(const GranularStage::Packet* p, const Vec3* v, const Vec3* w, const Real* invM,
                                    const Real* invI, LaneState8& s) {
  s.ima = join8(gather4(invM, p[0].a), gather4(invM, p[1].a));
  s.imb = join8(gather4(invM, p[0].b), gather4(invM, p[1].b));
  s.iIa = join8(gather4(invI, p[0].a), gather4(invI, p[1].a));
  s.iIb = join8(gather4(invI, p[0].b), gather4(invI, p[1].b));
  load3x8(v, p[0].a, p[1].a, s.vax, s.vay, s.vaz);
  load3x8(v, p[0].b, p[1].b, s.vbx, s.vby, s.vbz);
  load3x8(w, p[0].a, p[1].a, s.wax, s.way, s.waz);
  load3x8(w, p[0].b, p[1].b, s.wbx, s.wby, s.wbz);
}

SCREE_AVX512 inline void stageStore8(const GranularStage::Packet* p, Vec3* v, Vec3* w, const LaneState8& s) {
  store3x8(v, p[0].a, p[1].a, s.vax, s.vay, s.vaz);
  store3x8(v, p[0].b, p[1].b, s.vbx, s.vby, s.vbz);
  store3x8(w, p[0].a, p[1].a, s.wax, s.way, s.waz);
  store3x8(w, p[0].b, p[1].b, s.wbx, s.wby, s.wbz);
}

/// stageNormal in eight lanes.
SCREE_AVX512 inline void stageNormal8(GranularStage::Packet* p, LaneState8& s) {
  using G = GranularStage;
  const P8 zero = _mm512_setzero_pd();
  const P8 nx = field8(p, G::kNx), ny = field8(p, G::kNy), nz = field8(p, G::kNz);
  const P8 ima = s.ima, imb = s.imb;
  const P8 lN = field8(p, G::kLN);
  const P8 vn = dot8(nx, ny, nz, sub8(s.vax, s.vbx), sub8(s.vay, s.vby), sub8(s.vaz, s.vbz));
  P8 nl = add8(lN, mul8(sub8(sub8(field8(p, G::kRhsN), vn), mul8(field8(p, G::kEN), lN)), field8(p, G::kKN)));
  const P8 lo = field8(p, G::kLoN);
  nl = sel8(nl, lo, _mm512_cmp_pd_mask(nl, lo, _CMP_LT_OQ));  // std::max(nl, lo)
  const P8 d = sub8(nl, lN);
  storeField8(p, G::kLN, nl);
  const M8 moved = _mm512_cmp_pd_mask(d, zero, _CMP_NEQ_UQ);
  const P8 px = mul8(d, nx), py = mul8(d, ny), pz = mul8(d, nz);
  s.vax = sel8(s.vax, add8(s.vax, mul8(ima, px)), moved);
  s.vay = sel8(s.vay, add8(s.vay, mul8(ima, py)), moved);
  s.vaz = sel8(s.vaz, add8(s.vaz, mul8(ima, pz)), moved);
  s.vbx = sel8(s.vbx, sub8(s.vbx, mul8(imb, px)), moved);
  s.vby = sel8(s.vby, sub8(s.vby, mul8(imb, py)), moved);
  s.vbz = sel8(s.vbz, sub8(s.vbz, mul8(imb, pz)), moved);
  s.lNpos = sel8(nl, zero, _mm512_cmp_pd_mask(nl, zero, _CMP_LT_OQ));  // std::max(lN, 0)
  s.absD = _mm512_abs_pd(d);
}

/// stageFriction in eight lanes.
SCREE_AVX512 inline void stageFriction8(GranularStage::Packet* p, LaneState8& s) {
  using G = GranularStage;
  const P8 zero = _mm512_setzero_pd();
  const P8 t1x = field8(p, G::kT1x), t1y = field8(p, G::kT1y), t1z = field8(p, G::kT1z);
  const P8 t2x = field8(p, G::kT2x), t2y = field8(p, G::kT2y), t2z = field8(p, G::kT2z);
  const P8 eT = field8(p, G::kET);
  const P8 mu = field8(p, G::kMu);
  const P8 lim = mul8(mu, s.lNpos);
  const P8 lT1 = field8(p, G::kLT1), lT2 = field8(p, G::kLT2);
  const P8 la = field8(p, G::kLa), lb = field8(p, G::kLb), sigma = field8(p, G::kSigma);
  const P8 dvx = sub8(s.vax, s.vbx), dvy = sub8(s.vay, s.vby), dvz = sub8(s.vaz, s.vbz);
  const P8 Lx = add8(mul8(la, s.wax), mul8(lb, s.wbx)), Ly = add8(mul8(la, s.way), mul8(lb, s.wby)),
           Lz = add8(mul8(la, s.waz), mul8(lb, s.wbz));
  const P8 vt1 = sub8(dot8(t1x, t1y, t1z, dvx, dvy, dvz), mul8(sigma, dot8(Lx, Ly, Lz, t2x, t2y, t2z)));
  const P8 vt2 = add8(dot8(t2x, t2y, t2z, dvx, dvy, dvz), mul8(sigma, dot8(Lx, Ly, Lz, t1x, t1y, t1z)));
  const P8 kT = field8(p, G::kKT);
  P8 l1 = add8(lT1, mul8(sub8(sub8(zero, vt1), mul8(eT, lT1)), kT));  // rhsT1 = +0 (see packable)
  P8 l2 = add8(lT2, mul8(sub8(sub8(zero, vt2), mul8(eT, lT2)), kT));
  projectDisc8(l1, l2, lim);
  const M8 bounded = _mm512_cmp_pd_mask(lim, zero, _CMP_NEQ_UQ);
  l1 = sel8(zero, l1, bounded);
  l2 = sel8(zero, l2, bounded);
  const M8 has = _mm512_cmp_pd_mask(mu, zero, _CMP_GT_OQ);
  l1 = sel8(lT1, l1, has);
  l2 = sel8(lT2, l2, has);
  const P8 d1 = sub8(l1, lT1), d2 = sub8(l2, lT2);
  storeField8(p, G::kLT1, l1);
  storeField8(p, G::kLT2, l2);
  const M8 moved = M8(_mm512_cmp_pd_mask(d1, zero, _CMP_NEQ_UQ) | _mm512_cmp_pd_mask(d2, zero, _CMP_NEQ_UQ));
  const P8 px = add8(mul8(d1, t1x), mul8(d2, t2x)), py = add8(mul8(d1, t1y), mul8(d2, t2y)),
           pz = add8(mul8(d1, t1z), mul8(d2, t2z));
  const P8 qx = mul8(sigma, sub8(mul8(d1, t2x), mul8(d2, t1x))), qy = mul8(sigma, sub8(mul8(d1, t2y), mul8(d2, t1y))),
           qz = mul8(sigma, sub8(mul8(d1, t2z), mul8(d2, t1z)));  // n x P
  const P8 ima = s.ima, imb = s.imb;
  const P8 iia = mul8(s.iIa, la), iib = mul8(s.iIb, lb);
  s.vax = sel8(s.vax, add8(s.vax, mul8(ima, px)), moved);
  s.vay = sel8(s.vay, add8(s.vay, mul8(ima, py)), moved);
  s.vaz = sel8(s.vaz, add8(s.vaz, mul8(ima, pz)), moved);
  s.wax = sel8(s.wax, sub8(s.wax, mul8(iia, qx)), moved);
  s.way = sel8(s.way, sub8(s.way, mul8(iia, qy)), moved);
  s.waz = sel8(s.waz, sub8(s.waz, mul8(iia, qz)), moved);
  s.vbx = sel8(s.vbx, sub8(s.vbx, mul8(imb, px)), moved);
  s.vby = sel8(s.vby, sub8(s.vby, mul8(imb, py)), moved);
  s.vbz = sel8(s.vbz, sub8(s.vbz, mul8(imb, pz)), moved);
  s.wbx = sel8(s.wbx, sub8(s.wbx, mul8(iib, qx)), moved);
  s.wby = sel8(s.wby, sub8(s.wby, mul8(iib, qy)), moved);
  s.wbz = sel8(s.wbz, sub8(s.wbz, mul8(iib, qz)), moved);
}

/// stageRolling in eight lanes.
SCREE_AVX512 inline void stageRolling8(GranularStage::Packet* p, LaneState8& s) {
  using G = GranularStage;
  const P8 zero = _mm512_setzero_pd();
  const P8 t1x = field8(p, G::kT1x), t1y = field8(p, G::kT1y), t1z = field8(p, G::kT1z);
  const P8 t2x = field8(p, G::kT2x), t2y = field8(p, G::kT2y), t2z = field8(p, G::kT2z);
  const P8 eT = field8(p, G::kET);
  const P8 rollMu = field8(p, G::kRollMu), kR = field8(p, G::kKR);
  const M8 has = M8(_mm512_cmp_pd_mask(rollMu, zero, _CMP_GT_OQ) & _mm512_cmp_pd_mask(kR, zero, _CMP_GT_OQ));
  const P8 lim = mul8(rollMu, s.lNpos);
  const P8 lR1 = field8(p, G::kLR1), lR2 = field8(p, G::kLR2);
  const P8 rx = sub8(s.wax, s.wbx), ry = sub8(s.way, s.wby), rz = sub8(s.waz, s.wbz);
  const P8 n1 = neg8(dot8(t1x, t1y, t1z, rx, ry, rz));
  const P8 n2 = neg8(dot8(t2x, t2y, t2z, rx, ry, rz));
  P8 l1 = add8(lR1, mul8(sub8(n1, mul8(eT, lR1)), kR));
  P8 l2 = add8(lR2, mul8(sub8(n2, mul8(eT, lR2)), kR));
  projectDisc8(l1, l2, lim);
  const M8 bounded = _mm512_cmp_pd_mask(lim, zero, _CMP_NEQ_UQ);
  l1 = sel8(zero, l1, bounded);
  l2 = sel8(zero, l2, bounded);
  const P8 c1 = sub8(l1, lR1), c2 = sub8(l2, lR2);
  const P8 tx = add8(mul8(c1, t1x), mul8(c2, t2x)), ty = add8(mul8(c1, t1y), mul8(c2, t2y)),
           tz = add8(mul8(c1, t1z), mul8(c2, t2z));
  storeField8(p, G::kLR1, sel8(lR1, l1, has));
  storeField8(p, G::kLR2, sel8(lR2, l2, has));
  const P8 iA = s.iIa, iB = s.iIb;
  s.wax = sel8(s.wax, add8(s.wax, mul8(iA, tx)), has);
  s.way = sel8(s.way, add8(s.way, mul8(iA, ty)), has);
  s.waz = sel8(s.waz, add8(s.waz, mul8(iA, tz)), has);
  s.wbx = sel8(s.wbx, sub8(s.wbx, mul8(iB, tx)), has);
  s.wby = sel8(s.wby, sub8(s.wby, mul8(iB, ty)), has);
  s.wbz = sel8(s.wbz, sub8(s.wbz, mul8(iB, tz)), has);
}

/// solvePacketsAvx2<2 kZ> in eight lanes: kZ pairs of packets (2 kZ packets of one level). Returns the largest
/// |delta lambda_n|, folded in the four-wide kernel's order.
template <int kZ>
SCREE_AVX512 __attribute__((noinline)) Real solvePacketsAvx512(GranularStage::Packet* p, Vec3* v, Vec3* w,
                                                              const Real* invM, const Real* invI) {
  LaneState8 s[kZ];
  for (int q = 0; q < kZ; ++q) stageLoad8(p + 2 * q, v, w, invM, invI, s[q]);
  for (int q = 0; q < kZ; ++q) stageNormal8(p + 2 * q, s[q]);
  for (int q = 0; q < kZ; ++q) stageFriction8(p + 2 * q, s[q]);
  for (int q = 0; q < kZ; ++q) stageRolling8(p + 2 * q, s[q]);
  for (int q = 0; q < kZ; ++q) stageStore8(p + 2 * q, v, w, s[q]);
  P4 m = lo4(s[0].absD);
  m = _mm256_max_pd(m, hi4(s[0].absD));
  for (int q = 1; q < kZ; ++q) {
    m = _mm256_max_pd(m, lo4(s[q].absD));
    m = _mm256_max_pd(m, hi4(s[q].absD));
  }
  alignas(32) double ad[4];
  _mm256_store_pd(ad, m);
  return std::max(std::max(ad[0], ad[1]), std::max(ad[2], ad[3]));
}

bool cpuHasAvx512() {
  static const bool has = __builtin_cpu_supports("avx512f");
  return has;
}

bool cpuHasAvx2() {
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
}
#else
bool cpuHasAvx2() { return false; }
template <int kN>
Real solvePacketsAvx2(GranularStage::Packet*, Vec3*, Vec3*, const Real*, const Real*) { return 0; }
bool cpuHasAvx512() { return false; }
template <int kZ>
Real solvePacketsAvx512(GranularStage::Packet*, Vec3*, Vec3*, const Real*, const Real*) { return 0; }
#endif

}  // namespace

GranularStage::PairParams GranularStage::makeParams(const SurfaceParameters& s, const FrictionModel* fm, Real h) {
  PairParams p;
  // Without SuiteSparse every unit stays iterative (Simulation logs the one-time warning for rigid rows).
  if (fm && fm->getSolveType() != FrictionModel::ITERATIVE && DirectSolver::available())
    p.solveType = uint8_t(fm->getSolveType());
  p.youngsModulus = s.getYoungsModulus();
  p.damping = s.getDamping();
  const SpookCoefficients co = contactSpook(h, p.youngsModulus, p.damping);
  p.eN = co.e;
  p.a = co.a;
  p.upsilon = co.upsilon;
  p.eT = spookVelocityRegularisation(h, s.getSurfaceViscosity());
  p.mu = s.getFrictionCoefficient();
  p.rest = s.getRestitution();
  p.rolling = s.getRollingResistanceCoefficient();
  p.adhF = s.getAdhesiveForce();
  p.adhO = s.getAdhesiveOverlap();
  return p;
}

const GranularStage::CacheEntry* GranularStage::find(const std::vector<CacheKey>& keys,
                                                     const std::vector<uint32_t>& first,
                                                     const std::vector<CacheEntry>& entries, uint64_t key,
                                                     uint32_t feature) {
  if (!first.empty()) {
    // The keys whose high half (the lower particle's slot) is key's: a few, in (key, feature, entry) order, so
    // the first match is the one std::lower_bound finds.
    const uint64_t hi = key >> 32;
    if (hi + 1 >= first.size()) return nullptr;
    for (uint32_t k = first[hi]; k < first[hi + 1]; ++k)
      if (keys[k].key == key && keys[k].feature == feature) return &entries[keys[k].entry];
    return nullptr;
  }
  auto it = std::lower_bound(keys.begin(), keys.end(), CacheKey{key, feature, 0});
  if (it != keys.end() && it->key == key && it->feature == feature) return &entries[it->entry];
  return nullptr;
}

void GranularStage::applyForces(GranularBodySystem& ps, const Vec3& gravity, Real h) {
  const size_t n = ps.size();
  auto& v = ps.velocities();
  const auto& invM = ps.invMasses();
  vStart_.resize(n);
#pragma omp parallel for schedule(static) if (n > kParallelMin)
  for (size_t i = 0; i < n; ++i) {
    vStart_[i] = v[i];
    if (invM[i] > 0) v[i] += h * gravity;
  }
}

void GranularStage::buildRows(GranularBodySystem& ps, const ParticleContactLists& contacts,
                              const MaterialManager& materials, const Solver& solver,
                              std::vector<SolverBodyState>& bodies,
                              const std::function<int(const RigidBody*)>& solverIndexOf, const Vec3& gravity,
                              Real h) {
  const size_t n = ps.size();
  const auto& pp = *contacts.particleParticle;
  const auto& pg = *contacts.particleGeometry;
  const auto& sides = *contacts.geometrySides;
  const auto& x = ps.positions();
  const auto& v = vStart_;  // the rows see the start-of-step velocities
  auto& w = ps.angularVelocities();
  const auto& r = ps.radii();
  const auto& invM = ps.invMasses();
  const auto& matIdx = ps.materialIndices();
  const auto& matTable = ps.getMaterialTable();

  scheduleStale_ = true;  // new units: the four-wide sweep's schedule and packets are rebuilt
  packed_ = false;
  invInertia_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const Real m = ps.masses()[i];
    invInertia_[i] = invM[i] > 0 ? 1.0 / (0.4 * m * r[i] * r[i]) : 0.0;
  }

  // ---- material pairs ----------------------------------------------------------------------------------------
  const size_t K = matTable.size();
  auto& ppParams = ppParams_;
  ppParams.resize(K * K);
  for (size_t i = 0; i < K; ++i)
    for (size_t j = 0; j < K; ++j) {
      SurfaceParameters s;
      const FrictionModel* fm = nullptr;
      materials.resolve(matTable[i].get(), matTable[j].get(), s, &fm);
      ppParams[i * K + j] = makeParams(s, fm, h);
    }
  // Particle-geometry: (particle material, geometry material) pairs met this step, plus body indices.
  auto& pgParams = pgParams_;
  auto& pgParam = pgParam_;
  auto& pgBody = pgBody_;
  auto& pgUnit = pgUnit_;
  pgParams.clear();
  pgParam.resize(pg.size());
  pgBody.resize(pg.size());
  pgUnit.resize(pg.size());
  size_t numUnits = pp.size();
  {
    const Geometry* lastGeom = nullptr;
    int lastBody = -1;
    for (size_t k = 0; k < pg.size(); ++k) {
      const ParticleContact& c = pg[k];
      if (c.sensor) continue;
      const Material* gm = sides[k].material;
      const std::pair<uint32_t, const Material*> key{matIdx[c.a], gm};
      size_t e = 0;
      while (e < pgParams.size() && pgParams[e].first != key) ++e;
      if (e == pgParams.size()) {
        SurfaceParameters s;
        const FrictionModel* fm = nullptr;
        materials.resolve(matTable[key.first].get(), gm, s, &fm);
        pgParams.push_back({key, makeParams(s, fm, h)});
      }
      pgParam[k] = uint32_t(e);
      if (c.geometry != lastGeom) {
        lastGeom = c.geometry;
        lastBody = solverIndexOf(sides[k].body);
      }
      pgBody[k] = lastBody;
      pgUnit[k] = uint32_t(numUnits++);
    }
  }

  // A glued pair's speculative partner (see gapBond below): an ordinary frictionless iterative unit.
  auto isGapBond = [&](const ParticleContact& c, const PairParams& p) {
    const Real rollR = r[c.a] * r[size_t(c.b)] / (r[c.a] + r[size_t(c.b)]);
    return std::isinf(p.adhF) && c.depth < -0.2 * rollR;
  };

  // ---- where each unit goes ----------------------------------------------------------------------------------
  // The partition (slab, serial set or DIRECT mode) of every unit is found first from what decides it (its
  // particles, body and solve type), so that each unit is built directly in its place in units_ (a copy of
  // all units, some 8 MB in the trench bench, was 3.5 % of it). Same order as building and then partitioning.
  plan_.resize(numUnits);
  warm_.resize(pp.size() + pg.size());
  // Without any DIRECT-mode material pair (the usual case) no unit is DIRECT: the plan needs only a contact's
  // first bytes (a, b), not the rest of its 168.
  bool anyDirect = false;
  for (const PairParams& q : ppParams) anyDirect |= q.solveType != FrictionModel::ITERATIVE;
  for (const auto& q : pgParams) anyDirect |= q.second.solveType != FrictionModel::ITERATIVE;
  for (size_t k = 0; k < pp.size() + pg.size(); ++k) {
    const bool isPP = k < pp.size();
    // The contacts (168 bytes each) are read here for the first time since the collider wrote them: fetch
    // ahead (the loop does little else; no effect on results).
    if (k + 16 < pp.size()) __builtin_prefetch(&pp[k + 16]);
    const ParticleContact& c = isPP ? pp[k] : pg[k - pp.size()];
    if (!isPP && c.sensor) continue;
    UnitPlan& e = plan_[isPP ? k : pgUnit[k - pp.size()]];
    e.a = c.a;
    e.b = isPP ? c.b : -1;
    e.body = isPP ? -1 : pgBody[k - pp.size()];
    e.direct = false;
    // The warm-start entry is looked up here, where the contact's keys are read anyway, so that the unit loop
    // below can fetch it ahead (the entries, 2 MB in storeResults order, are met in contact order: waiting for
    // them was a quarter of the unit loop; docs/terrain.md, "Digging cost", seventh round).
    if (isPP) {
      const uint64_t sa = slotKey(ps, c.a), sb = slotKey(ps, size_t(c.b));
      warm_[k] = find(ppKeys_, ppFirst_, ppCache_, sa > sb ? (sb << 32 | sa) : (sa << 32 | sb), 0);
    } else {
      warm_[k] = find(pgKeys_, pgFirst_, pgCache_, slotKey(ps, c.a) << 32 | sides[k - pp.size()].geometryId,
                      c.featureId);
    }
    if (!anyDirect) continue;
    const bool deadPair = !ps.isAliveDense(c.a) || (isPP && !ps.isAliveDense(size_t(c.b)));
    if (deadPair || !c.enabled) continue;  // inert: iterative
    const PairParams& p =
        isPP ? ppParams[matIdx[c.a] * K + matIdx[size_t(c.b)]] : pgParams[pgParam[k - pp.size()]].second;
    e.direct = !(isPP && isGapBond(c, p)) && p.solveType != FrictionModel::ITERATIVE;
  }
  partition(ps, contacts.cellSize);

  // ---- units -------------------------------------------------------------------------------------------------
  const bool warm = solver.getUseWarmStarting();  // the impact memory is kept either way

  const ContactLawSettings law{h, solver.getRestitutionThreshold(), solver.getMaxPenetrationRecoverySpeed()};
  auto effMass = [](Real im, Real ii, const Vec3& r, const Vec3& d) { return im + ii * r.cross(d).squaredNorm(); };
  auto bodyEff = [](const SolverBodyState& b, const Vec3& r, const Vec3& d) {
    const Vec3 c = r.cross(d);
    return b.invMass + c.dot(b.invInertia * c);
  };

  // DIRECT lump bonds (see bondRest_ in the header): this step's rest per particle pair, NaN for a non-bond.
  const bool anyBondRest = !bondRest_.empty() || anyGluedMaterial(ppParams, K);
  if (anyBondRest) ppRest_.assign(pp.size(), std::numeric_limits<Real>::quiet_NaN());
  else ppRest_.clear();

#pragma omp parallel for schedule(static) if (numUnits > kParallelMin)
  for (size_t k = 0; k < pp.size() + pg.size(); ++k) {
    const bool isPP = k < pp.size();
    const ParticleContact& c = isPP ? pp[k] : pg[k - pp.size()];
    if (!isPP && c.sensor) continue;
    if (k + 8 < warm_.size() && warm_[k + 8]) {  // the entry of a later contact (no effect on results)
      const char* e = reinterpret_cast<const char*>(warm_[k + 8]);
      __builtin_prefetch(e);
      __builtin_prefetch(e + sizeof(CacheEntry) - 1);
    }
    const uint32_t dest = unitDest_[isPP ? k : pgUnit[k - pp.size()]];
    Unit& u = units_[dest];
    u = Unit{};
    u.a = c.a;
    u.b = isPP ? c.b : -1;
    schedUnit_[dest] = {u.a, u.b, 0};  // packable: set below once the unit is complete
    u.body = isPP ? -1 : pgBody[k - pp.size()];
    u.src = uint32_t(isPP ? k : k - pp.size());
    u.n = c.normal;
    orthonormalBasis(u.n, u.t1, u.t2);
    const uint32_t a = c.a;
    const bool deadPair = !ps.isAliveDense(a) || (isPP && !ps.isAliveDense(size_t(c.b)));
    // Inert unit (all gains zero): a destroyed particle, or a point a listener disabled.
    if (deadPair || !c.enabled) continue;
    u.ra = c.point - x[a];
    const PairParams& p = isPP ? ppParams[matIdx[a] * K + matIdx[size_t(c.b)]] : pgParams[pgParam[k - pp.size()]].second;
    // Relative velocity at the point at the start of the step, and effective masses.
    Vec3 vrel = v[a] + w[a].cross(u.ra);
    Real kn = effMass(invM[a], invInertia_[a], u.ra, u.n);
    Real kt1 = effMass(invM[a], invInertia_[a], u.ra, u.t1);
    Real kt2 = effMass(invM[a], invInertia_[a], u.ra, u.t2);
    Real kr = invInertia_[a];
    Real rollR = r[a];
    if (isPP) {
      const size_t b = size_t(c.b);
      u.rb = c.point - x[b];
      // Centred: both arms along the normal to rounding (a listener may have moved the point off the line of
      // centres; then the general form is kept). The arms are then set exactly along n.
      const Real la = -u.ra.dot(u.n), lb = u.rb.dot(u.n);
      const Real tol2 = 1e-18 * (u.ra.squaredNorm() + u.rb.squaredNorm());
      if ((u.ra + la * u.n).squaredNorm() <= tol2 && (u.rb - lb * u.n).squaredNorm() <= tol2) {
        u.centred = true;
        u.la = la;
        u.lb = lb;
        u.ra = -la * u.n;
        u.rb = lb * u.n;
        u.sigma = u.n.cross(u.t1).dot(u.t2) >= 0 ? 1.0 : -1.0;
        vrel = v[a] - v[b] + u.n.cross(la * w[a] + lb * w[b]);  // w_a x r_a - w_b x r_b with the arms on n
        const Real im = invM[a] + invM[b], rot = invInertia_[a] * la * la + invInertia_[b] * lb * lb;
        kn = im;
        kt1 = im + rot;
        kt2 = im + rot;
      } else {
        vrel -= v[b] + w[b].cross(u.rb);
        kn += effMass(invM[b], invInertia_[b], u.rb, u.n);
        kt1 += effMass(invM[b], invInertia_[b], u.rb, u.t1);
        kt2 += effMass(invM[b], invInertia_[b], u.rb, u.t2);
      }
      kr += invInertia_[b];
      rollR = r[a] * r[b] / (r[a] + r[b]);
    } else {
      const ParticleGeometrySide& side = sides[k - pp.size()];
      const RigidBody* body = side.body;
      if (u.body >= 0) {
        const SolverBodyState& sb = bodies[size_t(u.body)];
        u.rb = c.point - body->getCmPosition();
        vrel -= body->getVelocity() + body->getAngularVelocity().cross(u.rb);
        kn += bodyEff(sb, u.rb, u.n);
        kt1 += bodyEff(sb, u.rb, u.t1);
        kt2 += bodyEff(sb, u.rb, u.t2);
        // Rolling rows act on the relative rotation: add the body's rotational compliance about the tangents
        // (average of the two, the rows are solved as a disc).
        kr += 0.5 * (u.t1.dot(sb.invInertia * u.t1) + u.t2.dot(sb.invInertia * u.t2));
      }
      const Real gr = side.rollingRadius;
      if (gr > 0) rollR = r[a] * gr / (r[a] + gr);
    }
    // Warm start and remembered impact speed.
    const CacheEntry* ce = warm_[k];  // found by the plan loop above
    Real sgn = 1.0;
    if (isPP) {
      u.flip = slotKey(ps, a) > slotKey(ps, size_t(c.b));
      sgn = u.flip ? -1.0 : 1.0;
    }
    uint64_t pairKey = 0;  // only glued bonds need it (bondRest_)
    if (isPP && anyBondRest) {
      const uint64_t sa = slotKey(ps, a), sb = slotKey(ps, size_t(c.b));
      pairKey = u.flip ? (sb << 32 | sa) : (sa << 32 | sb);
    }
    const Real vn0 = u.n.dot(vrel);
    const Real vnFree = vn0 + (isPP ? 0.0 : h * gravity.dot(u.n));
    // Speculative contacts stop an approach exactly at the surface; the approach speed is then remembered so
    // that the next step (touching) bounces with restitution * that speed, as the rigid contacts do.
    NormalContactState cs;
    cs.depth = c.depth;
    cs.vn0 = vn0;
    cs.vnFree = vnFree;
    cs.rememberedImpact = ce ? ce->impact : 0.0;
    cs.adhesiveForce = p.adhF;
    cs.adhesiveOverlap = p.adhO;
    // A glued pair (infinite adhesion: the DIRECT particle mode, docs/terrain.md "External materials and
    // particle solve type") bonds only surfaces that touch. A speculative pair (a gap, e.g. the lattice's second
    // neighbours at 0.24 r) is an ordinary frictionless speculative stop swept with the particles: as an
    // infinite-adhesion equality row it would pull the gap shut to the rest overlap against the lump's bonds, and
    // with this tiny regularisation the conflicting rows threw the lump apart.
    // "A gap" means wider than a tenth of the smaller radius (0.2 x the reduced radius): a glued bond stretched
    // elastically past touching (adhesive overlap 0 under tension, some 1e-7 m) stays a bond.
    const bool gapBond = isPP && isGapBond(c, p);  // as in the plan above
    if (gapBond) cs.adhesiveForce = 0;
    // A glued bond rests at the overlap it had when it formed (bondRest_): on the creation lattice that is the
    // material's r(sqrt2 - 1); a bond formed later, e.g. between particles of two dig steps, is not pushed.
    // A bond formed this step captures the pair inelastically: the row targets zero relative normal velocity
    // (SPOOK's damping term would carry most of the approach speed into the bond, which then swings back over
    // many steps: a particle dug during the lift, at rest, bonding to the rising lump deformed it by 7.5e-5 m).
    if (isPP && std::isinf(p.adhF) && !gapBond && anyBondRest) {
      bool formed = false;
      cs.adhesiveOverlap = bondRestOf(pairKey, c.depth, formed);
      ppRest_[k] = cs.adhesiveOverlap;
      if (!formed) cs.vn0 = 0;
    }
    // Per-point overrides (ContactEventListener::particleContacts), as ContactPoint's for rigid contacts.
    cs.restitution = c.restitution >= 0 ? c.restitution : p.rest;
    const bool ownSpook = c.youngsModulus > 0 || c.damping >= 0;
    const SpookCoefficients spook =
        ownSpook ? contactSpook(h, c.youngsModulus > 0 ? c.youngsModulus : p.youngsModulus,
                                c.damping >= 0 ? c.damping : p.damping)
                 : SpookCoefficients{p.a, p.upsilon, p.eN};
    const NormalRowCoefficients nr = contactNormalRow(law, spook, cs);
    u.rhsN = nr.rhs;
    u.eN = nr.e;
    u.loN = nr.lo;
    u.impact = nr.impactSpeed;
    u.solveType = gapBond ? uint8_t(FrictionModel::ITERATIVE) : p.solveType;
    u.kN = 1.0 / (kn + u.eN);
    u.mu = gapBond ? 0.0 : c.frictionCoefficient >= 0 ? c.frictionCoefficient : p.mu;
    if (!c.surfaceVelocity.isZero(0)) {
      u.rhsT1 = c.surfaceVelocity.dot(u.t1);
      u.rhsT2 = c.surfaceVelocity.dot(u.t2);
    }
    u.eT = p.eT;
    u.kT1 = 1.0 / (kt1 + u.eT);
    u.kT2 = 1.0 / (kt2 + u.eT);
    // A glued bond (infinite adhesion, touching) does not roll either: its rolling rows are unbounded like its
    // friction (with the material's finite rolling resistance every tensile bond - lambda_n < 0, a zero-width
    // box - was an active-set pivot of the direct solve, some 1e4 per step).
    u.rollMu = gapBond ? 0.0 : std::isinf(p.adhF) && p.rolling > 0 ? std::numeric_limits<Real>::infinity()
                                                                    : p.rolling * rollR;
    u.kR = kr > 0 ? 1.0 / (kr + u.eT) : 0.0;
    if (ce && warm) {
      u.lN = std::max(ce->normal, u.loN);
      u.lT1 = sgn * ce->friction.dot(u.t1);
      u.lT2 = sgn * ce->friction.dot(u.t2);
      u.lR1 = sgn * ce->rolling.dot(u.t1);
      u.lR2 = sgn * ce->rolling.dot(u.t2);
    }
    schedUnit_[dest].packable = packable(u);
  }
}

void GranularStage::partition(const GranularBodySystem& ps, Real cellSize) {
  // Slabs along the axis of largest extent of the particle cloud, each at least one grid cell wide (the
  // largest particle-pair reach), so a contact's two particles lie in the same or adjacent slabs. A unit
  // belongs to the lower slab of its particles: units of two even (or two odd) slabs never share a particle.
  // The partition depends on the particle positions only, never on the number of threads.
  const size_t nu = plan_.size();
  const auto& x = ps.positions();
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (size_t i = 0; i < ps.size(); ++i) {
    if (!ps.isAliveDense(i)) continue;
    lo = lo.cwiseMin(x[i]);
    hi = hi.cwiseMax(x[i]);
  }
  int axis = 0;
  const Vec3 ext = (hi - lo).cwiseMax(Vec3::Zero());
  if (ext.y() > ext[axis]) axis = 1;
  if (ext.z() > ext[axis]) axis = 2;
  const Real cell = cellSize;
  int numSlabs = cell > 0 ? int(std::min<Real>(kMaxSlabs, std::floor(ext[axis] / cell))) : 1;
  if (numSlabs < 4 || nu < kParallelMin) numSlabs = 1;  // too narrow or too small to be worth splitting
  const Real width = numSlabs > 1 ? ext[axis] / Real(numSlabs) : 1.0;
  auto slabOfParticle = [&](size_t i) {
    if (numSlabs == 1) return 0;
    return std::clamp(int(std::floor((x[i][axis] - lo[axis]) / width)), 0, numSlabs - 1);
  };
  slabOf_.resize(nu);
  auto& count = slabCount_;
  count.assign(size_t(numSlabs) + 2, 0);
  for (size_t k = 0; k < nu; ++k) {
    const UnitPlan& u = plan_[k];
    int sl;
    if (u.direct) sl = numSlabs + 1;  // DIRECT mode: solved with the rigid rows
    else if (u.body >= 0) sl = numSlabs;  // touches a dynamic rigid body: serial
    else if (u.b >= 0) sl = std::min(slabOfParticle(u.a), slabOfParticle(size_t(u.b)));
    else sl = slabOfParticle(u.a);
    slabOf_[k] = uint16_t(sl);
    ++count[size_t(sl)];
  }
  slabStart_.assign(size_t(numSlabs) + 3, 0);
  for (int sl = 0; sl <= numSlabs + 1; ++sl) slabStart_[size_t(sl) + 1] = slabStart_[size_t(sl)] + count[size_t(sl)];
  auto& cursor = slabCursor_;
  cursor.assign(slabStart_.begin(), slabStart_.end() - 1);
  units_.resize(nu);
  schedUnit_.assign(nu, SchedUnit{});
  unitDest_.resize(nu);
  for (size_t k = 0; k < nu; ++k) unitDest_[k] = cursor[slabOf_[k]]++;
  numSlabs_ = numSlabs;
}

void GranularStage::prepare(GranularBodySystem& ps, std::vector<SolverBodyState>& bodies) {
  auto& v = ps.velocities();
  auto& w = ps.angularVelocities();
  const auto& invM = ps.invMasses();
  // Serial in unit order: warm-start impulses of different units may touch the same particle.
  for (const Unit& u : units_) {
    const Vec3 P = u.lN * u.n + u.lT1 * u.t1 + u.lT2 * u.t2;
    const Vec3 T = u.lR1 * u.t1 + u.lR2 * u.t2;
    if (P.isZero(0) && T.isZero(0)) continue;
    v[u.a] += invM[u.a] * P;
    w[u.a] += invInertia_[u.a] * (u.ra.cross(P) + T);
    if (u.b >= 0) {
      v[size_t(u.b)] -= invM[size_t(u.b)] * P;
      w[size_t(u.b)] -= invInertia_[size_t(u.b)] * (u.rb.cross(P) + T);
    } else if (u.body >= 0 && bodies[size_t(u.body)].invMass > 0) {
      SolverBodyState& b = bodies[size_t(u.body)];
      b.v -= b.invMass * P;
      b.w -= b.invInertia * (u.rb.cross(P) + T);
    }
  }
}

template <int kFrozen>
void GranularStage::solveUnit(Unit& u, std::vector<Vec3>& v, std::vector<Vec3>& w, const std::vector<Real>& invM,
                              const std::vector<Real>& invI, std::vector<SolverBodyState>& bodies,
                              Real& maxDelta) const {
  static_assert(kFrozen >= -1 && kFrozen <= 1);
  const uint32_t a = u.a;
  const int32_t b = u.b;
  SolverBodyState* body = (b < 0 && u.body >= 0) ? &bodies[size_t(u.body)] : nullptr;
  // A frozen side never moves; in the shock pass side B is a particle or a static/kinematic support.
  const bool moveA = kFrozen != 0;
  const bool bodyDyn = kFrozen < 0 && body && body->invMass > 0;
  auto relVel = [&]() SCREE_UNIT_INLINE -> Vec3 {
    Vec3 vr = v[a] + w[a].cross(u.ra);
    if (b >= 0) vr -= v[size_t(b)] + w[size_t(b)].cross(u.rb);
    else if (body) vr -= body->v + body->w.cross(u.rb);
    return vr;
  };
  // 1 / (J M^-1 J^T + e) along d: precomputed for both sides moving, else that of the free particle alone.
  auto gain = [&](Real both, const Vec3& d, Real e) SCREE_UNIT_INLINE {
    if constexpr (kFrozen < 0) {
      return both;
    } else {
      const size_t p = moveA ? a : size_t(b);
      const Vec3& rp = moveA ? u.ra : u.rb;
      return 1.0 / (invM[p] + invI[p] * rp.cross(d).squaredNorm() + e);
    }
  };
  // Impulse P on side A (and -P on side B).
  auto applyP = [&](const Vec3& P) SCREE_UNIT_INLINE {
    if (moveA) {
      v[a] += invM[a] * P;
      w[a] += invI[a] * u.ra.cross(P);
    }
    if (kFrozen == 1) return;
    if (b >= 0) {
      v[size_t(b)] -= invM[size_t(b)] * P;
      w[size_t(b)] -= invI[size_t(b)] * u.rb.cross(P);
    } else if (bodyDyn) {
      body->v -= body->invMass * P;
      body->w -= body->invInertia * u.rb.cross(P);
    }
  };

  // Normal.
  {
    const Real vn = u.n.dot(relVel());
    const Real nl = std::max(u.lN + (u.rhsN - vn - u.eN * u.lN) * gain(u.kN, u.n, u.eN), u.loN);
    const Real d = nl - u.lN;
    u.lN = nl;
    if (d != 0) applyP(d * u.n);
    if constexpr (kFrozen < 0) maxDelta = std::max(maxDelta, std::abs(d));
  }
  // Friction: scalar updates of both tangents at the same velocity, then projection onto the disc.
  if (u.mu > 0) {
    const Real lim = frictionLimit(u.mu, u.lN);
    Real l1 = 0, l2 = 0;  // a zero bound projects any update to zero (as solveCentred)
    if (lim != 0) {
      const Vec3 vr = relVel();
      l1 = u.lT1 + (u.rhsT1 - u.t1.dot(vr) - u.eT * u.lT1) * gain(u.kT1, u.t1, u.eT);
      l2 = u.lT2 + (u.rhsT2 - u.t2.dot(vr) - u.eT * u.lT2) * gain(u.kT2, u.t2, u.eT);
      projectOntoDisc(l1, l2, lim);
    }
    const Real d1 = l1 - u.lT1, d2 = l2 - u.lT2;
    u.lT1 = l1;
    u.lT2 = l2;
    if (d1 != 0 || d2 != 0) applyP(d1 * u.t1 + d2 * u.t2);
  }
  // Rolling resistance: torque about the tangents opposing the relative rolling, disc bound.
  if constexpr (kFrozen < 0) {
    if (u.rollMu > 0 && u.kR > 0) {
      Vec3 wr = w[a];
      if (b >= 0) wr -= w[size_t(b)];
      else if (body) wr -= body->w;
      const Vec3 T = rollingImpulse(u, wr);
      w[a] += invI[a] * T;
      if (b >= 0) w[size_t(b)] -= invI[size_t(b)] * T;
      else if (bodyDyn) body->w -= body->invInertia * T;
    }
  }
}

template <int kFrozen>
void GranularStage::solveCentred(Unit& u, Vec3* v, Vec3* w, const Real* invM, const Real* invI,
                                 Real& maxDelta) const {
  // The arms lie on n (ra = -la n, rb = lb n): the relative normal velocity is n . (va - vb), a normal impulse
  // turns nothing, and with n x t1 = sigma t2, n x t2 = -sigma t1 the relative velocity along t is
  // t . (va - vb) - (la wa + lb wb) . (n x t), and an impulse d t turns a by -la d invIa (n x t) and b by
  // -lb d invIb (n x t). Same law and order of updates as solveUnit<kFrozen>; a frozen side (the shock pass)
  // is read but not moved, and the gains are then those of the free particle alone.
  static_assert(kFrozen >= -1 && kFrozen <= 1);
  const uint32_t a = u.a, b = uint32_t(u.b);
  const Real ima = kFrozen == 0 ? 0.0 : invM[a], imb = kFrozen == 1 ? 0.0 : invM[b];
  const Real iia = kFrozen == 0 ? 0.0 : invI[a] * u.la, iib = kFrozen == 1 ? 0.0 : invI[b] * u.lb;
  Real kN = u.kN, kT1 = u.kT1, kT2 = u.kT2;
  if constexpr (kFrozen >= 0) {
    const Real im = ima + imb;  // one of them is zero
    const Real rot = kFrozen == 0 ? iib * u.lb : iia * u.la;
    kN = 1.0 / (im + u.eN);
    kT1 = kT2 = 1.0 / (im + rot + u.eT);
  }
  // Normal.
  {
    const Real vn = u.n.dot(v[a] - v[b]);
    const Real nl = std::max(u.lN + (u.rhsN - vn - u.eN * u.lN) * kN, u.loN);
    const Real d = nl - u.lN;
    u.lN = nl;
    if (d != 0) {
      const Vec3 P = d * u.n;
      if (kFrozen != 0) v[a] += ima * P;
      if (kFrozen != 1) v[b] -= imb * P;
    }
    if constexpr (kFrozen < 0) maxDelta = std::max(maxDelta, std::abs(d));
  }
  // Friction: scalar updates of both tangents at the same velocity, then projection onto the disc.
  if (u.mu > 0) {
    // A zero bound (no normal impulse: a separated or speculative contact, some of the units) projects any
    // update to zero: skip the update and the projection's square root and division.
    const Real lim = frictionLimit(u.mu, u.lN);
    Real l1 = 0, l2 = 0;
    if (lim != 0) {
      const Vec3 dv = v[a] - v[b];
      const Vec3 L = u.la * w[a] + u.lb * w[b];
      const Real vt1 = u.t1.dot(dv) - u.sigma * L.dot(u.t2);
      const Real vt2 = u.t2.dot(dv) + u.sigma * L.dot(u.t1);
      l1 = u.lT1 + (u.rhsT1 - vt1 - u.eT * u.lT1) * kT1;
      l2 = u.lT2 + (u.rhsT2 - vt2 - u.eT * u.lT2) * kT2;
      projectOntoDisc(l1, l2, lim);
    }
    const Real d1 = l1 - u.lT1, d2 = l2 - u.lT2;
    u.lT1 = l1;
    u.lT2 = l2;
    if (d1 != 0 || d2 != 0) {
      const Vec3 P = d1 * u.t1 + d2 * u.t2;
      const Vec3 nxP = u.sigma * (d1 * u.t2 - d2 * u.t1);  // n x P
      if (kFrozen != 0) {
        v[a] += ima * P;
        w[a] -= iia * nxP;
      }
      if (kFrozen != 1) {
        v[b] -= imb * P;
        w[b] -= iib * nxP;
      }
    }
  }
  // Rolling resistance, as solveUnit (left to the sweeps in the shock pass).
  if constexpr (kFrozen < 0) {
    if (u.rollMu > 0 && u.kR > 0) {
      const Vec3 wr = w[a] - w[b];
      const Vec3 T = rollingImpulse(u, wr);
      w[a] += invI[a] * T;
      w[b] -= invI[b] * T;
    }
  }
}

Real GranularStage::sweep(GranularBodySystem& ps, std::vector<SolverBodyState>& bodies, bool backward) {
  auto& v = ps.velocities();
  auto& w = ps.angularVelocities();
  const auto& invM = ps.invMasses();
  Real maxDelta = 0;
  auto one = [&](Unit& u, Real& md) SCREE_UNIT_INLINE {
    if (u.centred) solveCentred<-1>(u, v.data(), w.data(), invM.data(), invInertia_.data(), md);
    else solveUnit<-1>(u, v, w, invM, invInertia_, bodies, md);
  };
  auto runRange = [&](uint32_t b0, uint32_t b1) {
    Real md = 0;
    if (!backward)
      for (uint32_t k = b0; k < b1; ++k) one(units_[k], md);
    else
      for (uint32_t k = b1; k-- > b0;) one(units_[k], md);
    return md;
  };
  const int S = numSlabs_;
  // Four-wide sweep (see "Four-wide sweep" above): each slab's units in level order, centred ones in packets.
  const bool vec = gVectorSweepEnabled && cpuHasAvx2() && !units_.empty();
  const bool wide = vec && gWideSweepEnabled && cpuHasAvx512();
  if (vec) {
    if (scheduleStale_) {
      buildSchedule(ps);
      scheduleStale_ = false;
      packed_ = false;
    }
    if (!packed_) pack(ps);
  } else {
    unpack();
    numPackets_ = 0;
    scheduleStale_ = true;
  }
  auto runSlab = [&](int sl) {
    if (!vec) return runRange(slabStart_[size_t(sl)], slabStart_[size_t(sl) + 1]);
    Real md = 0;
    uint64_t wideUnits = 0;
    const Real* im = invM.data();
    const Real* ii = invInertia_.data();
    const uint32_t i0 = itemStart_[size_t(sl)], i1 = itemStart_[size_t(sl) + 1];
    auto item = [&](int32_t it) SCREE_UNIT_INLINE {
      if (it >= 0) one(units_[size_t(it)], md);
      else {
        const uint32_t code = uint32_t(-1 - it);
        Packet* p = &packets_[code >> 2];
        if (wide) {  // eight-wide: pairs of packets in 512-bit lanes, a last odd packet four-wide
          wideUnits += (code & 3) >= 1 ? ((code & 3) == 3 ? 16 : 8) : 0;
          switch (code & 3) {
            case 0: md = std::max(md, solvePacketsAvx2<1>(p, v.data(), w.data(), im, ii)); break;
            case 1: md = std::max(md, solvePacketsAvx512<1>(p, v.data(), w.data(), im, ii)); break;
            case 2:
              md = std::max(md, solvePacketsAvx512<1>(p, v.data(), w.data(), im, ii));
              md = std::max(md, solvePacketsAvx2<1>(p + 2, v.data(), w.data(), im, ii));
              break;
            default: md = std::max(md, solvePacketsAvx512<2>(p, v.data(), w.data(), im, ii)); break;
          }
          return;
        }
        switch (code & 3) {
          case 0: md = std::max(md, solvePacketsAvx2<1>(p, v.data(), w.data(), im, ii)); break;
          case 1: md = std::max(md, solvePacketsAvx2<2>(p, v.data(), w.data(), im, ii)); break;
          case 2: md = std::max(md, solvePacketsAvx2<3>(p, v.data(), w.data(), im, ii)); break;
          default: md = std::max(md, solvePacketsAvx2<4>(p, v.data(), w.data(), im, ii)); break;
        }
      }
    };
    // The packets stream from memory (about 290 bytes a unit): the packets (or the unit) of the item kAheadItems ahead
    // are fetched while this one is solved (no effect on results).
    constexpr uint32_t kAheadItems = 3;
    auto fetch = [&](int32_t it) SCREE_UNIT_INLINE {
      if (it >= 0) {  // a single unit, visited in level order (scattered over units_)
        const char* c = reinterpret_cast<const char*>(&units_[size_t(it)]);
        for (size_t off = 0; off < sizeof(Unit); off += 64) __builtin_prefetch(c + off);
        __builtin_prefetch(c + sizeof(Unit) - 1);
        return;
      }
      const uint32_t code = uint32_t(-1 - it);
      const char* c = reinterpret_cast<const char*>(&packets_[code >> 2]);
      const size_t bytes = ((code & 3) + 1) * sizeof(Packet);
      for (size_t off = 0; off < bytes; off += 64) __builtin_prefetch(c + off);
    };
    if (!backward)
      for (uint32_t i = i0; i < i1; ++i) {
        if (i + kAheadItems < i1) fetch(items_[i + kAheadItems]);
        item(items_[i]);
      }
    else
      for (uint32_t i = i1; i-- > i0;) {
        if (i >= i0 + kAheadItems) fetch(items_[i - kAheadItems]);
        item(items_[i]);
      }
    if (wideUnits) gWideUnits += wideUnits;
    return md;
  };
  const uint32_t serialBegin = slabStart_[size_t(S)], serialEnd = slabStart_[size_t(S) + 1];
  if (backward) maxDelta = std::max(maxDelta, runRange(serialBegin, serialEnd));
  if (S == 1) {
    maxDelta = std::max(maxDelta, runSlab(0));
  } else {
    // Two phases (even slabs, then odd; reversed when sweeping backward), each slab a serial Gauss-Seidel run:
    // slabs of one phase share no particle, so which thread runs which slab does not change any bit.
#pragma omp parallel
    for (int ph = 0; ph < 2; ++ph) {
      const int parity = backward ? 1 - ph : ph;
#pragma omp for schedule(dynamic, 1) reduction(max : maxDelta)
      for (int j = 0; j < (S - parity + 1) / 2; ++j) {
        const int sl = backward ? S - 1 - ((S - 1 - parity) % 2) - 2 * j : parity + 2 * j;
        maxDelta = std::max(maxDelta, runSlab(sl));
      }
    }
  }
  if (!backward) maxDelta = std::max(maxDelta, runRange(serialBegin, serialEnd));
  return maxDelta;
}

bool GranularStage::vectorSweepAvailable() { return gVectorSweepEnabled && cpuHasAvx2(); }

void GranularStage::setVectorSweepEnabled(bool on) { gVectorSweepEnabled = on; }

uint64_t GranularStage::packedUnitsTotal() { return gPackedUnits.load(); }

bool GranularStage::avx512SweepAvailable() { return vectorSweepAvailable() && gWideSweepEnabled && cpuHasAvx512(); }

void GranularStage::setAvx512SweepEnabled(bool on) { gWideSweepEnabled = on; }

uint64_t GranularStage::wideUnitsTotal() { return gWideUnits.load(); }

bool GranularStage::packable(const Unit& u) {
  // +0 friction targets (no surface velocity) and equal tangent gains: the packet's reduced fields.
  const bool plainT = std::bit_cast<uint64_t>(u.rhsT1) == 0 && std::bit_cast<uint64_t>(u.rhsT2) == 0;
  return u.centred && u.b >= 0 && u.kN != 0 && std::isfinite(u.mu) && std::isfinite(u.rollMu) && plainT &&
         u.kT1 == u.kT2;
}

void GranularStage::buildSchedule(const GranularBodySystem& ps) {
  // Per slab: each unit's dependency level, the units in (level, unit) order (a counting sort), and per level
  // the packable units in packets of four (see "Four-wide sweep"). Depends on the units only, never on the
  // number of threads.
  const size_t n = ps.size();
  const int S = numSlabs_;
  numPackets_ = 0;
  items_.clear();
  itemStart_.assign(size_t(S) + 1, 0);
  if (lastLevel_.size() < n) {
    lastLevel_.resize(n);
    stampOf_.assign(n, 0);
    stamp_ = 0;
  }
  uint32_t group[4];
  int grouped = 0;
  for (int sl = 0; sl < S; ++sl) {
    itemStart_[size_t(sl)] = uint32_t(items_.size());
    const uint32_t b0 = slabStart_[size_t(sl)], b1 = slabStart_[size_t(sl) + 1];
    if (++stamp_ == 0) {  // wrapped: forget all stamps
      std::fill(stampOf_.begin(), stampOf_.end(), 0);
      stamp_ = 1;
    }
    levelOf_.resize(b1 - b0);
    packable_.resize(b1 - b0);
    uint32_t top = 0;
    auto levelAt = [&](size_t i) { return stampOf_[i] == stamp_ ? lastLevel_[i] : 0u; };
    for (uint32_t k = b0; k < b1; ++k) {
      const SchedUnit& u = schedUnit_[k];  // 12 bytes a unit, written by buildRows (not the 312 of units_)
      uint32_t L = levelAt(u.a);
      if (u.b >= 0) L = std::max(L, levelAt(size_t(u.b)));
      ++L;
      packable_[k - b0] = char(u.packable);
      levelOf_[k - b0] = L;
      top = std::max(top, L);
      lastLevel_[u.a] = L;
      stampOf_[u.a] = stamp_;
      if (u.b >= 0) {
        lastLevel_[size_t(u.b)] = L;
        stampOf_[size_t(u.b)] = stamp_;
      }
    }
    levelCount_.assign(size_t(top) + 2, 0);
    for (uint32_t k = 0; k < b1 - b0; ++k) ++levelCount_[levelOf_[k] + 1];
    for (uint32_t L = 0; L <= top; ++L) levelCount_[L + 1] += levelCount_[L];
    levelOrder_.resize(b1 - b0);
    for (uint32_t k = 0; k < b1 - b0; ++k) levelOrder_[levelCount_[levelOf_[k]]++] = b0 + k;
    // levelCount_[L] is now the end of level L in levelOrder_.
    size_t pos = 0;
    for (uint32_t L = 1; L <= top; ++L) {
      const size_t end = levelCount_[L];
      grouped = 0;
      const size_t firstPacket = numPackets_;
      const size_t firstSingle = items_.size();
      for (; pos < end; ++pos) {
        const uint32_t k = levelOrder_[pos];
        if (!packable_[k - b0]) {
          items_.push_back(int32_t(k));
          continue;
        }
        group[grouped++] = k;
        if (grouped == 4) {
          // packets_ only grows (value-initialising 1 KB a packet every step cost 1-2 % of the trench bench).
          if (numPackets_ == packets_.size()) packets_.resize(std::max<size_t>(64, 2 * packets_.size()));
          Packet& p = packets_[numPackets_++];
          for (int j = 0; j < 4; ++j) p.unit[j] = group[j];
          grouped = 0;
        }
      }
      for (int j = 0; j < grouped; ++j) items_.push_back(int32_t(group[j]));
      // The level's packets go before its single units, in runs of up to kPacketRun solved by one kernel call.
      const size_t numSingles = items_.size() - firstSingle;
      for (size_t q = firstPacket; q < numPackets_; q += kPacketRun) {
        const size_t c = std::min<size_t>(kPacketRun, numPackets_ - q);
        items_.push_back(-1 - int32_t(q * 4 + (c - 1)));
      }
      std::rotate(items_.begin() + long(firstSingle), items_.begin() + long(firstSingle + numSingles), items_.end());
    }
  }
  itemStart_[size_t(S)] = uint32_t(items_.size());
  gPackedUnits += 4 * numPackets_;
}

void GranularStage::pack(const GranularBodySystem&) {
  // The units are read in level order, scattered over units_: the next packet's are fetched ahead.
  constexpr size_t kAhead = 2;
  for (size_t q = 0; q < numPackets_; ++q) {
    Packet& p = packets_[q];
    if (q + kAhead < numPackets_)
      for (int j = 0; j < 4; ++j) {
        const char* c = reinterpret_cast<const char*>(&units_[packets_[q + kAhead].unit[j]]);
        for (size_t off = 0; off < sizeof(Unit); off += 64) __builtin_prefetch(c + off);
        __builtin_prefetch(c + sizeof(Unit) - 1);
      }
    for (int j = 0; j < 4; ++j) {
      const Unit& u = units_[p.unit[j]];
      const uint32_t a = u.a, b = uint32_t(u.b);
      p.a[j] = a;
      p.b[j] = b;
      auto& f = p.f;
      f[kNx][j] = u.n.x();
      f[kNy][j] = u.n.y();
      f[kNz][j] = u.n.z();
      f[kT1x][j] = u.t1.x();
      f[kT1y][j] = u.t1.y();
      f[kT1z][j] = u.t1.z();
      f[kT2x][j] = u.t2.x();
      f[kT2y][j] = u.t2.y();
      f[kT2z][j] = u.t2.z();
      f[kSigma][j] = u.sigma;
      f[kLa][j] = u.la;
      f[kLb][j] = u.lb;
      f[kKN][j] = u.kN;
      f[kKT][j] = u.kT1;
      f[kRhsN][j] = u.rhsN;
      f[kEN][j] = u.eN;
      f[kLoN][j] = u.loN;
      f[kET][j] = u.eT;
      f[kMu][j] = u.mu;
      f[kRollMu][j] = u.rollMu;
      f[kKR][j] = u.kR;
      f[kLN][j] = u.lN;
      f[kLT1][j] = u.lT1;
      f[kLT2][j] = u.lT2;
      f[kLR1][j] = u.lR1;
      f[kLR2][j] = u.lR2;
    }
  }
  packed_ = true;
}

void GranularStage::unpack() {
  if (!packed_) return;
  for (size_t q = 0; q < numPackets_; ++q)
    for (int j = 0; j < 4; ++j) {
      const Packet& p = packets_[q];
      Unit& u = units_[p.unit[j]];
      u.lN = p.f[kLN][j];
      u.lT1 = p.f[kLT1][j];
      u.lT2 = p.f[kLT2][j];
      u.lR1 = p.f[kLR1][j];
      u.lR2 = p.f[kLR2][j];
    }
  packed_ = false;
}

void GranularStage::shockPass(GranularBodySystem& ps, std::vector<SolverBodyState>& bodies, const Vec3& up,
                              int sweeps) {
  unpack();  // the units' impulses, as the four-wide sweep left them
  if (units_.empty() || sweeps <= 0) return;
  const auto& x = ps.positions();
  const auto& r = ps.radii();
  shockOrder_.clear();
  for (uint32_t k = 0; k < iterativeEnd(); ++k) {
    const Unit& u = units_[k];
    if (u.kN == 0) continue;  // inert (destroyed particle)
    if (u.b < 0) {
      // Geometry side: only static or kinematic geometry acts as a support here (side B is never moved).
      if (u.body >= 0 && bodies[size_t(u.body)].invMass > 0) continue;
      shockOrder_.push_back({heightKey(x[u.a].dot(up) - 2 * r[u.a]), k * 2 + 1});
      continue;
    }
    if (std::abs(u.n.dot(up)) <= 0.3) continue;
    const Real ha = x[u.a].dot(up), hb = x[size_t(u.b)].dot(up);
    // Freeze the lower particle.
    shockOrder_.push_back(ha < hb ? std::make_pair(heightKey(ha), k * 2 + 0) : std::make_pair(heightKey(hb), k * 2 + 1));
  }
  sortByHeight(shockOrder_, shockScratch_);
  auto& v = ps.velocities();
  auto& w = ps.angularVelocities();
  Real unused = 0;
  // The units are visited in height order, i.e. scattered over units_ (8 MB in the trench bench, beyond the
  // L2 cache): the unit a few visits ahead is prefetched (no effect on results).
  constexpr size_t kAhead = 8;
  const size_t nOrder = shockOrder_.size();
  for (int s = 0; s < sweeps; ++s)
    for (size_t i = 0; i < nOrder; ++i) {
      if (i + kAhead < nOrder) {
        const char* p = reinterpret_cast<const char*>(&units_[shockOrder_[i + kAhead].second >> 1]);
        for (size_t off = 0; off < sizeof(Unit); off += 64) __builtin_prefetch(p + off, 1);
        __builtin_prefetch(p + sizeof(Unit) - 1, 1);
      }
      const uint32_t code = shockOrder_[i].second;
      Unit& u = units_[code >> 1];
      if (u.centred) {
        if (code & 1) solveCentred<1>(u, v.data(), w.data(), ps.invMasses().data(), invInertia_.data(), unused);
        else solveCentred<0>(u, v.data(), w.data(), ps.invMasses().data(), invInertia_.data(), unused);
      } else if (code & 1) solveUnit<1>(u, v, w, ps.invMasses(), invInertia_, bodies, unused);
      else solveUnit<0>(u, v, w, ps.invMasses(), invInertia_, bodies, unused);
    }
}

void GranularStage::appendDirectRows(const GranularBodySystem& ps, std::vector<ConstraintRow>& rows,
                                     std::vector<SolverBodyState>& bodies) {
  const auto& v = ps.velocities();
  const auto& w = ps.angularVelocities();
  const auto& invM = ps.invMasses();
  const uint32_t begin = iterativeEnd(), end = uint32_t(units_.size());
  rowBase_ = rows.size();
  bodyBase_ = bodies.size();
  extBody_.assign(ps.size(), -1);
  extParticle_.clear();
  directRow_.clear();
  glued_ = false;
  auto bodyOf = [&](size_t i) {
    if (extBody_[i] < 0) {
      extBody_[i] = int32_t(bodies.size());
      extParticle_.push_back(uint32_t(i));
      SolverBodyState b;
      b.v = v[i];
      b.w = w[i];
      b.invMass = invM[i];
      b.invInertia = invInertia_[i] * Mat3::Identity();
      bodies.push_back(b);
    }
    return extBody_[i];
  };
  for (uint32_t k = begin; k < end; ++k) {
    const Unit& u = units_[k];
    const int32_t ia = bodyOf(u.a);
    const int32_t ib = u.b >= 0 ? bodyOf(size_t(u.b)) : u.body;
    const auto type = FrictionModel::SolveType(u.solveType);
    glued_ |= type == FrictionModel::DIRECT;
    const int32_t normal = int32_t(rows.size());
    directRow_.push_back(uint32_t(normal));
    // Same rows as solveUnit: impulse P along +d on a, -d on b (or the body); J v = relative velocity along d.
    auto linear = [&](const Vec3& d) {
      ConstraintRow r = pointRow(ia, ib, u.ra, u.rb, d);
      r.solveType = type;
      return r;
    };
    ConstraintRow rn = linear(u.n);
    rn.rhs = u.rhsN;
    rn.e = u.eN;
    rn.lo = u.loN;  // -1e300 with infinite adhesion: an equality row
    rn.hi = 1e300;
    rows.push_back(rn);
    if (u.mu > 0) {
      for (int j = 0; j < 2; ++j) {
        ConstraintRow f = linear(j == 0 ? u.t1 : u.t2);
        f.rhs = j == 0 ? u.rhsT1 : u.rhsT2;
        f.e = u.eT;
        f.mu = u.mu;  // infinite: unbounded
        f.normalRow = normal;
        f.friction = true;
        if (j == 0) f.pairedRow = int32_t(rows.size()) + 1;
        rows.push_back(f);
      }
    }
    if (u.rollMu > 0 && u.kR > 0) {
      for (int j = 0; j < 2; ++j) {
        ConstraintRow f;
        f.bodyA = ia;
        f.bodyB = ib;
        f.jAngA = j == 0 ? u.t1 : u.t2;
        f.jAngB = -f.jAngA;
        f.e = u.eT;
        f.mu = u.rollMu;
        f.normalRow = normal;
        f.friction = true;
        f.solveType = type;
        if (j == 0) f.pairedRow = int32_t(rows.size()) + 1;
        rows.push_back(f);
      }
    }
  }
}

void GranularStage::loadDirectImpulses(std::vector<ConstraintRow>& rows) const {
  const uint32_t begin = iterativeEnd();
  for (size_t j = 0; j < directRow_.size(); ++j) {
    const Unit& u = units_[begin + j];
    size_t r = directRow_[j];
    rows[r++].lambda = u.lN;
    if (u.mu > 0) {
      rows[r++].lambda = u.lT1;
      rows[r++].lambda = u.lT2;
    }
    if (u.rollMu > 0 && u.kR > 0) {
      rows[r++].lambda = u.lR1;
      rows[r++].lambda = u.lR2;
    }
  }
}

void GranularStage::finishDirect(GranularBodySystem& ps, std::vector<ConstraintRow>& rows,
                                 std::vector<SolverBodyState>& bodies) {
  const uint32_t begin = iterativeEnd();
  for (size_t j = 0; j < directRow_.size(); ++j) {
    Unit& u = units_[begin + j];
    size_t r = directRow_[j];
    u.lN = rows[r++].lambda;
    if (u.mu > 0) {
      u.lT1 = rows[r++].lambda;
      u.lT2 = rows[r++].lambda;
    }
    if (u.rollMu > 0 && u.kR > 0) {
      u.lR1 = rows[r++].lambda;
      u.lR2 = rows[r++].lambda;
    }
  }
  auto& v = ps.velocities();
  auto& w = ps.angularVelocities();
  for (size_t k = 0; k < extParticle_.size(); ++k) {
    v[extParticle_[k]] = bodies[bodyBase_ + k].v;
    w[extParticle_[k]] = bodies[bodyBase_ + k].w;
  }
  rows.resize(rowBase_);
  bodies.resize(bodyBase_);
}

bool GranularStage::anyGluedMaterial(const std::vector<PairParams>& ppParams, size_t K) {
  for (size_t e = 0; e < K * K && e < ppParams.size(); ++e)
    if (std::isinf(ppParams[e].adhF)) return true;
  return false;
}

Real GranularStage::bondRestOf(uint64_t key, Real depth, bool& found) const {
  const auto first = std::make_pair(key, -std::numeric_limits<Real>::infinity());
  auto it = std::lower_bound(bondRest_.begin(), bondRest_.end(), first);
  found = it != bondRest_.end() && it->first == key;
  return found ? it->second : depth;
}

void GranularStage::directToParticles(GranularBodySystem& ps, const std::vector<SolverBodyState>& bodies) const {
  auto& v = ps.velocities();
  auto& w = ps.angularVelocities();
  for (size_t k = 0; k < extParticle_.size(); ++k) {
    v[extParticle_[k]] = bodies[bodyBase_ + k].v;
    w[extParticle_[k]] = bodies[bodyBase_ + k].w;
  }
}

void GranularStage::particlesToDirect(const GranularBodySystem& ps, std::vector<SolverBodyState>& bodies) const {
  const auto& v = ps.velocities();
  const auto& w = ps.angularVelocities();
  for (size_t k = 0; k < extParticle_.size(); ++k) {
    bodies[bodyBase_ + k].v = v[extParticle_[k]];
    bodies[bodyBase_ + k].w = w[extParticle_[k]];
  }
}

// ---- DIRECT lump: rigid integration of a bonded lump's positions (issue 16, second pass; header) ------------
void GranularStage::integrateBondedLumps(GranularBodySystem& ps, const std::vector<ParticleContact>& pp, Real h) {
  lumpMoved_.clear();
  if (ppRest_.size() != pp.size()) return;
  const size_t n = ps.size();
  // Union-find over this step's glued bonds.
  std::vector<uint32_t> parent;
  auto find = [&](uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  bool any = false;
  for (size_t k = 0; k < pp.size(); ++k) {
    const ParticleContact& c = pp[k];
    if (std::isnan(ppRest_[k]) || c.b < 0 || !c.enabled || c.a >= n || size_t(c.b) >= n) continue;
    if (!any) {
      parent.resize(n);
      for (size_t i = 0; i < n; ++i) parent[i] = uint32_t(i);
      any = true;
    }
    const uint32_t ra = find(c.a), rb = find(uint32_t(c.b));
    if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
  }
  if (!any) return;
  auto& x = ps.positions();
  auto& v = ps.velocities();
  const auto& invM = ps.invMasses();
  // Members of each cluster of >= 3 live dynamic particles (roots are the smallest index of their cluster).
  std::vector<uint32_t> count(n, 0);
  for (size_t i = 0; i < n; ++i)
    if (invM[i] > 0 && ps.isAliveDense(i)) ++count[find(uint32_t(i))];
  std::vector<std::vector<uint32_t>> members;
  std::vector<int> slot(n, -1);
  for (size_t i = 0; i < n; ++i) {
    if (invM[i] <= 0 || !ps.isAliveDense(i)) continue;
    const uint32_t r = find(uint32_t(i));
    if (count[r] < 3) continue;
    if (slot[r] < 0) {
      slot[r] = int(members.size());
      members.emplace_back();
      members.back().reserve(count[r]);
    }
    members[size_t(slot[r])].push_back(uint32_t(i));
  }
  lumpMoved_.assign(n, 0);
  for (const auto& mem : members) {
    Real M = 0;
    Vec3 xc = Vec3::Zero(), vc = Vec3::Zero();
    for (uint32_t i : mem) {
      const Real m = 1.0 / invM[i];
      M += m;
      xc += m * x[i];
      vc += m * v[i];
    }
    xc /= M;
    vc /= M;
    Mat3 I = Mat3::Zero();
    Vec3 L = Vec3::Zero();
    for (uint32_t i : mem) {
      const Real m = 1.0 / invM[i];
      const Vec3 r = x[i] - xc;
      I += m * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
      L += m * r.cross(v[i] - vc);
    }
    const Eigen::LDLT<Mat3> ldlt(I);
    // A straight chain has a singular inertia (no angular velocity about its axis is defined): x += h v.
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 1e-12 * I.trace())) continue;
    const Vec3 w = ldlt.solve(L);
    if (!w.allFinite() || !xc.allFinite() || !vc.allFinite()) continue;  // integrate reports it
    const Real angle = h * w.norm();
    const Mat3 R = angle > 0 ? Mat3(Eigen::AngleAxis<Real>(angle, w.normalized())) : Mat3::Identity();
    const Vec3 xcNext = xc + h * vc;
    for (uint32_t i : mem) {
      const Vec3 r = x[i] - xc;
      const Vec3 dv = v[i] - vc - w.cross(r);  // non-rigid velocity
      const Vec3 rn = R * r;
      x[i] = xcNext + rn + h * dv;
      v[i] = vc + w.cross(rn) + R * dv;
      lumpMoved_[i] = 1;
    }
  }
}

void GranularStage::integrate(GranularBodySystem& ps, Real h, std::vector<size_t>& outNonFinite,
                              std::vector<std::string>& outMessages, Real time) {
  const size_t n = ps.size();
  auto& x = ps.positions();
  auto& v = ps.velocities();
  auto& w = ps.angularVelocities();
  const auto& invM = ps.invMasses();
  bool bad = false;
  const bool skipLumps = lumpMoved_.size() == n;
#pragma omp parallel for schedule(static) if (n > kParallelMin) reduction(|| : bad)
  for (size_t i = 0; i < n; ++i) {
    if (invM[i] <= 0 || (skipLumps && lumpMoved_[i])) continue;
    const Vec3 xn = x[i] + h * v[i];
    if (xn.allFinite() && w[i].allFinite()) x[i] = xn;
    else bad = true;
  }
  if (!bad) return;
  for (size_t i = 0; i < n; ++i) {
    if (invM[i] <= 0) continue;
    if (v[i].allFinite() && w[i].allFinite() && (x[i] + h * v[i]).allFinite()) continue;
    v[i].setZero();
    w[i].setZero();
    if (!ps.isAliveDense(i)) continue;
    const size_t id = ps.idOfDense(i);
    std::ostringstream msg;
    msg << "Particle id " << id << " has a non-finite state after the step at t = " << time
        << " s; kept its last position and stopped it";
    outNonFinite.push_back(id);
    outMessages.push_back(msg.str());
  }
}

void GranularStage::storeResults(const GranularBodySystem& ps, const ParticleContactLists& contacts, Real h) {
  auto& pp = *contacts.particleParticle;
  auto& pg = *contacts.particleGeometry;
  const auto& sides = *contacts.geometrySides;
  unpack();
  const Real invH = 1.0 / h;
  ppCache_.clear();
  pgCache_.clear();
  bondRest_.clear();
  for (size_t k = 0; k < ppRest_.size(); ++k)
    if (!std::isnan(ppRest_[k])) {
      // The pair's key as buildRows made it (lower slot first).
      const ParticleContact& c = pp[k];
      if (!ps.isAliveDense(c.a) || !ps.isAliveDense(size_t(c.b))) continue;
      const uint64_t sa = slotKey(ps, c.a), sb = slotKey(ps, size_t(c.b));
      bondRest_.push_back({sa > sb ? (sb << 32 | sa) : (sa << 32 | sb), ppRest_[k]});
    }
  std::sort(bondRest_.begin(), bondRest_.end());
  for (const Unit& u : units_) {
    if (!ps.isAliveDense(u.a) || (u.b >= 0 && !ps.isAliveDense(size_t(u.b)))) continue;
    const Vec3 F = u.lT1 * u.t1 + u.lT2 * u.t2;
    const Vec3 T = u.lR1 * u.t1 + u.lR2 * u.t2;
    ParticleContact& c = u.b >= 0 ? pp[u.src] : pg[u.src];
    c.normalForce = u.lN * invH;
    c.frictionForce = F * invH;
    const uint64_t sa = slotKey(ps, u.a);
    if (u.b >= 0) {
      const uint64_t sb = slotKey(ps, size_t(u.b));
      const Real s = u.flip ? -1.0 : 1.0;
      ppCache_.push_back({u.flip ? (sb << 32 | sa) : (sa << 32 | sb), 0, u.lN, s * F, s * T, u.impact});
    } else {
      pgCache_.push_back({sa << 32 | sides[u.src].geometryId, c.featureId, u.lN, F, T, u.impact});
    }
  }
  auto index = [this](const std::vector<CacheEntry>& entries, std::vector<CacheKey>& keys,
                       std::vector<uint32_t>& first) {
    indexKeys(entries, keys);
    // first[s]: the first key whose high half is s (a slot), so find scans only that slot's few keys instead of
    // a binary search over all (whose branches are unpredictable). Only while the slots are dense enough.
    first.clear();
    if (keys.empty()) return;
    const uint64_t top = keys.back().key >> 32;
    if (top > 4 * keys.size() + 65536) return;  // sparse slots: binary search
    first.assign(size_t(top) + 2, 0);
    for (const CacheKey& k : keys) ++first[size_t(k.key >> 32) + 1];
    for (size_t s = 0; s + 1 < first.size(); ++s) first[s + 1] += first[s];
  };
  index(ppCache_, ppKeys_, ppFirst_);
  index(pgCache_, pgKeys_, pgFirst_);
}

void GranularStage::indexKeys(const std::vector<CacheEntry>& entries, std::vector<CacheKey>& keys) {
  keys.resize(entries.size());
  for (size_t e = 0; e < entries.size(); ++e) keys[e] = {entries[e].key, entries[e].feature, uint32_t(e)};
  // In (key, feature, entry) order, as std::sort with CacheKey::operator< (the entries are pushed in
  // increasing entry order, and the stable radix sort by feature, then key, keeps that order among equals):
  // a third of std::sort's time here, whose comparisons were mispredicted.
  if (keys.size() < 64) {
    std::sort(keys.begin(), keys.end());
    return;
  }
  radixSortBy(keys, keyScratch_, 32, [](const CacheKey& k) { return uint64_t(k.feature); });
  radixSortBy(keys, keyScratch_, 64, [](const CacheKey& k) { return k.key; });
}

}  // namespace scree::detail
