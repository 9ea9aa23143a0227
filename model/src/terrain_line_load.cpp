// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Terrain: gathering the contacts' normal loads onto the grid vertices (terrain.h, "Line contacts are line
// loads"). A point's load is split onto the three vertices of its triangle by barycentric weights; the points of
// a lying cylinder's or capsule's contact are read as one line load along its axis over their axial extent, a
// linear density (no tension: the middle-third rule) integrated exactly against the barycentric weights of every
// triangle the segment crosses.
#include <algorithm>
#include <cmath>
#include <vector>

#include "scree/model/terrain.h"

namespace scree {

namespace {

/// A linear density on t in [0, 1] with total W and centroid tc, non-negative: the linear one while tc lies in
/// the middle third, else the triangle from zero at `kink` to the near end (same total and centroid).
struct LineDensity {
  Real a = 0, b = 0;  ///< linear case: q(t) = a + (b - a) t
  Real kink = -1;     ///< triangle cases: where q starts (tc > 2/3) or ends (tc < 1/3); -1 in the linear case
  bool rising = false;
  Real W = 0;
  LineDensity(Real total, Real tc) : W(total) {
    if (tc >= Real(1) / 3 && tc <= Real(2) / 3) {
      a = W * (4 - 6 * tc);
      b = W * (6 * tc - 2);
    } else if (tc > Real(2) / 3) {
      kink = 3 * tc - 2;  // the triangle over [kink, 1], peak 2 W / (1 - kink) at t = 1: centroid kink + 2/3 (1 - kink)
      rising = true;
    } else {
      kink = 3 * tc;  // over [0, kink], peak at t = 0: centroid kink / 3
    }
  }
  Real operator()(Real t) const {
    if (kink < 0) return a + (b - a) * t;
    if (rising) {
      const Real l = 1 - kink;
      return t <= kink ? Real(0) : 2 * W * (t - kink) / (l * l);
    }
    return t >= kink ? Real(0) : 2 * W * (kink - t) / (kink * kink);
  }
  /// The whole load at one end (the triangle has shrunk to nothing): -1 none, 0 at t = 0, 1 at t = 1.
  int concentrated() const {
    if (kink < 0) return -1;
    if (rising && 1 - kink <= Real(1e-9)) return 1;
    if (!rising && kink <= Real(1e-9)) return 0;
    return -1;
  }
};

struct LoadedPoint {
  Vec3 q;       ///< height-field frame
  Real load = 0, E = 0;
};

}  // namespace

void Terrain::addVertexLoad(size_t v, Real f, Real k) {
  if (f == 0 && k == 0) return;
  if (load_[v] == 0 && stiffness_[v] == 0) loaded_.push_back(v);
  load_[v] += f;
  stiffness_[v] += k;
}

void Terrain::depositPoint(const Vec3& q, Real load, Real E) {
  size_t v[3];
  Real w[3];
  if (!locate(q, v, w)) return;
  for (int k = 0; k < 3; ++k)
    if (w[k] > 0) addVertexLoad(v[k], w[k] * load, w[k] * E);
}

void Terrain::gatherContactLoads(const GeometryContact& c, int self) {
  const Transform& T = geometry_->getTransform();
  const Real Ec = c.material().getYoungsModulus();
  std::vector<LoadedPoint> pts;
  for (const ContactPoint& p : c.points()) {
    if (!p.enabled || !(p.normalForce > 0)) continue;
    // The normal points from geometry 1 to geometry 0; the terrain is pressed along -normal when it is 1.
    const Real nz = T.rotateInverse(p.normal).z();
    const Real load = p.normalForce * (self == 1 ? nz : -nz);
    if (!(load > 0)) continue;
    pts.push_back(LoadedPoint{T.applyInverse(p.point), load,
                              p.youngsModulus > 0 ? p.youngsModulus : Ec});
  }
  const Geometry* other = c.geometry(1 - self);
  const Shape* shape = other->getShape().get();
  const bool lineShape = dynamic_cast<const Cylinder*>(shape) || dynamic_cast<const Capsule*>(shape);
  // Deformer contacts are generated points (terrain_deform.cpp), read as points.
  if (pts.size() < 2 || !lineShape || (dynamicHeightField_ && isGeometryDeformer(*other))) {
    for (const LoadedPoint& p : pts) depositPoint(p.q, p.load, p.E);
    return;
  }
  // A lying cylinder or capsule (axis within 60 degrees of the field's plane): its loaded points are read as one
  // line load along the axis, over the points' axial extent, on the line through their force centroid parallel
  // to the axis (so the total and the moment about every horizontal line are the points').
  const Transform& G = other->getTransform();
  const Vec3 axis = T.rotateInverse(G.rotate(Vec3::UnitY())), centre = T.applyInverse(G.p);
  if (std::abs(axis.z()) > Real(0.5)) {
    for (const LoadedPoint& p : pts) depositPoint(p.q, p.load, p.E);
    return;
  }
  Real F = 0, K = 0, lo = 0, hi = 0;
  Vec3 g = Vec3::Zero();
  std::vector<Real> along(pts.size());
  for (size_t i = 0; i < pts.size(); ++i) {
    along[i] = (pts[i].q - centre).dot(axis);
    lo = i == 0 ? along[i] : std::min(lo, along[i]);
    hi = i == 0 ? along[i] : std::max(hi, along[i]);
    F += pts[i].load, K += pts[i].E;
    g += pts[i].load * pts[i].q;
  }
  const Real len = hi - lo;
  if (!(len > 1e-9 * (1 + std::abs(lo) + std::abs(hi)))) {
    for (const LoadedPoint& p : pts) depositPoint(p.q, p.load, p.E);
    return;
  }
  g /= F;
  Real Ft = 0, Kt = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    const Real t = (along[i] - lo) / len;
    Ft += pts[i].load * t, Kt += pts[i].E * t;
  }
  const Real gAlong = (g - centre).dot(axis);
  spreadLine(g + (lo - gAlong) * axis, g + (hi - gAlong) * axis, F, Ft / F, K, K > 0 ? Kt / K : Real(0.5));
}

void Terrain::spreadLine(const Vec3& A, const Vec3& B, Real F, Real tF, Real K, Real tK) {
  LineDensity qf(F, std::clamp<Real>(tF, 0, 1)), qk(K, std::clamp<Real>(tK, 0, 1));
  // A load (or stiffness) wholly at one end (its resultant at the end: one point carries it all) is a point there.
  if (const int e = qf.concentrated(); e >= 0) {
    depositPoint(e ? B : A, F, 0);
    qf = LineDensity(0, 0.5);
  }
  if (const int e = qk.concentrated(); e >= 0) {
    depositPoint(e ? B : A, 0, K);
    qk = LineDensity(0, 0.5);
  }
  // Grid coordinates along the footprint: u = x / dx, s = y / dy from the field's corner.
  const Real hx = 0.5 * heightField_->getSizeX(), hy = 0.5 * heightField_->getSizeY();
  const Real uA = (A.x() + hx) / dx_, sA = (A.y() + hy) / dy_;
  const Real du = (B.x() + hx) / dx_ - uA, ds = (B.y() + hy) / dy_ - sA;
  // Breaks: crossings of grid lines (u or s integer) and cell diagonals (u - s integer), and the densities'
  // kinks. Between breaks the barycentric weights of one triangle and both densities are linear in t.
  std::vector<Real> breaks{0, 1};
  auto crossings = [&](Real start, Real delta) {
    if (std::abs(delta) < 1e-12) return;
    const Real end = start + delta;
    for (Real k = std::ceil(std::min(start, end)); k <= std::floor(std::max(start, end)); k += 1) {
      const Real t = (k - start) / delta;
      if (t > 0 && t < 1) breaks.push_back(t);
    }
  };
  crossings(uA, du);
  crossings(sA, ds);
  crossings(uA - sA, du - ds);
  if (qf.kink > 0 && qf.kink < 1) breaks.push_back(qf.kink);
  if (qk.kink > 0 && qk.kink < 1) breaks.push_back(qk.kink);
  std::sort(breaks.begin(), breaks.end());
  const bool noForce = qf.W == 0, noStiff = qk.W == 0;
  if (noForce && noStiff) return;
  for (size_t b = 0; b + 1 < breaks.size(); ++b) {
    const Real t0 = breaks[b], t1 = breaks[b + 1];
    if (!(t1 - t0 > 1e-14)) continue;
    const Real tm = 0.5 * (t0 + t1);
    // The triangle under the piece's middle; its barycentric weights are linear, so evaluated at the piece's
    // ends they are the weights of those ends (even if rounding would have located them in the neighbour).
    const Real um = uA + tm * du, sm = sA + tm * ds;
    if (!(um >= 0 && sm >= 0 && um <= Real(nx_ - 1) && sm <= Real(ny_ - 1))) continue;  // off the field
    const size_t i = std::min(size_t(um), nx_ - 2), j = std::min(size_t(sm), ny_ - 2);
    const bool lower = um - Real(i) >= sm - Real(j);
    const size_t v00 = j * nx_ + i;
    const size_t v[3] = {v00, lower ? v00 + 1 : v00 + nx_, v00 + nx_ + 1};
    auto weights = [&](Real t, Real (&w)[3]) {
      const Real fu = uA + t * du - Real(i), fv = sA + t * ds - Real(j);
      if (lower) w[0] = 1 - fu, w[1] = fu - fv, w[2] = fv;
      else w[0] = 1 - fv, w[1] = fv - fu, w[2] = fu;
    };
    Real w0[3], wm[3], w1[3];
    weights(t0, w0);
    weights(tm, wm);
    weights(t1, w1);
    // Simpson's rule: exact for the quadratic (weight x linear density) on the piece.
    const Real f0 = noForce ? 0 : qf(t0), fm = noForce ? 0 : qf(tm), f1 = noForce ? 0 : qf(t1);
    const Real k0 = noStiff ? 0 : qk(t0), km = noStiff ? 0 : qk(tm), k1 = noStiff ? 0 : qk(t1);
    const Real h6 = (t1 - t0) / 6;
    for (int n = 0; n < 3; ++n)
      addVertexLoad(v[n], h6 * (w0[n] * f0 + 4 * wm[n] * fm + w1[n] * f1),
                    h6 * (w0[n] * k0 + 4 * wm[n] * km + w1[n] * k1));
  }
}

}  // namespace scree
