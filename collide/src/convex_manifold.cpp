// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Contact manifolds for every convex pair from one penetration normal (narrowphase_internal.h,
// "support-feature manifolds"; docs/design.md "Contact manifolds for every convex pair").
//
// Why: libccd (and any single-point query) returns the deepest point only. A body resting on a flat feature of
// another (a can on a shelf, a hull on a cylinder's cap, a wheel on a ramp) then gets one point per step that jumps
// from rim point to rim point, and it rocks, tilts and creeps. Boxes stand because box-box clips faces; this file
// does the same for every pair once the normal is known.
//
// Method (the normal n points from shape 1 towards shape 0, so shape 0's surface facing shape 1 is along -n):
//  1. Each shape's supporting feature along its outward direction (-n for shape 0, +n for shape 1), decided with
//     one angle tolerance kFeatureAngle (~2.6 deg, as cylinder-plane and cylinder-box use):
//       sphere: its point; box: a face (within the tolerance of a face normal), else an edge (direction within the
//       tolerance of perpendicular to an edge), else a vertex; capsule: its segment shifted by r along the
//       direction when the axis is perpendicular within the tolerance, else an end point; cylinder: its cap as a
//       regular polygon when the axis is parallel, its side line (segment) when perpendicular, else its support
//       point; convex hull: its best-aligned face within the tolerance, else an edge at its support vertex
//       perpendicular to the direction within the tolerance (a hull resting on an edge), else that vertex.
//     The cap polygon's point count follows a tolerance: N is the smallest multiple of 4 whose chord sagitta
//     r (1 - cos(pi / N)) is at most kCapSagitta r (1 %), clamped to [8, 32]; its vertices lie on the rim at
//     fixed angles in the cylinder frame, so they are material points (stable ids, exact rim positions).
//  2. A point on either side: no manifold (the caller keeps its single point, which is exact for curved
//     contact). Otherwise the reference feature is a polygon: the one whose normal is best aligned with n (ties
//     within 1e-3 go to the larger area, then to shape 1, so the choice does not flip at rest). The contact
//     normal is snapped to the reference face's normal and the incident feature is taken again along it, so a
//     face contact has the face's exact normal (no MPR/EPA noise). The incident polygon or segment is clipped by
//     the reference polygon's side planes (Sutherland-Hodgman, clipToReference); each clipped point's depth is its
//     distance below the reference plane; points more than `margin` above it are dropped. Two segments (parallel
//     capsules or cylinders lying side by side) clip shape 0's segment by the end planes of shape 1's; crossed
//     segments keep the single point.
//     A cylinder cap on either side is clipped as its true circle, not the polygon: in the cap's plane (the other
//     feature carried there along the reference normal) the region is bounded by the other feature's vertices
//     inside the circle, its edges' crossings with the circle, and the cap's rim points inside the other
//     feature (they stand for the arcs). That is exact at the rim and costs O(n) instead of O(n^2) clip tests for
//     a cap on a cap. A cap on a cap gives a band of kCapBand r about the reference circle to the reference cap,
//     so coaxial caps (every aligned stack of equal cylinders) get the reference's rim points only, never a
//     roundoff-chosen copy of a doubled point (the reason is at that branch).
//  3. Reduction: at most 4 points, the deepest, then the farthest from it, then the two spanning the largest
//     signed area on either side of that segment (reduceManifold), so the kept quadrilateral spans the contact
//     area and the centre of pressure can sit anywhere in it.
//
// Feature ids: (hash of reference side, feature id of shape 0, feature id of shape 1) in bits 14..30, the clip
// label of the point in bits 0..13 (ClipVertex labels: incident edge k = k, reference side plane k = 64 + k; for a
// segment, its end e = e; against a circle, a polygon vertex is the pair of its edges, an edge crossing the pair
// (edge, 64 entering / 65 leaving), a rim point j the pair (64 + j, 127)). Shape feature ids: box face f = f
// (makeBoxPolytope's order), edge 8 + 8 axis + the sign bits of the other two axes; cylinder cap 0 (-y) / 1 (+y),
// side 2; capsule segment 1; hull face index, hull edge 0x80000000 | hash(lower, higher vertex index) >> 1. All
// are fixed in the shape's frame, so the same touching features give the same ids step after step (warm
// starting, contact_rows.h; its position fallback covers roundoff).
//
// The analytic paths stay where they are exact and faster: box-box, box-plane, capsule-capsule, capsule-box,
// cylinder-plane, convex-convex/-box (SAT), and the cylinder cap lying on a box face (cylinder_box.cpp). Cost per
// pair type: bench/bench_narrowphase.cpp, table in docs/design.md.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "narrowphase_internal.h"

namespace scree::detail {

namespace {

constexpr Real kFeatureAngle = 0.045;  // rad: sin and 1 - cos tolerances below
constexpr Real kCapSagitta = 0.01;     // cap polygon: chord sagitta / r
constexpr int kMaxFeaturePoints = 64;
constexpr Real kCapBand = 1e-4;        // cap on cap: width of the boundary band that belongs to D, / r

/// A supporting feature in world coordinates: 1 point, 2 (segment) or >= 3 (polygon counter-clockwise about
/// `normal`, its outward face normal).
struct Feature {
  int count = 0;
  Vec3 normal = Vec3::Zero();
  uint32_t id = 0;
  Real area = 0;
  bool disc = false;  ///< a cylinder cap: as reference it clips by its true circle (centre, radius)
  Vec3 centre = Vec3::Zero();
  Real radius = 0;
  std::array<Vec3, kMaxFeaturePoints> p;
};

inline uint32_t labelPair(uint32_t a, uint32_t b) { return a < b ? (a << 7) | b : (b << 7) | a; }

Real polygonArea(const Feature& f) {
  Vec3 s = Vec3::Zero();
  for (int k = 0; k < f.count; ++k) s += f.p[size_t(k)].cross(f.p[size_t((k + 1) % f.count)]);
  return Real(0.5) * std::abs(s.dot(f.normal));
}

/// Cap polygon: the number of points for the sagitta tolerance (a multiple of 4 in [8, 32]) and the unit circle
/// at those angles, computed once.
struct CapCircle {
  int n = 0;
  std::array<Real, kMaxFeaturePoints> s{}, c{};
  Real areaFactor = 0;  // polygon area / r^2
  CapCircle() {
    const Real pi = Real(3.14159265358979323846);
    const Real half = std::acos(1 - kCapSagitta);  // pi / N at the tolerance
    n = int(std::ceil(pi / half));
    n = std::clamp((n + 3) / 4 * 4, 8, 32);
    for (int k = 0; k < n; ++k) {
      s[size_t(k)] = std::sin(2 * pi * k / n);
      c[size_t(k)] = std::cos(2 * pi * k / n);
    }
    areaFactor = Real(0.5) * n * std::sin(2 * pi / n);
  }
};
const CapCircle& capCircle() {
  static const CapCircle circle;
  return circle;
}

/// Supporting feature of shape s (placed by t) along the unit world direction d (outward from s).
void supportFeature(const Shape& s, const Transform& t, const Vec3& d, Feature& f) {
  const Real sinTol = std::sin(kFeatureAngle), cosTol = std::cos(kFeatureAngle);
  f.count = 0;
  f.area = 0;
  f.disc = false;
  f.normal = d;
  switch (s.getType()) {
    case Shape::BOX: {
      const Vec3& h = static_cast<const Box&>(s).getHalfExtents();
      const Vec3 dl = t.rotateInverse(d);
      int ax = 0;
      for (int i = 1; i < 3; ++i)
        if (std::abs(dl[i]) > std::abs(dl[ax])) ax = i;
      if (std::abs(dl[ax]) >= cosTol) {
        // Face: counter-clockwise about its outward normal.
        const Real sg = dl[ax] > 0 ? 1 : -1;
        const int u = (ax + 1) % 3, v = (ax + 2) % 3;
        const Real cu[4] = {-1, 1, 1, -1}, cv[4] = {-1, -1, 1, 1};
        for (int k = 0; k < 4; ++k) {
          Vec3 q;
          q[ax] = sg * h[ax];
          // (u, v, ax) is right-handed: going (-,-),(+,-),(+,+),(-,+) in (u, v) is counter-clockwise about +ax.
          q[u] = cu[k] * h[u] * sg;
          q[v] = cv[k] * h[v];
          f.p[size_t(k)] = t.apply(q);
        }
        f.count = 4;
        f.normal = t.rotate(Vec3::Unit(ax) * sg);
        f.id = uint32_t(2 * ax + (sg > 0 ? 0 : 1));
        f.area = 4 * h[u] * h[v];
        return;
      }
      int e = 0;
      for (int i = 1; i < 3; ++i)
        if (std::abs(dl[i]) < std::abs(dl[e])) e = i;
      Vec3 q;
      uint32_t bits = 0;
      for (int i = 0; i < 3; ++i) {
        q[i] = dl[i] >= 0 ? h[i] : -h[i];
        bits |= (dl[i] >= 0 ? 1u : 0u) << i;
      }
      if (std::abs(dl[e]) <= sinTol) {
        Vec3 q0 = q, q1 = q;
        q0[e] = -h[e];
        q1[e] = h[e];
        f.p[0] = t.apply(q0);
        f.p[1] = t.apply(q1);
        f.count = 2;
        f.id = 8 + 8 * uint32_t(e) + (bits & ~(1u << e));
        return;
      }
      f.p[0] = t.apply(q);
      f.count = 1;
      f.id = 64 + bits;
      return;
    }
    case Shape::CYLINDER: {
      const auto& c = static_cast<const Cylinder&>(s);
      const Real r = c.getRadius(), hh = Real(0.5) * c.getHeight();
      const Vec3 dl = t.rotateInverse(d);
      if (std::abs(dl.y()) >= cosTol) {
        const Real sg = dl.y() > 0 ? 1 : -1;
        const CapCircle& cc = capCircle();
        const Mat3 R = t.q.toRotationMatrix();
        const Vec3 centre = t.p + R.col(1) * (sg * hh), ex = R.col(0) * (sg * r), ez = R.col(2) * r;
        // Counter-clockwise about +y runs from +z towards +x: angle a at (sin a, ., cos a); about -y x flips.
        for (int k = 0; k < cc.n; ++k) f.p[size_t(k)] = centre + ex * cc.s[size_t(k)] + ez * cc.c[size_t(k)];
        f.count = cc.n;
        f.normal = R.col(1) * sg;
        f.id = sg > 0 ? 1 : 0;
        f.area = cc.areaFactor * r * r;
        f.disc = true;
        f.centre = centre;
        f.radius = r;
        return;
      }
      const Vec3 radial(dl.x(), 0, dl.z());
      const Real rl = radial.norm();
      if (std::abs(dl.y()) <= sinTol && rl > 0) {
        const Vec3 u = radial / rl * r;
        f.p[0] = t.apply(Vec3(u.x(), -hh, u.z()));
        f.p[1] = t.apply(Vec3(u.x(), hh, u.z()));
        f.count = 2;
        f.id = 2;
        return;
      }
      f.p[0] = t.apply(s.support(dl));
      f.count = 1;
      f.id = 3;
      return;
    }
    case Shape::CAPSULE: {
      const auto& c = static_cast<const Capsule&>(s);
      const Real r = c.getRadius(), hh = Real(0.5) * c.getHeight();
      const Vec3 w = t.rotate(Vec3::UnitY());
      const Real wd = w.dot(d);
      if (std::abs(wd) <= sinTol) {
        f.p[0] = t.p - hh * w + r * d;
        f.p[1] = t.p + hh * w + r * d;
        f.count = 2;
        f.id = 1;
        return;
      }
      f.p[0] = t.p + (wd > 0 ? hh : -hh) * w + r * d;
      f.count = 1;
      f.id = wd > 0 ? 3 : 2;
      return;
    }
    case Shape::CONVEX: {
      const auto& c = static_cast<const Convex&>(s);
      const Vec3 dl = t.rotateInverse(d);
      const auto& faces = c.getFaces();
      int best = -1;
      Real bestDot = cosTol;
      for (size_t k = 0; k < faces.size(); ++k) {
        const Real x = faces[k].normal.dot(dl);
        if (x >= bestDot) {
          bestDot = x;
          best = int(k);
        }
      }
      if (best >= 0 && faces[size_t(best)].vertices.size() <= size_t(kMaxFeaturePoints)) {
        const auto& F = faces[size_t(best)];
        for (size_t k = 0; k < F.vertices.size(); ++k) f.p[k] = t.apply(c.getVertices()[F.vertices[k]]);
        f.count = int(F.vertices.size());
        f.normal = t.rotate(F.normal);
        f.id = uint32_t(best);
        f.area = polygonArea(f);
        return;
      }
      // No face: an edge when one leaving the support vertex is perpendicular to d within the tolerance (a hull
      // resting on an edge gets the edge's two ends, as a box does), else the vertex. The edge's ends are stored
      // lower vertex index first and its id hashes the two indices (high bit set: never a face index), so both
      // are fixed in the hull's frame whichever end is the support vertex.
      const auto& V = c.getVertices();
      uint32_t iv = 0;
      Real top = -std::numeric_limits<Real>::max();
      for (size_t k = 0; k < V.size(); ++k) {
        const Real x = V[k].dot(dl);
        if (x > top) {
          top = x;
          iv = uint32_t(k);
        }
      }
      uint32_t iw = iv;
      Real bestSin = sinTol;
      for (const auto& F : faces) {
        const size_t m = F.vertices.size();
        for (size_t k = 0; k < m; ++k) {
          if (F.vertices[k] != iv) continue;
          for (const uint32_t w : {F.vertices[(k + 1) % m], F.vertices[(k + m - 1) % m]}) {
            const Vec3 e = V[w] - V[iv];
            const Real len = e.norm();
            if (len <= 0) continue;
            const Real sn = std::abs(e.dot(dl)) / len;
            if (sn <= bestSin) {
              bestSin = sn;
              iw = w;
            }
          }
        }
      }
      if (iw != iv) {
        const uint32_t lo = std::min(iv, iw), hi = std::max(iv, iw);
        f.p[0] = t.apply(V[lo]);
        f.p[1] = t.apply(V[hi]);
        f.count = 2;
        f.id = 0x80000000u | (hashFeatureIds(lo, hi) >> 1);
        return;
      }
      f.p[0] = t.apply(V[iv]);
      f.count = 1;
      f.id = 0xFFFFu;
      return;
    }
    default:  // sphere (and anything else with a support point)
      f.p[0] = t.apply(s.support(t.rotateInverse(d)));
      f.count = 1;
      f.id = 0;
      return;
  }
}

/// Keeps the part of segment a-b with sn . x <= so. Returns false when nothing remains; a cut end takes `label`.
bool clipSegmentByPlane(Vec3& a, Vec3& b, uint8_t& la, uint8_t& lb, const Vec3& sn, Real so, uint8_t label) {
  const Real da = sn.dot(a) - so, db = sn.dot(b) - so;
  if (da > 0 && db > 0) return false;
  if (da > 0) {
    a = a + (da / (da - db)) * (b - a);
    la = label;
  } else if (db > 0) {
    b = b + (db / (db - da)) * (a - b);
    lb = label;
  }
  return true;
}

/// Clips segment a-b by the side planes of reference polygon `ref` (counter-clockwise about nRef). Returns false
/// when nothing remains; labels: the original end (0, 1) or 64 + side plane.
bool clipSegment(Vec3& a, Vec3& b, uint8_t& la, uint8_t& lb, const Vec3* ref, int n, const Vec3& nRef) {
  for (int k = 0; k < n; ++k) {
    const Vec3& r0 = ref[k];
    const Vec3 sn = (ref[(k + 1) % n] - r0).cross(nRef);
    if (!clipSegmentByPlane(a, b, la, lb, sn, sn.dot(r0), uint8_t(64 + (k & 63)))) return false;
  }
  return true;
}

}  // namespace

int manifoldFromNormal(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, const Vec3& n,
                       Real margin, std::vector<ContactPoint>& out) {
  thread_local Feature fa, fb;
  supportFeature(s0, t0, -n, fa);
  if (fa.count < 2) return 0;
  supportFeature(s1, t1, n, fb);
  if (fb.count < 2) return 0;
  const size_t begin = out.size();

  if (fa.count == 2 && fb.count == 2) {
    // Two segments: parallel within the tolerance, else one crossing point (the caller's).
    const Vec3 ua = (fa.p[1] - fa.p[0]).normalized(), ub = (fb.p[1] - fb.p[0]).normalized();
    if (ua.cross(ub).norm() > std::sin(kFeatureAngle)) return 0;
    Vec3 a = fa.p[0], b = fa.p[1];
    uint8_t la = 0, lb = 1;
    // End planes of segment B: x . ub >= p0 . ub and x . ub <= p1 . ub.
    const Real lo = ub.dot(fb.p[0]), hi = ub.dot(fb.p[1]);
    if (!clipSegmentByPlane(a, b, la, lb, -ub, -lo, 64) || !clipSegmentByPlane(a, b, la, lb, ub, hi, 65)) return 0;
    const uint32_t base = hashFeatureIds(hashFeatureIds(2, fa.id), fb.id) & 0x7FFFC000u;
    const Vec3 pts[2] = {a, b};
    const uint8_t labels[2] = {la, lb};
    for (int k = 0; k < 2; ++k) {
      const Vec3& p = pts[k];
      const Vec3 q = fb.p[0] + ub * ub.dot(p - fb.p[0]);  // B's point beside p
      const Real sep = n.dot(p - q);
      const Vec3 x = Real(0.5) * (p + q);
      if (sep > margin || nearExisting(out, begin, x)) continue;
      out.push_back(makeContact(x, n, -sep, base | (uint32_t(k) << 7) | labels[k]));
    }
    return int(out.size() - begin);
  }

  // Reference polygon: best aligned with n; ties to the larger face, then to shape 1.
  bool refIsB;
  if (fa.count < 3) {
    refIsB = true;
  } else if (fb.count < 3) {
    refIsB = false;
  } else {
    const Real aa = -fa.normal.dot(n), ab = fb.normal.dot(n);
    if (std::abs(aa - ab) <= Real(1e-3))
      refIsB = fb.area * Real(1.05) >= fa.area;
    else
      refIsB = ab > aa;
  }
  const Feature& R = refIsB ? fb : fa;
  Feature& I = refIsB ? fa : fb;
  const Vec3 nRef = R.normal;  // outward from the reference shape towards the incident one
  // A segment or point depends on the direction: take it again along the exact face normal. (A polygon does
  // not; its choice only flips at the tolerance's edge.)
  if (I.count < 3) {
    if (refIsB)
      supportFeature(s0, t0, -nRef, I);
    else
      supportFeature(s1, t1, -nRef, I);
    if (I.count < 2) return 0;
  }
  const Real refOffset = nRef.dot(R.p[0]);
  const Vec3 normal = refIsB ? nRef : Vec3(-nRef);
  const uint32_t base = hashFeatureIds(hashFeatureIds(uint32_t(refIsB), fa.id), fb.id) & 0x7FFFC000u;
  // Clipping emits a point twice only where an incident vertex lies exactly on a side plane, and then the two
  // copies are neighbours in the clipped polygon: comparing with the last point kept (and the first, for the
  // wrap-around) removes them at O(1) per point.
  auto same = [](const Vec3& a, const Vec3& b) {
    return (a - b).cwiseAbs().maxCoeff() <= Real(1e-9) * (1 + a.cwiseAbs().maxCoeff());
  };
  auto emit = [&](const Vec3& p, uint32_t label) {
    const Real sep = nRef.dot(p) - refOffset;
    const Vec3 x = p - nRef * (Real(0.5) * sep);
    if (sep > margin) return;
    if (out.size() > begin && (same(out.back().point, x) || same(out[begin].point, x))) return;
    out.push_back(makeContact(x, normal, -sep, base | label));
  };
  if (R.disc || (I.disc && I.count >= 3)) {
    // A cylinder cap on either side: intersect the other feature with its true circle, working in the cap's
    // plane (points of the other feature are carried there along nRef, which keeps lines straight and the
    // circle exact). The region is bounded by the other feature's vertices inside the circle, the crossings of
    // its edges with the circle, and arcs, for which the cap's rim points (on the circle) inside the other
    // feature stand. Each point is then reported on the incident surface.
    const Feature& D = R.disc ? R : I;
    const Feature& P = R.disc ? I : R;
    const bool discIsRef = R.disc;
    const Vec3 nD = D.normal, c = D.centre;
    const Real r2 = D.radius * D.radius;
    const Real denD = nD.dot(nRef);
    const Vec3 pBase = P.disc ? P.centre : P.p[0];
    const Real denP = P.normal.dot(nRef);
    if (std::abs(denD) < Real(0.5) || std::abs(denP) < Real(0.5)) return 0;
    auto toD = [&](const Vec3& x) { return Vec3(x + nRef * (nD.dot(c - x) / denD)); };
    auto toP = [&](const Vec3& x) { return Vec3(x + nRef * (P.normal.dot(pBase - x) / denP)); };
    // A point of P (given on P) and of D (given on D), reported on the incident one.
    auto emitFromP = [&](const Vec3& x, uint32_t label) { emit(discIsRef ? x : toD(x), label); };
    auto emitFromD = [&](const Vec3& y, uint32_t label) { emit(discIsRef ? toP(y) : y, label); };
    // Parameters where segment a-b (in D's plane) enters and leaves the circle; false when it misses.
    auto crossings = [&](const Vec3& a, const Vec3& b, Real& tIn, Real& tOut) {
      const Vec3 m = a - c, d = b - a;
      const Real dd = d.squaredNorm();
      if (dd <= Real(1e-24)) return false;
      const Real bq = m.dot(d), disc = bq * bq - dd * (m.squaredNorm() - r2);
      if (disc <= 0) return false;
      const Real sq = std::sqrt(disc);
      tIn = (-bq - sq) / dd;
      tOut = (-bq + sq) / dd;
      return true;
    };
    if (P.count == 2) {
      Real tIn, tOut;
      const Vec3 a = toD(P.p[0]), b = toD(P.p[1]);
      if (!crossings(a, b, tIn, tOut) || tIn >= 1 || tOut <= 0) return 0;
      const Real lo = std::max<Real>(0, tIn), hi = std::min<Real>(1, tOut);
      const Vec3 d = P.p[1] - P.p[0];
      emitFromP(P.p[0] + lo * d, lo > 0 ? 64 : 0);
      emitFromP(P.p[0] + hi * d, (1u << 7) | (hi < 1 ? 65 : 1));
      return int(out.size() - begin);
    }
    const int n = P.count;
    if (P.disc) {
      // A cap on a cap. Both rims are material points at the same fixed angles, so on coaxial caps of equal
      // radius (every aligned stack of equal cylinders) P's rim points lie on D's circle and coincide with D's:
      // testing them against the circle exactly let roundoff decide, step by step, which copy (P's vertex, an
      // edge crossing at t = 0 or 1, or D's rim point) was emitted and kept -- a new feature id, and a warm start
      // lost while the tower still settles faster than the position fallback's 1e-5 m (contact_rows.h); the
      // unequal start tilted the heavy cylinder towers of test_extremes_stacks_cylinders (first sideways motion
      // at step 8 of 10 x 2 m x 1000 kg/m^3, at the top joint's re-labelled point). Here the boundary band of
      // width kCapBand r around D's circle belongs to D: D's rim points count as inside P up to kCapBand r
      // beyond P's circle, P's rim points only when more than kCapBand r inside D's circle, and P's rim edges
      // give crossings only between a point inside and one outside the band (or two outside: a secant). A 1e-4 r
      // lateral band is far below the cap polygon's own 1 % sagitta, and far above roundoff; coaxial caps
      // (tilted up to sqrt(2e-4) rad, ~0.8 deg) then give exactly D's rim points, a fixed set of material points.
      const Real band = kCapBand * D.radius;
      const Real in2 = (D.radius - band) * (D.radius - band), out2 = (D.radius + band) * (D.radius + band);
      thread_local std::array<int8_t, kMaxFeaturePoints> where;  // -1 inside the band, 0 in it, +1 outside
      for (int k = 0; k < n; ++k) {
        const Real d2 = (toD(P.p[size_t(k)]) - c).squaredNorm();
        where[size_t(k)] = int8_t(d2 < in2 ? -1 : d2 > out2 ? 1 : 0);
      }
      for (int k = 0; k < n; ++k) {
        const int kb = (k + 1) % n;
        const Vec3& a = P.p[size_t(k)];
        const Vec3& b = P.p[size_t(kb)];
        if (where[size_t(k)] < 0) emitFromP(a, labelPair(uint32_t((k + n - 1) % n & 63), uint32_t(k & 63)));
        const int wa = where[size_t(k)], wb = where[size_t(kb)];
        if (wa == 0 || wb == 0 || (wa < 0 && wb < 0)) continue;
        Real tIn, tOut;
        if (!crossings(toD(a), toD(b), tIn, tOut)) continue;
        if (wa > 0) emitFromP(a + std::clamp<Real>(tIn, 0, 1) * (b - a), labelPair(uint32_t(k & 63), 64));
        if (wb > 0) emitFromP(a + std::clamp<Real>(tOut, 0, 1) * (b - a), labelPair(uint32_t(k & 63), 65));
      }
      const Real rP = P.radius + band, rP2 = rP * rP;
      for (int j = 0; j < D.count; ++j) {
        const Vec3& y = D.p[size_t(j)];
        if ((toP(y) - P.centre).squaredNorm() <= rP2) emitFromD(y, labelPair(uint32_t(64 + (j & 63)), 127));
      }
      levelDepths(out, begin, Real(1e-12) * (1 + c.cwiseAbs().maxCoeff()));
      return reduceManifold(out, begin, 4, Real(1e-4) * D.radius);
    }
    for (int k = 0; k < n; ++k) {
      const Vec3& a = P.p[size_t(k)];
      const Vec3& b = P.p[size_t((k + 1) % n)];
      const Vec3 aD = toD(a), bD = toD(b);
      if ((aD - c).squaredNorm() <= r2) emitFromP(a, labelPair(uint32_t((k + n - 1) % n & 63), uint32_t(k & 63)));
      Real tIn, tOut;
      if (crossings(aD, bD, tIn, tOut)) {
        if (tIn > 0 && tIn < 1) emitFromP(a + tIn * (b - a), labelPair(uint32_t(k & 63), 64));
        if (tOut > 0 && tOut < 1) emitFromP(a + tOut * (b - a), labelPair(uint32_t(k & 63), 65));
      }
    }
    // D's rim points inside P (a polygon here; a cap on a cap is the branch above).
    const Real rP2 = P.radius * P.radius * (1 + Real(1e-12));
    thread_local std::array<Vec3, kMaxFeaturePoints> side;
    thread_local std::array<Real, kMaxFeaturePoints> sideOffset;
    if (!P.disc)
      for (int k = 0; k < n; ++k) {
        side[size_t(k)] = (P.p[size_t((k + 1) % n)] - P.p[size_t(k)]).cross(P.normal);
        sideOffset[size_t(k)] = side[size_t(k)].dot(P.p[size_t(k)]);
      }
    for (int j = 0; j < D.count; ++j) {
      const Vec3& y = D.p[size_t(j)];
      const Vec3 x = toP(y);
      bool inside = true;
      if (P.disc) {
        inside = (x - P.centre).squaredNorm() <= rP2;
      } else {
        for (int k = 0; k < n && inside; ++k) inside = side[size_t(k)].dot(x) <= sideOffset[size_t(k)];
      }
      if (inside) emitFromD(y, labelPair(uint32_t(64 + (j & 63)), 127));
    }
    levelDepths(out, begin, Real(1e-12) * (1 + c.cwiseAbs().maxCoeff()));
    return reduceManifold(out, begin, 4, Real(1e-4) * D.radius);
  }
  if (I.count == 2) {
    Vec3 a = I.p[0], b = I.p[1];
    uint8_t la = 0, lb = 1;
    if (!clipSegment(a, b, la, lb, R.p.data(), R.count, nRef)) return 0;
    emit(a, (0u << 7) | la);
    emit(b, (1u << 7) | lb);
    return int(out.size() - begin);
  }
  thread_local std::vector<ClipVertex> poly, scratch;
  initIncident(I.p.data(), I.count, poly);
  clipToReference(poly, R.p.data(), R.count, nRef, scratch);
  for (const ClipVertex& v : poly) emit(v.p, clipLabel(v));
  return reduceManifold(out, begin, 4);
}

int collideCcdManifold(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
                       std::vector<ContactPoint>& out) {
  const size_t begin = out.size();
  if (collideCcd(s0, t0, s1, t1, margin, out) != 1) return int(out.size() - begin);
  return manifoldOrSinglePoint(s0, t0, s1, t1, out.back(), margin, out, begin);
}

int manifoldOrSinglePoint(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1,
                          const ContactPoint single, Real margin, std::vector<ContactPoint>& out, size_t begin) {
  out.resize(begin);
  const int m = manifoldFromNormal(s0, t0, s1, t1, single.normal, margin, out);
  if (m > 0) return m;
  out.resize(begin);
  out.push_back(single);
  return 1;
}

}  // namespace scree::detail
