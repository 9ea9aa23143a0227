// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Box-box: separating-axis test over the 15 axes (3 + 3 face normals, 9 edge-edge cross products; Gottschalk's
// OBB test as given in Ericson, RTCD 4.4.1), then a contact manifold:
//  - face axis: the reference face is the chosen box's face along the axis, the incident face the other box's
//    face most anti-parallel to it; the incident quad is clipped by the reference face's four side planes
//    (Sutherland-Hodgman), points more than `margin` above the reference face are dropped, and at most four are
//    kept (deepest, farthest, largest area on each side; reduceManifold).
//  - edge axis: one point midway between the closest points of the two supporting edges.
//
// Axis choice is biased (Gregorius, "The Separating Axis Test between Convex Polyhedra", GDC 2013; Catto's
// Box2D uses the same idea): face axes within 5% (+ an absolute 1e-5 m) of each other count as tied and the
// larger face is the reference, and an edge axis must beat the best face by the same margin. Without it the reference face flips between nearly equal axes from step
// to step, the feature ids change and warm starting is lost.
//
// Feature ids: face contacts  (refIsBox1 << 30) | (refFace << 26) | (incidentFace << 22) | clip label (14 bits),
//              edge contacts  (1 << 31) | (edge0 axis * 3 + edge1 axis) << 8 | sign bits of the two edges.
#include <algorithm>
#include <cmath>
#include <limits>

#include "narrowphase_internal.h"

namespace scree::detail {

namespace {

constexpr Real kRelTol = 0.05;
constexpr Real kAbsTol = 1e-5;

// Face vertex tables shared with makeBoxPolytope: vertex k has sign bit (k >> a) & 1 on axis a; face f = 2*axis +
// (negative side), vertices counter-clockwise seen from outside.
constexpr int kFaceVerts[6][4] = {{1, 3, 7, 5}, {0, 4, 6, 2}, {2, 6, 7, 3}, {0, 1, 5, 4}, {4, 5, 7, 6}, {0, 2, 3, 1}};

Vec3 boxVertex(const Vec3& c, const Mat3& R, const Vec3& h, int k) {
  return c + R.col(0) * ((k & 1) ? h.x() : -h.x()) + R.col(1) * ((k & 2) ? h.y() : -h.y()) +
         R.col(2) * ((k & 4) ? h.z() : -h.z());
}

}  // namespace

int collideBoxBox(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
                  std::vector<ContactPoint>& out) {
  const Vec3& ha = static_cast<const Box&>(s0).getHalfExtents();
  const Vec3& hb = static_cast<const Box&>(s1).getHalfExtents();
  const Mat3 Ra = t0.q.toRotationMatrix(), Rb = t1.q.toRotationMatrix();
  const Vec3 d = t1.p - t0.p;  // from box 0 to box 1
  const Mat3 C = Ra.transpose() * Rb;  // C(i, j) = a_i . b_j
  const Mat3 absC = C.cwiseAbs();
  const Vec3 da = Ra.transpose() * d, db = Rb.transpose() * d;

  // --- face axes -------------------------------------------------------------------------------------------
  Real sepA = -std::numeric_limits<Real>::max(), sepB = sepA;
  int axA = 0, axB = 0;
  for (int i = 0; i < 3; ++i) {
    const Real s = std::abs(da[i]) - ha[i] - absC.row(i).dot(hb);
    if (s > sepA) {
      sepA = s;
      axA = i;
    }
  }
  if (sepA > margin) return 0;
  for (int j = 0; j < 3; ++j) {
    const Real s = std::abs(db[j]) - hb[j] - absC.col(j).dot(ha);
    if (s > sepB) {
      sepB = s;
      axB = j;
    }
  }
  if (sepB > margin) return 0;

  // --- edge axes a_i x b_j ---------------------------------------------------------------------------------
  Real sepE = -std::numeric_limits<Real>::max();
  int eI = -1, eJ = -1;
  Vec3 nE = Vec3::Zero();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      Vec3 L = Ra.col(i).cross(Rb.col(j));
      const Real len = L.norm();
      if (len < Real(1e-6)) continue;  // parallel edges: the face axes cover this direction
      L /= len;
      const Real pa = ha.dot((Ra.transpose() * L).cwiseAbs()), pb = hb.dot((Rb.transpose() * L).cwiseAbs());
      const Real dl = L.dot(d);
      const Real s = std::abs(dl) - pa - pb;
      if (s > margin) return 0;
      if (s > sepE) {
        sepE = s;
        eI = i;
        eJ = j;
        nE = dl >= 0 ? L : Vec3(-L);
      }
    }
  }

  // --- pick the axis, preferring box 0's faces, then box 1's faces, then edges -----------------------------
  // Nearly tied face axes (a box resting flat on another): the larger face becomes the reference. That is also
  // the face that wins as soon as the smaller box wobbles (tilting the small box lowers the separation along its
  // own axis in proportion to the big box's width), so the choice does not flip at rest.
  bool refIsB;
  if (std::abs(sepA - sepB) <= kRelTol * std::max(std::abs(sepA), std::abs(sepB)) + kAbsTol) {
    const Real areaA = ha[(axA + 1) % 3] * ha[(axA + 2) % 3], areaB = hb[(axB + 1) % 3] * hb[(axB + 2) % 3];
    refIsB = areaB > areaA * (1 + kRelTol);
  } else {
    refIsB = sepB > sepA;
  }
  const Real faceSep = refIsB ? sepB : sepA;
  if (eI >= 0 && sepE > faceSep + kRelTol * std::abs(faceSep) + kAbsTol) {
    // Supporting edges: box 0's edge along a_i farthest along nE, box 1's edge along b_j farthest along -nE.
    Vec3 pa = t0.p, pb = t1.p;
    uint32_t bitsA = 0, bitsB = 0;
    for (int k = 0; k < 3; ++k) {
      if (k != eI) {
        const Real s = Ra.col(k).dot(nE) >= 0 ? 1 : -1;
        pa += Ra.col(k) * (s * ha[k]);
        bitsA = (bitsA << 1) | (s > 0 ? 1u : 0u);
      }
      if (k != eJ) {
        const Real s = Rb.col(k).dot(nE) <= 0 ? 1 : -1;
        pb += Rb.col(k) * (s * hb[k]);
        bitsB = (bitsB << 1) | (s > 0 ? 1u : 0u);
      }
    }
    const Vec3 a0 = pa - Ra.col(eI) * ha[eI], a1 = pa + Ra.col(eI) * ha[eI];
    const Vec3 b0 = pb - Rb.col(eJ) * hb[eJ], b1 = pb + Rb.col(eJ) * hb[eJ];
    Real s, t;
    closestSegmentSegment(a0, a1, b0, b1, s, t);
    const Vec3 ca = a0 + s * (a1 - a0), cb = b0 + t * (b1 - b0);
    // Depth from the SAT separation (exact for crossing edges); the closest points only place the contact.
    const uint32_t fid = (1u << 31) | (uint32_t(eI * 3 + eJ) << 8) | (bitsA << 2) | bitsB;
    out.push_back(makeContact(Real(0.5) * (ca + cb), -nE, -sepE, fid));
    return 1;
  }

  // --- face contact ------------------------------------------------------------------------------------------
  const Mat3& Rr = refIsB ? Rb : Ra;
  const Mat3& Ri = refIsB ? Ra : Rb;
  const Vec3& hr = refIsB ? hb : ha;
  const Vec3& hi = refIsB ? ha : hb;
  const Vec3& cr = refIsB ? t1.p : t0.p;
  const Vec3& ci = refIsB ? t0.p : t1.p;
  const int ax = refIsB ? axB : axA;
  const Vec3 toInc = ci - cr;
  const Real sgn = Rr.col(ax).dot(toInc) >= 0 ? 1 : -1;
  const Vec3 nRef = Rr.col(ax) * sgn;  // outward from the reference box towards the incident one
  const int refFace = 2 * ax + (sgn > 0 ? 0 : 1);
  // Incident face: the face of the other box whose outward normal is most anti-parallel to nRef.
  int incAx = 0;
  Real best = -1;
  for (int k = 0; k < 3; ++k) {
    const Real dd = std::abs(Ri.col(k).dot(nRef));
    if (dd > best) {
      best = dd;
      incAx = k;
    }
  }
  const int incFace = 2 * incAx + (Ri.col(incAx).dot(nRef) > 0 ? 1 : 0);

  Vec3 ref[4], inc[4];
  for (int k = 0; k < 4; ++k) {
    ref[k] = boxVertex(cr, Rr, hr, kFaceVerts[refFace][k]);
    inc[k] = boxVertex(ci, Ri, hi, kFaceVerts[incFace][k]);
  }
  thread_local std::vector<ClipVertex> poly, scratch;
  initIncident(inc, 4, poly);
  clipToReference(poly, ref, 4, nRef, scratch);

  const Real refOffset = nRef.dot(ref[0]);
  const Vec3 normal = refIsB ? nRef : Vec3(-nRef);  // from box 1 towards box 0
  const size_t begin = out.size();
  const uint32_t base = (uint32_t(refIsB) << 30) | (uint32_t(refFace) << 26) | (uint32_t(incFace) << 22);
  for (const ClipVertex& v : poly) {
    const Real sep = nRef.dot(v.p) - refOffset;  // incident point above (> 0) or below the reference face
    const Vec3 p = v.p - nRef * (Real(0.5) * sep);
    if (sep > margin || nearExisting(out, begin, p)) continue;
    out.push_back(makeContact(p, normal, -sep, base | clipLabel(v)));
  }
  return reduceManifold(out, begin, 4);
}

}  // namespace scree::detail
