// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// libccd adapter: the only file that includes libccd (docs/design.md §1).
//
// Used for the convex pairs without an analytic routine (cylinder-cylinder, cylinder-box, cylinder-capsule,
// cylinder-convex, sphere-convex, capsule-convex). One point per call; every pair but sphere-convex then takes
// its normal to convex_manifold.cpp, which builds the manifold from the two supporting features (a cap, side line
// or face resting on another gets up to 4 points; cylinder-box keeps its analytic cap-on-face path,
// cylinder_box.cpp).
//
// Debian's libccd is built with CCD_DOUBLE (ccd/config.h), so ccd_real_t is double like scree::Real; the
// static_assert below catches a single-precision build instead of silently truncating.
//
// Speculative contacts: libccd 2.x has no GJK distance query (ccdGJKSeparate returns the separation vector only for
// intersecting objects). Instead both supports are inflated by margin/2 (Minkowski sum with a ball): the
// penetration depth of the inflated pair is exactly the true depth + margin, both for overlapping pairs
// (the boundary of K + ball(m) lies m further out) and for separated pairs within the margin (where it equals
// margin - distance). So one MPR call yields depth = inflatedDepth - margin, overlapping or not.
//
// MPR first (fast, robust for smooth shapes), GJK+EPA when MPR returns a degenerate direction. Tolerances: MPR's
// portal tolerance 1e-9 m, EPA 1e-9, iteration cap 200. MPR converges linearly on curved boundaries, so depths
// and normals of curved pairs are accurate to ~1e-4 relative in practice (the tests use 1e-4).
#include <ccd/ccd.h>
#include <ccd/vec3.h>

#include <cmath>
#include <type_traits>

#include "narrowphase_internal.h"

static_assert(std::is_same_v<ccd_real_t, scree::Real>, "libccd must be built with CCD_DOUBLE");

namespace scree::detail {

namespace {

struct CcdObject {
  const Shape* shape;
  const Transform* t;
  Real inflate;  // radius of the ball added to the shape (margin / 2)
  Vec3 centre;   // world point inside the shape (MPR's interior point)
};

void ccdSupport(const void* obj, const ccd_vec3_t* dir, ccd_vec3_t* out) {
  const auto* o = static_cast<const CcdObject*>(obj);
  const Vec3 d(ccdVec3X(dir), ccdVec3Y(dir), ccdVec3Z(dir));
  Vec3 p = o->t->apply(o->shape->support(o->t->rotateInverse(d)));
  const Real len = d.norm();
  if (o->inflate > 0 && len > 0) p += d * (o->inflate / len);
  ccdVec3Set(out, p.x(), p.y(), p.z());
}

void ccdCenter(const void* obj, ccd_vec3_t* out) {
  const auto* o = static_cast<const CcdObject*>(obj);
  ccdVec3Set(out, o->centre.x(), o->centre.y(), o->centre.z());
}

/// A point inside the shape: the shape-frame origin is inside every Scree primitive except a Convex whose points
/// were not centred, so a Convex uses its vertex average.
Vec3 interiorPoint(const Shape& s, const Transform& t) {
  if (s.getType() == Shape::CONVEX) {
    const auto& v = static_cast<const Convex&>(s).getVertices();
    Vec3 c = Vec3::Zero();
    for (const Vec3& x : v) c += x;
    return t.apply(c / Real(v.size()));
  }
  if (s.getType() == Shape::LINE) {
    const auto& l = static_cast<const Line&>(s);
    return t.apply(Real(0.5) * (l.getFirstPoint() + l.getSecondPoint()));
  }
  return t.p;
}

bool finite(const Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

}  // namespace

int collideCcd(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
               std::vector<ContactPoint>& out) {
  const Real infl = Real(0.5) * margin;
  CcdObject o0{&s0, &t0, infl, interiorPoint(s0, t0)};
  CcdObject o1{&s1, &t1, infl, interiorPoint(s1, t1)};

  ccd_t ccd;
  CCD_INIT(&ccd);
  ccd.support1 = ccdSupport;
  ccd.support2 = ccdSupport;
  ccd.center1 = ccdCenter;
  ccd.center2 = ccdCenter;
  ccd.max_iterations = 200;
  ccd.mpr_tolerance = 1e-9;
  ccd.epa_tolerance = 1e-9;
  ccd.dist_tolerance = 1e-9;

  ccd_real_t depth = 0;
  ccd_vec3_t dir, pos;
  // "Penetration of obj2 into obj1": translating obj2 by depth * dir separates them, so dir points from
  // geometry 0 towards geometry 1 and our normal (from 1 towards 0) is -dir.
  int rc = ccdMPRPenetration(&o0, &o1, &ccd, &depth, &dir, &pos);
  if (rc != 0) return 0;  // no intersection of the inflated shapes: farther apart than the margin
  Vec3 d(ccdVec3X(&dir), ccdVec3Y(&dir), ccdVec3Z(&dir));
  Vec3 p(ccdVec3X(&pos), ccdVec3Y(&pos), ccdVec3Z(&pos));
  if (!finite(d) || !finite(p) || !std::isfinite(depth) || d.norm() < Real(0.5)) {
    // MPR degenerates when the interior points coincide with the contact (e.g. touching centres); GJK+EPA does
    // not rely on them.
    rc = ccdGJKPenetration(&o0, &o1, &ccd, &depth, &dir, &pos);
    if (rc != 0) return 0;
    d = Vec3(ccdVec3X(&dir), ccdVec3Y(&dir), ccdVec3Z(&dir));
    p = Vec3(ccdVec3X(&pos), ccdVec3Y(&pos), ccdVec3Z(&pos));
    if (!finite(d) || !finite(p) || !std::isfinite(depth) || d.norm() < Real(0.5)) return 0;
  }
  const Real trueDepth = depth - margin;
  if (trueDepth < -margin) return 0;
  out.push_back(makeContact(p, -d.normalized(), trueDepth, 0));
  return 1;
}

}  // namespace scree::detail
