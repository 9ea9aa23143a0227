// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Convex polytopes: convex-convex, convex-box (the box through an 8-vertex adapter), convex-plane, and the
// clipping helpers shared with box-box.
//
// SAT (Gregorius, "The Separating Axis Test between Convex Polyhedra", GDC 2013): face normals of both hulls,
// then cross products of every pair of distinct edge directions. Edge axes are measured with full support
// projections (max over A, min over B) instead of Gregorius' Gauss-map pruning: it costs O(dirsA * dirsB *
// (VA + VB)) but needs no adjacency and also works for the degenerate polytopes of height-field triangles. The
// hulls Scree collides are small (tens of vertices), so this is cheap enough; a Gauss-map prune is the upgrade
// path if large hulls show up in profiles.
//
// Contact creation as for boxes: reference face (the SAT face), incident face (the other hull's face most
// anti-parallel to it), Sutherland-Hodgman clipping by the reference face's side planes, points within the margin,
// reduced to 4. Edge axes give one point between the closest points of the two supporting edges.
//
// Feature ids: face contacts hash (reference side, reference face, incident face) into bits 14..30 and put the
// clip label in bits 0..13; edge contacts set bit 31 and hash the two edge indices. A hash collision only costs
// a warm start (ids are compared within one geometry pair).
#include <cmath>
#include <limits>

#include "narrowphase_internal.h"

namespace scree::detail {

namespace {

constexpr Real kRelTol = 0.05;
constexpr Real kAbsTol = 1e-5;

struct Projection {
  Real lo, hi;
};
Projection project(const std::vector<Vec3>& v, const Vec3& L) {
  Projection p{std::numeric_limits<Real>::max(), -std::numeric_limits<Real>::max()};
  for (const Vec3& x : v) {
    const Real d = L.dot(x);
    p.lo = std::min(p.lo, d);
    p.hi = std::max(p.hi, d);
  }
  return p;
}

/// Unique edge directions (unit) of a polytope, each with one representative edge.
void edgeDirections(const Polytope& p, std::vector<Vec3>& dirs) {
  dirs.clear();
  for (const auto& e : p.edges) {
    Vec3 d = p.verts[e.second] - p.verts[e.first];
    const Real len = d.norm();
    if (len < Real(1e-12)) continue;
    d /= len;
    bool dup = false;
    for (const Vec3& o : dirs)
      if (o.cross(d).squaredNorm() < Real(1e-12)) {
        dup = true;
        break;
      }
    if (!dup) dirs.push_back(d);
  }
}

/// Edge of p parallel to dir that lies farthest along L (sign = +1) or -L (sign = -1).
int supportingEdge(const Polytope& p, const Vec3& dir, const Vec3& L, Real sign) {
  int best = -1;
  Real bestV = -std::numeric_limits<Real>::max();
  for (size_t k = 0; k < p.edges.size(); ++k) {
    const Vec3 a = p.verts[p.edges[k].first], b = p.verts[p.edges[k].second];
    const Vec3 d = b - a;
    if (d.normalized().cross(dir).squaredNorm() > Real(1e-10)) continue;
    const Real v = sign * L.dot(a + b);
    if (v > bestV) {
      bestV = v;
      best = int(k);
    }
  }
  return best;
}

struct FaceQuery {
  Real sep = -std::numeric_limits<Real>::max();
  int face = -1;
};
FaceQuery queryFaces(const Polytope& a, const Polytope& b) {
  FaceQuery q;
  for (size_t f = 0; f < a.faces.size(); ++f) {
    const auto& F = a.faces[f];
    Real lo = std::numeric_limits<Real>::max();
    for (const Vec3& v : b.verts) lo = std::min(lo, F.normal.dot(v));
    const Real s = lo - F.offset;
    if (s > q.sep) {
      q.sep = s;
      q.face = int(f);
    }
  }
  return q;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
void initIncident(const Vec3* verts, int n, std::vector<ClipVertex>& poly) {
  poly.resize(size_t(n));
  for (int k = 0; k < n; ++k)
    poly[size_t(k)] = {verts[k], uint8_t((k + n - 1) % n & 63), uint8_t(k & 63), uint8_t(k & 63)};
}

void clipToReference(std::vector<ClipVertex>& poly, const Vec3* ref, int n, const Vec3& refNormal,
                     std::vector<ClipVertex>& scratch) {
  for (int k = 0; k < n && !poly.empty(); ++k) {
    // Side plane through reference edge k: outward normal edge x n (counter-clockwise polygon about n).
    const Vec3& r0 = ref[k];
    const Vec3 sn = (ref[(k + 1) % n] - r0).cross(refNormal);
    const Real so = sn.dot(r0);
    const uint8_t label = uint8_t(64 + (k & 63));
    scratch.clear();
    const size_t m = poly.size();
    // Each vertex's distance to the side plane is computed once and carried from edge to edge (the same
    // expression as for both ends before, so the same bits; box-box calls this for every face contact).
    const Real d0 = sn.dot(poly[0].p) - so;
    Real da = d0;
    for (size_t i = 0; i < m; ++i) {
      const ClipVertex& a = poly[i];
      const ClipVertex& b = poly[i + 1 < m ? i + 1 : 0];
      const Real db = i + 1 < m ? sn.dot(b.p) - so : d0;
      if (da <= 0) scratch.push_back(a);
      if ((da <= 0) != (db <= 0)) {
        // The crossing lies on the polygon edge a->b (label a.out) and on the side plane.
        const Real t = da / (da - db);
        ClipVertex x{a.p + t * (b.p - a.p), a.out, label, 0};
        // Leaving the half space: the next polygon edge runs along the side plane; entering: along a->b.
        x.out = da <= 0 ? label : a.out;
        scratch.push_back(x);
      }
      da = db;
    }
    poly.swap(scratch);
  }
}

void makeBoxPolytope(const Vec3& h, const Transform& t, Polytope& p) {
  static constexpr int kFaceVerts[6][4] = {{1, 3, 7, 5}, {0, 4, 6, 2}, {2, 6, 7, 3},
                                           {0, 1, 5, 4}, {4, 5, 7, 6}, {0, 2, 3, 1}};
  p.clear();
  const Mat3 R = t.q.toRotationMatrix();
  for (int k = 0; k < 8; ++k)
    p.verts.push_back(t.apply(Vec3((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(), (k & 4) ? h.z() : -h.z())));
  for (int f = 0; f < 6; ++f) {
    Polytope::Face F;
    F.first = uint32_t(p.indices.size());
    F.count = 4;
    for (int k = 0; k < 4; ++k) p.indices.push_back(uint32_t(kFaceVerts[f][k]));
    F.normal = R.col(f / 2) * ((f & 1) ? -1 : 1);
    F.offset = F.normal.dot(t.p) + h[f / 2];
    p.faces.push_back(F);
  }
  for (int a = 0; a < 3; ++a)
    for (int k = 0; k < 8; ++k)
      if (!((k >> a) & 1)) p.edges.emplace_back(uint32_t(k), uint32_t(k | (1 << a)));
}

void makeConvexPolytope(const Convex& c, const Transform& t, Polytope& p) {
  p.clear();
  for (const Vec3& v : c.getVertices()) p.verts.push_back(t.apply(v));
  for (const auto& f : c.getFaces()) {
    Polytope::Face F;
    F.first = uint32_t(p.indices.size());
    F.count = uint32_t(f.vertices.size());
    for (uint32_t i : f.vertices) p.indices.push_back(i);
    F.normal = t.rotate(f.normal);
    F.offset = f.offset + F.normal.dot(t.p);
    p.faces.push_back(F);
    // Each edge appears in two faces (once per direction); keep the copy with first < second.
    for (size_t k = 0; k < f.vertices.size(); ++k) {
      const uint32_t a = f.vertices[k], b = f.vertices[(k + 1) % f.vertices.size()];
      if (a < b) p.edges.emplace_back(a, b);
    }
  }
}

int collidePolytopes(const Polytope& A, const Polytope& B, Real margin, std::vector<ContactPoint>& out) {
  const FaceQuery fa = queryFaces(A, B);
  if (fa.face < 0 || fa.sep > margin) return 0;
  const FaceQuery fb = queryFaces(B, A);
  if (fb.face < 0 || fb.sep > margin) return 0;

  thread_local std::vector<Vec3> dirsA, dirsB;
  edgeDirections(A, dirsA);
  edgeDirections(B, dirsB);
  Real sepE = -std::numeric_limits<Real>::max();
  Vec3 nE = Vec3::Zero(), dA = Vec3::Zero(), dB = Vec3::Zero();
  for (const Vec3& ea : dirsA) {
    for (const Vec3& eb : dirsB) {
      Vec3 L = ea.cross(eb);
      const Real len = L.norm();
      if (len < Real(1e-6)) continue;
      L /= len;
      const Projection pa = project(A.verts, L), pb = project(B.verts, L);
      const Real s1 = pb.lo - pa.hi;  // B on the +L side of A
      const Real s2 = pa.lo - pb.hi;  // B on the -L side
      const Real s = std::max(s1, s2);
      if (s > margin) return 0;
      if (s > sepE) {
        sepE = s;
        nE = s1 >= s2 ? L : Vec3(-L);
        dA = ea;
        dB = eb;
      }
    }
  }

  const bool refIsB = fb.sep > fa.sep + kRelTol * std::abs(fa.sep) + kAbsTol;
  const Real faceSep = refIsB ? fb.sep : fa.sep;
  if (sepE > faceSep + kRelTol * std::abs(faceSep) + kAbsTol) {
    const int ea = supportingEdge(A, dA, nE, 1), eb = supportingEdge(B, dB, nE, -1);
    if (ea >= 0 && eb >= 0) {
      const Vec3 a0 = A.verts[A.edges[ea].first], a1 = A.verts[A.edges[ea].second];
      const Vec3 b0 = B.verts[B.edges[eb].first], b1 = B.verts[B.edges[eb].second];
      Real s, t;
      closestSegmentSegment(a0, a1, b0, b1, s, t);
      const Vec3 ca = a0 + s * (a1 - a0), cb = b0 + t * (b1 - b0);
      out.push_back(makeContact(Real(0.5) * (ca + cb), -nE, -sepE, 0x80000000u | (hashFeatureIds(uint32_t(ea), uint32_t(eb)) >> 1)));
      return 1;
    }
  }

  // --- face contact ---------------------------------------------------------------------------------------------
  const Polytope& R = refIsB ? B : A;
  const Polytope& I = refIsB ? A : B;
  const int fr = refIsB ? fb.face : fa.face;
  const Polytope::Face& RF = R.faces[size_t(fr)];
  const Vec3 nRef = RF.normal;
  int fi = 0;
  Real best = std::numeric_limits<Real>::max();
  for (size_t f = 0; f < I.faces.size(); ++f) {
    const Real d = I.faces[f].normal.dot(nRef);
    if (d < best) {
      best = d;
      fi = int(f);
    }
  }
  const Polytope::Face& IF = I.faces[size_t(fi)];
  thread_local std::vector<Vec3> ref, inc;
  thread_local std::vector<ClipVertex> poly, scratch;
  ref.clear();
  inc.clear();
  for (uint32_t k = 0; k < RF.count; ++k) ref.push_back(R.verts[R.indices[RF.first + k]]);
  for (uint32_t k = 0; k < IF.count; ++k) inc.push_back(I.verts[I.indices[IF.first + k]]);
  initIncident(inc.data(), int(inc.size()), poly);
  clipToReference(poly, ref.data(), int(ref.size()), nRef, scratch);

  const Vec3 normal = refIsB ? nRef : Vec3(-nRef);
  const uint32_t base = hashFeatureIds(hashFeatureIds(uint32_t(refIsB), uint32_t(fr)), uint32_t(fi)) & 0x7FFFC000u;
  const size_t begin = out.size();
  for (const ClipVertex& v : poly) {
    const Real sep = nRef.dot(v.p) - RF.offset;
    const Vec3 p = v.p - nRef * (Real(0.5) * sep);
    if (sep > margin || nearExisting(out, begin, p)) continue;
    out.push_back(makeContact(p, normal, -sep, base | clipLabel(v)));
  }
  return reduceManifold(out, begin, 4);
}

// ---------------------------------------------------------------------------------------------------------------
int collideConvexConvex(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
                        std::vector<ContactPoint>& out) {
  thread_local Polytope a, b;
  makeConvexPolytope(static_cast<const Convex&>(s0), t0, a);
  makeConvexPolytope(static_cast<const Convex&>(s1), t1, b);
  return collidePolytopes(a, b, margin, out);
}

int collideConvexBox(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
                     std::vector<ContactPoint>& out) {
  thread_local Polytope a, b;
  makeConvexPolytope(static_cast<const Convex&>(s0), t0, a);
  makeBoxPolytope(static_cast<const Box&>(s1).getHalfExtents(), t1, b);
  return collidePolytopes(a, b, margin, out);
}

int collideConvexPlane(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
                       std::vector<ContactPoint>& out) {
  const auto& c = static_cast<const Convex&>(s0);
  const auto& pl = static_cast<const Plane&>(s1);
  const Vec3 n = t1.rotate(pl.getNormal());
  const Real d = pl.getDistance() + n.dot(t1.p);
  const size_t begin = out.size();
  const auto& verts = c.getVertices();
  for (size_t k = 0; k < verts.size(); ++k) {
    const Vec3 x = t0.apply(verts[k]);
    const Real depth = d - n.dot(x);
    if (depth >= -margin) out.push_back(makeContact(x + n * (Real(0.5) * depth), n, depth, uint32_t(k)));
  }
  return reduceManifold(out, begin, 4);
}

}  // namespace scree::detail
