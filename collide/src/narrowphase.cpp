// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Narrowphase dispatch and the simple analytic pairs (sphere, capsule, cylinder, box-plane, line sensors).
//
// The table maps (Shape::Type, Shape::Type) to one routine written for a canonical order; the reverse order
// calls it with the arguments swapped and flips the normals it appended, so every routine only has to get the
// convention right once (normal from its second shape towards its first).
//
// Feature ids: sphere pairs 0; capsule ends 1 and 2 (0 for a single closest point); box-plane and convex-plane
// the vertex index; cylinder-plane cap * 8 + rim point; cylinder-box see cylinder_box.cpp; the libccd pairs
// with a manifold (capsule-cylinder, capsule-convex, cylinder-cylinder, cylinder-convex) see convex_manifold.cpp.
// Lines report only the entry point (id 0).
//
// Lines are sensors: a line contact is the point where the segment, walked from its first point to its second,
// enters the shape; the normal is the shape's outward surface normal there and the depth is the length of the
// segment that lies inside the shape. A line starting inside a shape reports its first point with the normal of
// the nearest surface. Margins do not apply to lines (no speculative line contacts).
#include "scree/collide/narrowphase.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "narrowphase_internal.h"

namespace scree {
namespace detail {

namespace {

constexpr Real kEps = 1e-12;

/// Any unit vector perpendicular to unit `a` (used when a direction degenerates).
Vec3 anyPerpendicular(const Vec3& a) {
  Vec3 t1, t2;
  orthonormalBasis(a, t1, t2);
  return t1;
}

/// Two spheres (c0, r0) and (c1, r1): one point when within the margin. `fallback` is the normal used when the
/// centres coincide (a unit vector from sphere 1 towards sphere 0).
int emitSpheres(const Vec3& c0, Real r0, const Vec3& c1, Real r1, Real margin, uint32_t fid, const Vec3& fallback,
                std::vector<ContactPoint>& out) {
  const Vec3 d = c0 - c1;
  const Real dist = d.norm();
  const Real depth = r0 + r1 - dist;
  if (depth < -margin) return 0;
  const Vec3 n = dist > kEps ? Vec3(d / dist) : fallback;
  // Midway between the surface points c0 - n r0 and c1 + n r1.
  const Vec3 p = Real(0.5) * ((c0 - n * r0) + (c1 + n * r1));
  out.push_back(makeContact(p, n, depth, fid));
  return 1;
}

/// World plane n . x = d of a Plane shape placed by t.
void worldPlane(const Plane& pl, const Transform& t, Vec3& n, Real& d) {
  n = t.rotate(pl.getNormal());
  d = pl.getDistance() + n.dot(t.p);
}

/// A point x of shape 0 lying `depth` below the plane surface (normal n): contact midway between x and its
/// projection x + n depth.
void emitPlanePoint(const Vec3& x, const Vec3& n, Real depth, uint32_t fid, std::vector<ContactPoint>& out) {
  out.push_back(makeContact(x + n * (Real(0.5) * depth), n, depth, fid));
}

void capsuleEnds(const Capsule& c, const Transform& t, Vec3& a, Vec3& b) {
  const Vec3 half = t.rotate(Vec3(0, Real(0.5) * c.getHeight(), 0));
  a = t.p - half;
  b = t.p + half;
}

// ---------------------------------------------------------------------------------------------------------------
int sphereSphere(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
                 std::vector<ContactPoint>& out) {
  return emitSpheres(t0.p, static_cast<const Sphere&>(s0).getRadius(), t1.p,
                     static_cast<const Sphere&>(s1).getRadius(), margin, 0, Vec3::UnitZ(), out);
}

int spherePlane(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
                std::vector<ContactPoint>& out) {
  const Real r = static_cast<const Sphere&>(s0).getRadius();
  Vec3 n;
  Real d;
  worldPlane(static_cast<const Plane&>(s1), t1, n, d);
  const Real h = n.dot(t0.p) - d;  // centre height above the plane
  const Real depth = r - h;
  if (depth < -margin) return 0;
  emitPlanePoint(t0.p - n * r, n, depth, 0, out);
  return 1;
}

int sphereBox(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
              std::vector<ContactPoint>& out) {
  const Real r = static_cast<const Sphere&>(s0).getRadius();
  const Vec3& h = static_cast<const Box&>(s1).getHalfExtents();
  const Vec3 c = t1.applyInverse(t0.p);
  const Vec3 q = c.cwiseMax(-h).cwiseMin(h);
  Vec3 n, boxPoint;
  Real depth;
  if (q != c) {
    // Centre outside: the clamped point is the closest box point (Ericson 5.1.3).
    const Vec3 d = c - q;
    const Real dist = d.norm();
    depth = r - dist;
    if (depth < -margin) return 0;
    n = d / dist;
    boxPoint = q;
  } else {
    // Centre inside: push out through the nearest face.
    int axis = 0;
    Real best = std::numeric_limits<Real>::max();
    for (int i = 0; i < 3; ++i) {
      const Real s = h[i] - std::abs(c[i]);
      if (s < best) {
        best = s;
        axis = i;
      }
    }
    const Real sign = c[axis] >= 0 ? 1 : -1;
    n = Vec3::Zero();
    n[axis] = sign;
    depth = r + best;
    boxPoint = c;
    boxPoint[axis] = sign * h[axis];
  }
  const Vec3 p = Real(0.5) * ((c - n * r) + boxPoint);
  out.push_back(makeContact(t1.apply(p), t1.rotate(n), depth, 0));
  return 1;
}

int sphereCapsule(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
                  std::vector<ContactPoint>& out) {
  const auto& cap = static_cast<const Capsule&>(s1);
  Vec3 a, b;
  capsuleEnds(cap, t1, a, b);
  const Real s = closestOnSegment(a, b, t0.p);
  const Vec3 axis = (b - a).normalized();
  return emitSpheres(t0.p, static_cast<const Sphere&>(s0).getRadius(), a + s * (b - a), cap.getRadius(), margin, 0,
                     anyPerpendicular(axis), out);
}

int sphereCylinder(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
                   std::vector<ContactPoint>& out) {
  const Real R = static_cast<const Sphere&>(s0).getRadius();
  const auto& cyl = static_cast<const Cylinder&>(s1);
  const Real r = cyl.getRadius(), hh = Real(0.5) * cyl.getHeight();
  const Vec3 c = t1.applyInverse(t0.p);  // cylinder frame, axis y
  const Real rho = std::hypot(c.x(), c.z());
  const Vec3 radial = rho > kEps ? Vec3(c.x() / rho, 0, c.z() / rho) : Vec3::UnitX();
  Vec3 n, q;
  Real depth;
  if (rho <= r && std::abs(c.y()) <= hh) {
    // Centre inside: leave through the side or through the nearer cap, whichever is closer.
    const Real side = r - rho, cap = hh - std::abs(c.y());
    const Real sy = c.y() >= 0 ? 1 : -1;
    if (side < cap) {
      n = radial;
      q = Vec3(radial.x() * r, c.y(), radial.z() * r);
      depth = R + side;
    } else {
      n = Vec3(0, sy, 0);
      q = Vec3(c.x(), sy * hh, c.z());
      depth = R + cap;
    }
  } else {
    // Closest point: clamp the radial distance and the axial coordinate separately (the cylinder is the product
    // of a disc and an interval, so the clamp is exact).
    const Real qr = std::min(rho, r);
    q = Vec3(radial.x() * qr, std::clamp(c.y(), -hh, hh), radial.z() * qr);
    const Vec3 d = c - q;
    const Real dist = d.norm();
    depth = R - dist;
    if (depth < -margin) return 0;
    n = d / dist;
  }
  const Vec3 p = Real(0.5) * ((c - n * R) + q);
  out.push_back(makeContact(t1.apply(p), t1.rotate(n), depth, 0));
  return 1;
}

// ---------------------------------------------------------------------------------------------------------------
// Capsule-capsule: closest points of the two segments. When the axes are nearly parallel the closest pair is not
// unique (a capsule lying along another), so the overlap of the two segments, projected on the first axis, gives
// two points; the unique closest point is added as well when it lies between them (slightly crossed axes).
int capsuleCapsule(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
                   std::vector<ContactPoint>& out) {
  const auto& c0 = static_cast<const Capsule&>(s0);
  const auto& c1 = static_cast<const Capsule&>(s1);
  Vec3 a0, b0, a1, b1;
  capsuleEnds(c0, t0, a0, b0);
  capsuleEnds(c1, t1, a1, b1);
  const Real r0 = c0.getRadius(), r1 = c1.getRadius();
  const Vec3 d0 = b0 - a0, d1 = b1 - a1;
  const Real l0 = d0.norm(), l1 = d1.norm();
  const Vec3 u0 = d0 / l0;
  const Vec3 fallback = anyPerpendicular(u0);
  const size_t begin = out.size();

  // sin(angle) below 1e-3 (0.06 deg) counts as parallel: beyond that the single closest point is well defined
  // and two points would misplace the support of crossed capsules.
  const bool parallel = d0.cross(d1).norm() <= Real(1e-3) * l0 * l1;
  if (parallel) {
    const Real u = (a1 - a0).dot(u0), v = (b1 - a0).dot(u0);
    const Real lo = std::max<Real>(0, std::min(u, v)), hi = std::min(l0, std::max(u, v));
    if (hi - lo > Real(1e-9) * (l0 + l1) && std::abs(v - u) > kEps) {
      for (int k = 0; k < 2; ++k) {
        const Real x = k == 0 ? lo : hi;
        const Real t = std::clamp((x - u) / (v - u), Real(0), Real(1));
        const Vec3 p1 = a1 + t * d1;
        const Vec3 p0 = a0 + closestOnSegment(a0, b0, p1) * d0;
        emitSpheres(p0, r0, p1, r1, margin, uint32_t(1 + k), fallback, out);
      }
      return int(out.size() - begin);
    }
  }
  Real s, t;
  closestSegmentSegment(a0, b0, a1, b1, s, t);
  return emitSpheres(a0 + s * d0, r0, a1 + t * d1, r1, margin, 0, fallback, out);
}

int capsulePlane(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
                 std::vector<ContactPoint>& out) {
  const auto& cap = static_cast<const Capsule&>(s0);
  const Real r = cap.getRadius();
  Vec3 ends[2];
  capsuleEnds(cap, t0, ends[0], ends[1]);
  Vec3 n;
  Real d;
  worldPlane(static_cast<const Plane&>(s1), t1, n, d);
  int count = 0;
  for (int k = 0; k < 2; ++k) {
    const Real depth = r - (n.dot(ends[k]) - d);
    if (depth < -margin) continue;
    emitPlanePoint(ends[k] - n * r, n, depth, uint32_t(1 + k), out);
    ++count;
  }
  return count;
}

// ---------------------------------------------------------------------------------------------------------------
// Capsule-box, in the box frame. Separated: the closest pair is an end point against the box or the segment
// against one of the 12 box edges (a segment-face closest pair that is not also one of these only exists when
// the segment is parallel to the face, and then an end point or edge attains it too). Intersecting: SAT over the
// 3 face normals and the 3 axis x edge directions gives the least-penetration axis.
// A capsule lying on a face (normal = face normal, axis within ~3 deg of the face) gets two points: its segment
// clipped to the face rectangle.
int capsuleBox(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
               std::vector<ContactPoint>& out) {
  const auto& cap = static_cast<const Capsule&>(s0);
  const Vec3& h = static_cast<const Box&>(s1).getHalfExtents();
  const Real r = cap.getRadius();
  Vec3 wa, wb;
  capsuleEnds(cap, t0, wa, wb);
  const Vec3 a = t1.applyInverse(wa), b = t1.applyInverse(wb), d = b - a;

  // Does the segment touch the box? (slab clipping, Ericson 5.3.3)
  Real tmin = 0, tmax = 1;
  for (int i = 0; i < 3 && tmin <= tmax; ++i) {
    if (std::abs(d[i]) < kEps) {
      if (std::abs(a[i]) > h[i]) tmax = -1;
    } else {
      Real ta = (-h[i] - a[i]) / d[i], tb = (h[i] - a[i]) / d[i];
      if (ta > tb) std::swap(ta, tb);
      tmin = std::max(tmin, ta);
      tmax = std::min(tmax, tb);
    }
  }
  Vec3 n, ps;  // normal (box -> capsule) and the segment point of the contact
  Real depth;
  if (tmin > tmax) {
    Real best = std::numeric_limits<Real>::max();
    Vec3 bestS = a, bestB = a;
    auto consider = [&](const Vec3& sp, const Vec3& bp) {
      const Real dd = (sp - bp).squaredNorm();
      if (dd < best) {
        best = dd;
        bestS = sp;
        bestB = bp;
      }
    };
    consider(a, a.cwiseMax(-h).cwiseMin(h));
    consider(b, b.cwiseMax(-h).cwiseMin(h));
    for (int ax = 0; ax < 3; ++ax) {
      const int u = (ax + 1) % 3, v = (ax + 2) % 3;
      for (int k = 0; k < 4; ++k) {
        Vec3 e0 = Vec3::Zero();
        e0[u] = (k & 1) ? h[u] : -h[u];
        e0[v] = (k & 2) ? h[v] : -h[v];
        e0[ax] = -h[ax];
        Vec3 e1 = e0;
        e1[ax] = h[ax];
        Real s, t;
        closestSegmentSegment(a, b, e0, e1, s, t);
        consider(a + s * d, e0 + t * (e1 - e0));
      }
    }
    const Real dist = std::sqrt(best);
    depth = r - dist;
    if (depth < -margin) return 0;
    n = (bestS - bestB) / dist;
    ps = bestS;
  } else {
    const Vec3 m = Real(0.5) * (a + b), hd = Real(0.5) * d;
    Real bestSep = -std::numeric_limits<Real>::max();
    n = Vec3::UnitZ();
    auto axisTest = [&](const Vec3& L) {
      const Real sep = std::abs(L.dot(m)) - h.dot(L.cwiseAbs()) - std::abs(L.dot(hd));
      if (sep > bestSep) {
        bestSep = sep;
        n = L.dot(m) >= 0 ? L : Vec3(-L);
      }
    };
    for (int i = 0; i < 3; ++i) axisTest(Vec3::Unit(i));
    // Small bias: a cross axis must beat the faces clearly, so a capsule resting in a face keeps the face normal.
    const Real faceSep = bestSep;
    const Vec3 faceN = n;
    for (int i = 0; i < 3; ++i) {
      const Vec3 L = d.cross(Vec3::Unit(i));
      const Real len = L.norm();
      if (len > Real(1e-6) * d.norm()) axisTest(L / len);
    }
    if (bestSep <= faceSep + Real(1e-9) + Real(0.02) * std::abs(faceSep)) {
      bestSep = faceSep;
      n = faceN;
    }
    depth = r - bestSep;
    ps = n.dot(a) <= n.dot(b) ? a : b;  // the segment's deepest point along -n
  }

  // Lying on a face: the normal is a face normal and the axis is nearly parallel to that face.
  int faceAxis = -1;
  for (int i = 0; i < 3; ++i)
    if (std::abs(n[i]) > 1 - Real(1e-9)) faceAxis = i;
  const size_t begin = out.size();
  if (faceAxis >= 0 && std::abs(d.normalized().dot(n)) < Real(0.05)) {
    const Vec3 fn = Vec3::Unit(faceAxis) * (n[faceAxis] > 0 ? 1 : -1);
    Real lo = 0, hi = 1;
    for (int i = 0; i < 3; ++i) {
      if (i == faceAxis) continue;
      if (std::abs(d[i]) < kEps) {
        if (std::abs(a[i]) > h[i]) hi = -1;
        continue;
      }
      Real ta = (-h[i] - a[i]) / d[i], tb = (h[i] - a[i]) / d[i];
      if (ta > tb) std::swap(ta, tb);
      lo = std::max(lo, ta);
      hi = std::min(hi, tb);
    }
    if (hi - lo > Real(1e-9)) {
      for (int k = 0; k < 2; ++k) {
        const Vec3 x = a + (k == 0 ? lo : hi) * d;
        const Real dk = r - (fn.dot(x) - h[faceAxis]);
        if (dk < -margin) continue;
        const Vec3 p = x - fn * r + fn * (Real(0.5) * dk);
        out.push_back(makeContact(t1.apply(p), t1.rotate(fn), dk, uint32_t(1 + k)));
      }
      return int(out.size() - begin);
    }
  }
  const Vec3 p = ps - n * r + n * (Real(0.5) * depth);
  out.push_back(makeContact(t1.apply(p), t1.rotate(n), depth, 0));
  return 1;
}

// ---------------------------------------------------------------------------------------------------------------
int boxPlane(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
             std::vector<ContactPoint>& out) {
  const Vec3& h = static_cast<const Box&>(s0).getHalfExtents();
  Vec3 n;
  Real d;
  worldPlane(static_cast<const Plane&>(s1), t1, n, d);
  std::array<std::pair<Real, int>, 8> cand;
  int num = 0;
  std::array<Vec3, 8> v;
  for (int k = 0; k < 8; ++k) {
    const Vec3 local((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(), (k & 4) ? h.z() : -h.z());
    v[k] = t0.apply(local);
    const Real depth = d - n.dot(v[k]);
    if (depth >= -margin) cand[num++] = {depth, k};
  }
  // Deepest four, ties kept in vertex order (stable_sort) so the choice does not flicker.
  std::stable_sort(cand.begin(), cand.begin() + num, [](const auto& x, const auto& y) { return x.first > y.first; });
  num = std::min(num, 4);
  for (int i = 0; i < num; ++i) emitPlanePoint(v[cand[i].second], n, cand[i].first, uint32_t(cand[i].second), out);
  return num;
}

// Cylinder-plane: the deepest points of a cylinder against a plane lie on the cap rims. Nearly upright (axis
// within ~2.6 deg of the plane normal), the lower cap rests on its face: four rim points at fixed angles in the
// cylinder frame (ids stay with the material points). Otherwise the deepest rim point of each cap (a lying
// cylinder gets its two line-contact ends; a tilted one its lowest rim point, the upper one usually beyond the
// margin).
int cylinderPlane(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
                  std::vector<ContactPoint>& out) {
  const auto& cyl = static_cast<const Cylinder&>(s0);
  const Real r = cyl.getRadius(), hh = Real(0.5) * cyl.getHeight();
  Vec3 n;
  Real d;
  worldPlane(static_cast<const Plane&>(s1), t1, n, d);
  const Vec3 nl = t0.rotateInverse(n);  // plane normal in the cylinder frame
  const size_t begin = out.size();
  auto emit = [&](const Vec3& local, uint32_t fid) {
    const Vec3 x = t0.apply(local);
    const Real depth = d - n.dot(x);
    if (depth >= -margin) emitPlanePoint(x, n, depth, fid, out);
  };
  const Vec3 radial(nl.x(), 0, nl.z());
  const Real rl = radial.norm();
  if (rl < Real(0.045)) {
    const Real cy = nl.y() > 0 ? -hh : hh;  // cap facing the plane
    const uint32_t cap = nl.y() > 0 ? 0 : 1;
    emit(Vec3(r, cy, 0), cap * 8 + 0);
    emit(Vec3(0, cy, r), cap * 8 + 1);
    emit(Vec3(-r, cy, 0), cap * 8 + 2);
    emit(Vec3(0, cy, -r), cap * 8 + 3);
  } else {
    const Vec3 u = -radial / rl;  // rim direction that goes deepest
    emit(Vec3(u.x() * r, -hh, u.z() * r), 0 * 8 + 4);
    emit(Vec3(u.x() * r, hh, u.z() * r), 1 * 8 + 4);
  }
  return int(out.size() - begin);
}

// ---------------------------------------------------------------------------------------------------------------
// Line sensors.

/// Emits a line contact from the entry parameter interval [tin, tout] (unclamped) on segment a + t d.
int emitLine(const Vec3& a, const Vec3& d, Real tin, Real tout, const Vec3& nIn, std::vector<ContactPoint>& out) {
  if (tin > tout || tout < 0 || tin > 1) return 0;
  const Real t0 = std::max<Real>(tin, 0), t1 = std::min<Real>(tout, 1);
  out.push_back(makeContact(a + t0 * d, nIn, (t1 - t0) * d.norm(), 0));
  return 1;
}

/// Line a + t d against sphere (c, r): interval and entry normal. False when the line misses.
bool lineSphereInterval(const Vec3& a, const Vec3& d, const Vec3& c, Real r, Real& tin, Real& tout) {
  const Vec3 m = a - c;
  const Real dd = d.squaredNorm(), b = m.dot(d), cc = m.squaredNorm() - r * r;
  const Real disc = b * b - dd * cc;
  if (dd < kEps || disc < 0) return false;
  const Real sq = std::sqrt(disc);
  tin = (-b - sq) / dd;
  tout = (-b + sq) / dd;
  return true;
}

/// Line a + t d against the finite cylinder with axis from A along unit w, length L, radius r (no caps needed
/// for capsules; `withCaps` adds the cap normals). Returns the interval and the entry normal.
bool lineCylinderInterval(const Vec3& a, const Vec3& d, const Vec3& A, const Vec3& w, Real L, Real r, Real& tin,
                          Real& tout, Vec3& nIn) {
  const Vec3 m = a - A;
  const Vec3 dp = d - d.dot(w) * w, mp = m - m.dot(w) * w;
  // Infinite cylinder |mp + t dp| = r.
  Real cin, cout;
  const Real dd = dp.squaredNorm();
  if (dd < kEps) {
    if (mp.squaredNorm() > r * r) return false;
    cin = -std::numeric_limits<Real>::infinity();
    cout = std::numeric_limits<Real>::infinity();
  } else {
    const Real b = mp.dot(dp), c = mp.squaredNorm() - r * r, disc = b * b - dd * c;
    if (disc < 0) return false;
    const Real sq = std::sqrt(disc);
    cin = (-b - sq) / dd;
    cout = (-b + sq) / dd;
  }
  // Slab 0 <= (m + t d) . w <= L.
  Real sin_ = -std::numeric_limits<Real>::infinity(), sout = std::numeric_limits<Real>::infinity();
  Vec3 capN = Vec3::Zero();
  const Real dw = d.dot(w), mw = m.dot(w);
  if (std::abs(dw) < kEps) {
    if (mw < 0 || mw > L) return false;
  } else {
    Real ta = (0 - mw) / dw, tb = (L - mw) / dw;
    capN = dw > 0 ? Vec3(-w) : w;
    if (ta > tb) std::swap(ta, tb);
    sin_ = ta;
    sout = tb;
  }
  tin = std::max(cin, sin_);
  tout = std::min(cout, sout);
  if (tin > tout) return false;
  if (sin_ >= cin) {
    nIn = capN;
  } else {
    const Vec3 x = mp + cin * dp;
    nIn = x.norm() > kEps ? Vec3(x.normalized()) : anyPerpendicular(w);
  }
  return true;
}

int lineSphere(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real,
               std::vector<ContactPoint>& out) {
  const auto& line = static_cast<const Line&>(s0);
  const Vec3 a = t0.apply(line.getFirstPoint()), d = t0.apply(line.getSecondPoint()) - a;
  const Vec3& c = t1.p;
  Real tin, tout;
  if (!lineSphereInterval(a, d, c, static_cast<const Sphere&>(s1).getRadius(), tin, tout)) return 0;
  const Vec3 x = a + std::max<Real>(tin, 0) * d - c;
  return emitLine(a, d, tin, tout, x.norm() > kEps ? Vec3(x.normalized()) : Vec3::UnitZ(), out);
}

int lineBox(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real,
            std::vector<ContactPoint>& out) {
  const auto& line = static_cast<const Line&>(s0);
  const Vec3& h = static_cast<const Box&>(s1).getHalfExtents();
  const Vec3 wa = t0.apply(line.getFirstPoint()), wd = t0.apply(line.getSecondPoint()) - wa;
  const Vec3 a = t1.applyInverse(wa), d = t1.rotateInverse(wd);
  Real tin = -std::numeric_limits<Real>::infinity(), tout = std::numeric_limits<Real>::infinity();
  Vec3 nIn = Vec3::UnitZ();
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < kEps) {
      if (std::abs(a[i]) > h[i]) return 0;
      continue;
    }
    Real ta = (-h[i] - a[i]) / d[i], tb = (h[i] - a[i]) / d[i];
    Vec3 ni = Vec3::Zero();
    ni[i] = d[i] > 0 ? -1 : 1;  // the face entered first faces against the direction of travel
    if (ta > tb) std::swap(ta, tb);
    if (ta > tin) {
      tin = ta;
      nIn = ni;
    }
    tout = std::min(tout, tb);
  }
  if (tin < 0) {
    // Starts inside: the nearest face's normal.
    Real best = std::numeric_limits<Real>::max();
    for (int i = 0; i < 3; ++i) {
      const Real s = h[i] - std::abs(a[i]);
      if (s < best) {
        best = s;
        nIn = Vec3::Zero();
        nIn[i] = a[i] >= 0 ? 1 : -1;
      }
    }
  }
  return emitLine(wa, wd, tin, tout, t1.rotate(nIn), out);
}

int linePlane(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real,
              std::vector<ContactPoint>& out) {
  const auto& line = static_cast<const Line&>(s0);
  Vec3 n;
  Real d;
  worldPlane(static_cast<const Plane&>(s1), t1, n, d);
  const Vec3 a = t0.apply(line.getFirstPoint()), b = t0.apply(line.getSecondPoint());
  const Real sa = n.dot(a) - d, sb = n.dot(b) - d;
  // Only a line entering from the front side: a line starting behind the plane sees nothing (shapes.h).
  if (sa < 0 || sb >= 0) return 0;
  return emitLine(a, b - a, sa / (sa - sb), 1, n, out);
}

int lineCapsule(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real,
                std::vector<ContactPoint>& out) {
  const auto& line = static_cast<const Line&>(s0);
  const auto& cap = static_cast<const Capsule&>(s1);
  const Vec3 a = t0.apply(line.getFirstPoint()), d = t0.apply(line.getSecondPoint()) - a;
  Vec3 A, B;
  capsuleEnds(cap, t1, A, B);
  const Real r = cap.getRadius();
  // The capsule is the union of two balls and a finite cylinder; it is convex, so its chord is the union of the
  // parts' chords: entry = earliest entry, exit = latest exit.
  Real tin = std::numeric_limits<Real>::infinity(), tout = -std::numeric_limits<Real>::infinity();
  Vec3 nIn = Vec3::UnitZ();
  bool hit = false;
  for (const Vec3& c : {A, B}) {
    Real i0, o0;
    if (lineSphereInterval(a, d, c, r, i0, o0)) {
      hit = true;
      if (i0 < tin) {
        tin = i0;
        nIn = (a + i0 * d - c).normalized();
      }
      tout = std::max(tout, o0);
    }
  }
  const Real L = (B - A).norm();
  Real i1, o1;
  Vec3 n1;
  if (L > kEps && lineCylinderInterval(a, d, A, (B - A) / L, L, r, i1, o1, n1)) {
    hit = true;
    if (i1 < tin) {
      tin = i1;
      nIn = n1;
    }
    tout = std::max(tout, o1);
  }
  if (!hit) return 0;
  if (tin < 0) {
    const Vec3 x = a - (A + closestOnSegment(A, B, a) * (B - A));
    nIn = x.norm() > kEps ? Vec3(x.normalized()) : anyPerpendicular((B - A).normalized());
  }
  return emitLine(a, d, tin, tout, nIn, out);
}

int lineCylinder(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real,
                 std::vector<ContactPoint>& out) {
  const auto& line = static_cast<const Line&>(s0);
  const auto& cyl = static_cast<const Cylinder&>(s1);
  const Vec3 a = t0.apply(line.getFirstPoint()), d = t0.apply(line.getSecondPoint()) - a;
  const Vec3 w = t1.rotate(Vec3::UnitY());
  const Real L = cyl.getHeight(), r = cyl.getRadius();
  const Vec3 A = t1.p - Real(0.5) * L * w;
  Real tin, tout;
  Vec3 nIn;
  if (!lineCylinderInterval(a, d, A, w, L, r, tin, tout, nIn)) return 0;
  if (tin < 0) {
    const Vec3 c = t1.applyInverse(a);
    const Real rho = std::hypot(c.x(), c.z());
    if (r - rho < Real(0.5) * L - std::abs(c.y()))
      nIn = t1.rotate(rho > kEps ? Vec3(c.x() / rho, 0, c.z() / rho) : Vec3::UnitX());
    else
      nIn = c.y() >= 0 ? w : Vec3(-w);
  }
  return emitLine(a, d, tin, tout, nIn, out);
}

int lineConvex(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real,
               std::vector<ContactPoint>& out) {
  const auto& line = static_cast<const Line&>(s0);
  const auto& cvx = static_cast<const Convex&>(s1);
  const Vec3 wa = t0.apply(line.getFirstPoint()), wd = t0.apply(line.getSecondPoint()) - wa;
  const Vec3 a = t1.applyInverse(wa), d = t1.rotateInverse(wd);
  // Clip the line by the hull's face half spaces (Cyrus-Beck).
  Real tin = -std::numeric_limits<Real>::infinity(), tout = std::numeric_limits<Real>::infinity();
  Vec3 nIn = Vec3::UnitZ(), nNear = Vec3::UnitZ();
  Real nearest = -std::numeric_limits<Real>::max();
  for (const auto& f : cvx.getFaces()) {
    const Real dist = f.normal.dot(a) - f.offset, den = f.normal.dot(d);
    if (dist > nearest) {
      nearest = dist;
      nNear = f.normal;
    }
    if (std::abs(den) < kEps) {
      if (dist > 0) return 0;
      continue;
    }
    const Real t = -dist / den;
    if (den < 0) {
      if (t > tin) {
        tin = t;
        nIn = f.normal;
      }
    } else {
      tout = std::min(tout, t);
    }
  }
  if (tin < 0) nIn = nNear;
  return emitLine(wa, wd, tin, tout, t1.rotate(nIn), out);
}

// ---------------------------------------------------------------------------------------------------------------
struct Entry {
  CollideFn fn = nullptr;
  bool swap = false;  // the routine takes (shape 1, shape 0)
};
using Table = std::array<std::array<Entry, Shape::NUM_TYPES>, Shape::NUM_TYPES>;

const Table& table() {
  static const Table t = [] {
    Table m{};
    auto add = [&m](Shape::Type a, Shape::Type b, CollideFn f) {
      m[a][b] = {f, false};
      if (a != b) m[b][a] = {f, true};
    };
    using S = Shape;
    add(S::SPHERE, S::SPHERE, sphereSphere);
    add(S::SPHERE, S::PLANE, spherePlane);
    add(S::SPHERE, S::BOX, sphereBox);
    add(S::SPHERE, S::CAPSULE, sphereCapsule);
    add(S::SPHERE, S::CYLINDER, sphereCylinder);
    add(S::SPHERE, S::CONVEX, collideCcd);
    add(S::SPHERE, S::HEIGHT_FIELD, collideSphereHeightField);
    add(S::BOX, S::BOX, collideBoxBox);
    add(S::BOX, S::PLANE, boxPlane);
    add(S::CYLINDER, S::BOX, collideCylinderBox);
    add(S::BOX, S::HEIGHT_FIELD, collideBoxHeightField);
    add(S::CAPSULE, S::BOX, capsuleBox);
    add(S::CAPSULE, S::CAPSULE, capsuleCapsule);
    add(S::CAPSULE, S::PLANE, capsulePlane);
    add(S::CAPSULE, S::CYLINDER, collideCcdManifold);
    add(S::CAPSULE, S::CONVEX, collideCcdManifold);
    add(S::CAPSULE, S::HEIGHT_FIELD, collideCapsuleHeightField);
    add(S::CYLINDER, S::CYLINDER, collideCcdManifold);
    add(S::CYLINDER, S::PLANE, cylinderPlane);
    add(S::CYLINDER, S::CONVEX, collideCcdManifold);
    add(S::CYLINDER, S::HEIGHT_FIELD, collideCylinderHeightField);
    add(S::CONVEX, S::CONVEX, collideConvexConvex);
    add(S::CONVEX, S::BOX, collideConvexBox);
    add(S::CONVEX, S::PLANE, collideConvexPlane);
    add(S::CONVEX, S::HEIGHT_FIELD, collideConvexHeightField);
    add(S::LINE, S::SPHERE, lineSphere);
    add(S::LINE, S::BOX, lineBox);
    add(S::LINE, S::PLANE, linePlane);
    add(S::LINE, S::CAPSULE, lineCapsule);
    add(S::LINE, S::CYLINDER, lineCylinder);
    add(S::LINE, S::CONVEX, lineConvex);
    add(S::LINE, S::HEIGHT_FIELD, collideLineHeightField);
    return m;
  }();
  return t;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
int reduceManifold(std::vector<ContactPoint>& out, size_t begin, int maxPoints, Real depthTieTolerance) {
  const int n = int(out.size() - begin);
  if (n <= maxPoints) return n;
  const ContactPoint* c = out.data() + begin;
  // 1. deepest (first wins ties, so the routines' emission order breaks ties deterministically)
  int i0 = 0;
  for (int i = 1; i < n; ++i)
    if (c[i].depth > c[i0].depth) i0 = i;
  if (depthTieTolerance > 0) {
    const Real level = c[i0].depth - depthTieTolerance;
    for (int i = 0; i < i0; ++i)
      if (c[i].depth >= level) {
        i0 = i;
        break;
      }
  }
  int sel[4] = {i0, -1, -1, -1};
  int numSel = 1;
  if (maxPoints >= 2) {
    // 2. farthest from it
    int i1 = -1;
    Real best = -1;
    for (int i = 0; i < n; ++i) {
      const Real d2 = (c[i].point - c[i0].point).squaredNorm();
      if (i != i0 && d2 > best) {
        best = d2;
        i1 = i;
      }
    }
    sel[numSel++] = i1;
    if (maxPoints >= 3) {
      // 3./4. largest signed triangle area with the segment on each side (area measured about the normal).
      const Vec3& nrm = c[i0].normal;
      const Vec3 e = c[i1].point - c[i0].point;
      int ip = -1, im = -1;
      Real ap = 0, am = 0;
      for (int i = 0; i < n; ++i) {
        if (i == i0 || i == i1) continue;
        const Real area = e.cross(c[i].point - c[i0].point).dot(nrm);
        if (ip < 0 || area > ap) {
          ap = area;
          ip = i;
        }
        if (im < 0 || area < am) {
          am = area;
          im = i;
        }
      }
      if (ip >= 0) sel[numSel++] = ip;
      if (maxPoints >= 4 && im >= 0 && im != ip) {
        sel[numSel++] = im;
      } else if (maxPoints >= 4) {
        // All on one side: the point farthest from the three chosen.
        int i3 = -1;
        Real b3 = -1;
        for (int i = 0; i < n; ++i) {
          if (i == sel[0] || i == sel[1] || i == sel[2]) continue;
          Real dmin = std::numeric_limits<Real>::max();
          for (int k = 0; k < 3; ++k) dmin = std::min(dmin, (c[i].point - c[sel[k]].point).squaredNorm());
          if (dmin > b3) {
            b3 = dmin;
            i3 = i;
          }
        }
        if (i3 >= 0) sel[numSel++] = i3;
      }
    }
  }
  ContactPoint keep[4];
  for (int k = 0; k < numSel; ++k) keep[k] = c[sel[k]];
  out.resize(begin);
  for (int k = 0; k < numSel; ++k) out.push_back(keep[k]);
  return numSel;
}

void closestSegmentSegment(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2, Real& s, Real& t) {
  // Ericson, RTCD 5.1.9, with the parallel case resolved towards the middle of the overlap is not needed here:
  // callers that care about parallel segments (capsule-capsule) treat that case themselves.
  const Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const Real a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  if (a <= kEps && e <= kEps) {
    s = t = 0;
    return;
  }
  if (a <= kEps) {
    s = 0;
    t = std::clamp(f / e, Real(0), Real(1));
    return;
  }
  const Real c = d1.dot(r);
  if (e <= kEps) {
    t = 0;
    s = std::clamp(-c / a, Real(0), Real(1));
    return;
  }
  const Real b = d1.dot(d2), denom = a * e - b * b;
  s = denom > kEps * a * e ? std::clamp((b * f - c * e) / denom, Real(0), Real(1)) : Real(0);
  t = (b * s + f) / e;
  if (t < 0) {
    t = 0;
    s = std::clamp(-c / a, Real(0), Real(1));
  } else if (t > 1) {
    t = 1;
    s = std::clamp((b - c) / a, Real(0), Real(1));
  }
}

Vec3 closestPointTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, int& region) {
  // Ericson, RTCD 5.1.5: barycentric tests against the vertex, edge and face Voronoi regions.
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const Real d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) {
    region = TRI_VERT_A;
    return a;
  }
  const Vec3 bp = p - b;
  const Real d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) {
    region = TRI_VERT_B;
    return b;
  }
  const Real vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    region = TRI_EDGE_AB;
    return a + (d1 / (d1 - d3)) * ab;
  }
  const Vec3 cp = p - c;
  const Real d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) {
    region = TRI_VERT_C;
    return c;
  }
  const Real vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    region = TRI_EDGE_CA;
    return a + (d2 / (d2 - d6)) * ac;
  }
  const Real va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    region = TRI_EDGE_BC;
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  }
  region = TRI_FACE;
  const Real denom = 1 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

}  // namespace detail

// ---------------------------------------------------------------------------------------------------------------
int collideGeometries(const Geometry& g0, const Geometry& g1, Real margin, std::vector<ContactPoint>& out) {
  const Shape& s0 = *g0.getShape();
  const Shape& s1 = *g1.getShape();
  const detail::Entry& e = detail::table()[s0.getType()][s1.getType()];
  if (!e.fn) return 0;
  margin = margin > 0 ? margin : Real(0);
  const size_t begin = out.size();
  if (!e.swap) {
    e.fn(s0, g0.getTransform(), s1, g1.getTransform(), margin, out);
  } else {
    e.fn(s1, g1.getTransform(), s0, g0.getTransform(), margin, out);
    for (size_t i = begin; i < out.size(); ++i) out[i].normal = -out[i].normal;
  }
  return int(out.size() - begin);
}

bool hasCollider(Shape::Type a, Shape::Type b) {
  if (a < 0 || b < 0 || a >= Shape::NUM_TYPES || b >= Shape::NUM_TYPES) return false;
  return detail::table()[a][b].fn != nullptr;
}

}  // namespace scree
