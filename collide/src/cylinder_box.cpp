// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Cylinder-box: a cylinder cap lying on a box face gets a full manifold (this analytic path: exact disc-rectangle
// candidates, faster than clipping the cap polygon); every other configuration goes through the support-feature
// manifold (convex_manifold.cpp: a cylinder lying on a face gets its side line clipped to the face), else keeps
// the single libccd point (ccd_adapter.cpp).
//
// Why: a single MPR point per step lets a cylinder standing on a box rock from rim point to rim point, and a
// suction cup (a short cylinder) pressed against a box could not hold the box level. When libccd's normal lies
// within ~2.6 deg of a box face normal and the cylinder axis within ~2.6 deg of the same normal (the same
// tolerance cylinder-plane uses), the contact region is the cap disc intersected with the face rectangle
// (both convex). Its candidate points are: 8 rim points at fixed angles in the cylinder frame that project
// inside the face, the face corners inside the disc, and the crossings of the face edges with the rim circle.
// Depths are measured along the face normal between the face plane and the (slightly tilted) cap plane;
// reduceManifold keeps 4. Feature ids: rim k -> k, corner c -> 8 + c, edge e crossing s -> 16 + 2 e + s.
#include <array>
#include <cmath>

#include "narrowphase_internal.h"

namespace scree::detail {

int collideCylinderBox(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
                       std::vector<ContactPoint>& out) {
  const size_t begin = out.size();
  const int n = collideCcd(s0, t0, s1, t1, margin, out);
  if (n != 1) return n;
  const ContactPoint single = out.back();
  // Every other configuration (a wheel lying on a face, a tilted cylinder on an edge): the support-feature
  // manifold (convex_manifold.cpp), else the single point.
  auto generic = [&]() { return manifoldOrSinglePoint(s0, t0, s1, t1, single, margin, out, begin); };

  const auto& cyl = static_cast<const Cylinder&>(s0);
  const Vec3& he = static_cast<const Box&>(s1).getHalfExtents();
  const Real r = cyl.getRadius(), hh = Real(0.5) * cyl.getHeight();
  const Vec3 w = t0.rotate(Vec3::UnitY());
  // Face of the box along libccd's normal (from box towards cylinder).
  const Vec3 nl = t1.rotateInverse(single.normal);
  int axis = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(nl[i]) > std::abs(nl[axis])) axis = i;
  const Real kParallel = std::cos(Real(0.045));
  if (std::abs(nl[axis]) < kParallel) return generic();
  const Real sgn = nl[axis] > 0 ? 1 : -1;
  const Vec3 fnLocal = Vec3::Unit(axis) * sgn;
  const Vec3 fn = t1.rotate(fnLocal);
  const Real wn = w.dot(fn);
  if (std::abs(wn) < kParallel) return generic();

  // Cap facing the box (its outward normal is about -fn) and the face plane fn . x = faceOffset.
  const Vec3 cc = t0.p - (wn > 0 ? 1 : -1) * hh * w;
  const Real faceOffset = fn.dot(t1.p) + he[axis];
  const int j = (axis + 1) % 3, k = (axis + 2) % 3;
  auto insideFace = [&](const Vec3& worldPoint) {
    const Vec3 q = t1.applyInverse(worldPoint);
    return std::abs(q[j]) <= he[j] * (1 + Real(1e-12)) && std::abs(q[k]) <= he[k] * (1 + Real(1e-12));
  };
  // Depth of the cap plane below the face at face point y (y on the face plane): walk along fn to the cap plane.
  auto capDepthAt = [&](const Vec3& y) { return -w.dot(cc - y) / wn; };

  out.pop_back();
  // Rim points.
  const Vec3 cl = t0.applyInverse(cc);
  for (int a = 0; a < 8; ++a) {
    const Real ang = Real(a) * Real(0.78539816339744830962);
    const Vec3 x = t0.apply(Vec3(cl.x() + r * std::cos(ang), cl.y(), cl.z() + r * std::sin(ang)));
    const Real depth = faceOffset - fn.dot(x);
    if (depth < -margin || !insideFace(x)) continue;
    out.push_back(makeContact(x + fn * (Real(0.5) * depth), fn, depth, uint32_t(a)));
  }
  // Face corners inside the disc, and edge crossings with the rim circle (the disc projected on the face).
  const Vec3 ccFace = cc + fn * (faceOffset - fn.dot(cc));
  std::array<Vec3, 4> corners;
  for (int c = 0; c < 4; ++c) {
    Vec3 q = fnLocal * he[axis];
    q[j] = (c == 0 || c == 3) ? -he[j] : he[j];
    q[k] = (c < 2) ? -he[k] : he[k];
    corners[c] = t1.apply(q);
  }
  auto emitFacePoint = [&](const Vec3& y, uint32_t fid) {
    const Real depth = capDepthAt(y);
    const Vec3 p = y - fn * (Real(0.5) * depth);
    // A rim point lying exactly on a face edge is also an edge crossing: keep one.
    if (depth < -margin || nearExisting(out, begin, p)) return;
    out.push_back(makeContact(p, fn, depth, fid));
  };
  for (int c = 0; c < 4; ++c)
    if ((corners[c] - ccFace).squaredNorm() <= r * r) emitFacePoint(corners[c], 8 + uint32_t(c));
  for (int e = 0; e < 4; ++e) {
    const Vec3 a = corners[e], d = corners[(e + 1) % 4] - a;
    const Vec3 m = a - ccFace;
    const Real dd = d.squaredNorm(), b = m.dot(d), disc = b * b - dd * (m.squaredNorm() - r * r);
    if (dd <= 0 || disc <= 0) continue;
    const Real sq = std::sqrt(disc);
    for (int s = 0; s < 2; ++s) {
      const Real t = (-b + (s == 0 ? -sq : sq)) / dd;
      if (t > 0 && t < 1) emitFacePoint(a + t * d, 16 + uint32_t(2 * e + s));
    }
  }
  if (out.size() == begin) {
    out.push_back(single);
    return 1;
  }
  levelDepths(out, begin, Real(1e-12) * (1 + cc.cwiseAbs().maxCoeff()));
  return reduceManifold(out, begin, 4, Real(1e-4) * r);
}

}  // namespace scree::detail
