// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Private helpers shared by the narrowphase files (narrowphase.cpp, box_box.cpp, convex_convex.cpp,
// heightfield_collide.cpp, ccd_adapter.cpp). Not installed.
//
// Every pair routine has the same signature: shapes and world transforms of geometry 0 and 1, the speculative
// margin, and the output vector. It appends points (normal from shape 1 towards shape 0, depth > 0 overlap,
// only depth >= -margin, at most 4) and returns how many it appended. The dispatch table in narrowphase.cpp
// calls a routine with its arguments swapped when the caller's order is the reverse of the routine's, and
// then flips the normals of the appended points.
#pragma once

#include <cstdint>
#include <algorithm>
#include <vector>

#include "scree/collide/shapes.h"
#include "scree/core/contact.h"
#include "scree/core/math.h"

namespace scree::detail {

using CollideFn = int (*)(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
                          std::vector<ContactPoint>& out);

inline ContactPoint makeContact(const Vec3& point, const Vec3& normal, Real depth, uint32_t featureId) {
  ContactPoint c;
  c.point = point;
  c.normal = normal;
  c.depth = depth;
  c.featureId = featureId;
  return c;
}

/// Keeps at most `maxPoints` of out[begin..end) (in place, deepest first): the deepest point, the one farthest
/// from it, then the two that span the largest signed area on either side of that segment (Gregorius, "Robust
/// Contact Creation for Physics Simulations", GDC 2015). Returns the number kept.
///
/// depthTieTolerance (m): points whose depth is within it of the deepest count as equally deep, and the first of
/// them in emission order starts the selection. A cap resting level on a face or on another cap has all its rim
/// points equally deep up to roundoff; without the tolerance the kept square turned from step to step (0, 15,
/// 30, 45 degrees ...) with new feature ids, the warm start matched nothing and cylinder towers rang and drifted
/// (test/test_extremes_stacks_cylinders.cpp). The cap routines pass 1e-4 x the cap radius (a tilt below 1e-4 rad
/// across the cap counts as level) and emit their rim points in an order fixed in the cylinder's frame.
int reduceManifold(std::vector<ContactPoint>& out, size_t begin, int maxPoints = 4, Real depthTieTolerance = 0);

/// Closest points between segments p1-q1 and p2-q2 (Ericson, RTCD 5.1.9): outS, outT in [0, 1].
void closestSegmentSegment(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2, Real& outS, Real& outT);

/// Closest point of segment a-b to p; returns the parameter in [0, 1].
inline Real closestOnSegment(const Vec3& a, const Vec3& b, const Vec3& p) {
  const Vec3 ab = b - a;
  const Real l2 = ab.squaredNorm();
  if (l2 <= 0) return 0;
  Real t = (p - a).dot(ab) / l2;
  return t < 0 ? 0 : (t > 1 ? 1 : t);
}

/// Triangle Voronoi region of a closest point: 0 face, 1..3 edges (ab, bc, ca), 4..6 vertices (a, b, c).
enum TriRegion : int { TRI_FACE = 0, TRI_EDGE_AB = 1, TRI_EDGE_BC = 2, TRI_EDGE_CA = 3, TRI_VERT_A = 4,
                       TRI_VERT_B = 5, TRI_VERT_C = 6 };
/// Closest point on triangle abc to p (Ericson, RTCD 5.1.5) and the region it lies in.
Vec3 closestPointTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, int& outRegion);

// --- convex polytopes (box adapter, Convex, height-field triangles) ------------------------------------------

/// A convex polytope in world coordinates. Faces list vertex indices counter-clockwise seen from outside.
struct Polytope {
  struct Face {
    uint32_t first = 0, count = 0;  ///< range in `indices`
    Vec3 normal;                    ///< outward unit
    Real offset = 0;                ///< normal . x on the face
  };
  std::vector<Vec3> verts;
  std::vector<uint32_t> indices;
  std::vector<Face> faces;
  std::vector<std::pair<uint32_t, uint32_t>> edges;  ///< unique edges (vertex index pairs)
  void clear() {
    verts.clear();
    indices.clear();
    faces.clear();
    edges.clear();
  }
};

/// Box as an 8-vertex polytope. Vertex k has sign bit (k >> a) & 1 on axis a; faces ordered +x,-x,+y,-y,+z,-z.
void makeBoxPolytope(const Vec3& halfExtents, const Transform& t, Polytope& out);
/// Convex hull placed in the world (faces from Convex::getFaces).
void makeConvexPolytope(const Convex& c, const Transform& t, Polytope& out);

/// SAT over face normals and edge-pair axes, then reference/incident face clipping (or the closest points of the
/// two supporting edges). Normal from B towards A. Feature ids come from the face (or edge) indices and the clip
/// labels, so a resting pair keeps them from step to step. Appends at most 4 points.
int collidePolytopes(const Polytope& a, const Polytope& b, Real margin, std::vector<ContactPoint>& out);

// --- clipping shared by box-box and polytopes ----------------------------------------------------------------

/// A vertex of the clipped incident polygon. Each vertex is the intersection of two "lines" (labels): incident
/// edges are 0..63 and reference side planes are 64 + k. The label pair identifies the point from step to step
/// (feature id). `out` is the label of the polygon edge that leaves this vertex.
struct ClipVertex {
  Vec3 p;
  uint8_t la, lb, out;
};

/// Incident polygon from `n` world vertices: vertex k sits between incident edges k-1 and k.
void initIncident(const Vec3* verts, int n, std::vector<ClipVertex>& poly);
/// Sutherland-Hodgman: clips `poly` by the side planes of the reference polygon `ref` (n vertices,
/// counter-clockwise about refNormal). `scratch` is reused storage.
void clipToReference(std::vector<ClipVertex>& poly, const Vec3* ref, int n, const Vec3& refNormal,
                     std::vector<ClipVertex>& scratch);
/// True when a point already appended since `begin` lies within 1e-9 m (scaled) of the clipped point x: clipping a
/// polygon whose vertices lie exactly on a side plane emits the same point twice.
inline bool nearExisting(const std::vector<ContactPoint>& out, size_t begin, const Vec3& x) {
  const Real tol = Real(1e-9) * (1 + x.cwiseAbs().maxCoeff());
  for (size_t k = begin; k < out.size(); ++k)
    if ((out[k].point - x).cwiseAbs().maxCoeff() <= tol) return true;
  return false;
}
/// 32-bit hash combine of two feature ids (a murmur3 finaliser on a simple fold): the high bits of a manifold's
/// persistent feature ids, shared by the hull-hull and the support-feature manifolds.
inline uint32_t hashFeatureIds(uint32_t a, uint32_t b) {
  uint32_t h = a * 0x9E3779B1u ^ (b + 0x7F4A7C15u + (a << 6) + (a >> 2));
  h ^= h >> 16;
  h *= 0x85EBCA6Bu;
  h ^= h >> 13;
  h *= 0xC2B2AE35u;
  h ^= h >> 16;
  return h;
}
/// A cap resting level: when the depths of out[begin, end) differ by at most `tol` (roundoff of the rim points'
/// rotation, e.g. +-5.6e-17 m on an upright cylinder), they are set to their mean. Without it an exactly level
/// cap placed touching got points at depth +5.6e-17 (overlap) and -5.6e-17 (a speculative gap) on opposite
/// sides, whose rows the solver treats differently: the cylinder tipped at the first step (v 1.3e-5 m/s).
/// A level mean within `tol` of 0 is 0 (touching: a spring row, no force until it sinks). Left at its roundoff
/// sign, -2.8e-17 m under the 2 m cylinders of test_extremes_stacks_cylinders made every ground row a
/// speculative stop, i.e. a rigid support that never sank: the tower's sink lacked the ground joint's compliance
/// term exactly, and the bottom joint was rigid where every other joint is a spring.
inline void levelDepths(std::vector<ContactPoint>& out, size_t begin, Real tol) {
  if (out.size() <= begin + 1) return;
  Real lo = out[begin].depth, hi = lo, sum = 0;
  for (size_t k = begin; k < out.size(); ++k) {
    lo = std::min(lo, out[k].depth);
    hi = std::max(hi, out[k].depth);
    sum += out[k].depth;
  }
  if (hi - lo > tol) return;
  Real mean = sum / Real(out.size() - begin);
  if (std::abs(mean) <= tol) mean = 0;
  for (size_t k = begin; k < out.size(); ++k) out[k].depth = mean;
}
/// Feature label of a clipped vertex (14 bits).
inline uint32_t clipLabel(const ClipVertex& v) {
  const uint32_t a = v.la & 127, b = v.lb & 127;
  return a < b ? (a << 7) | b : (b << 7) | a;
}

// --- pair routines (first shape type named first) -----------------------------------------------------------

int collideBoxBox(const Shape&, const Transform&, const Shape&, const Transform&, Real, std::vector<ContactPoint>&);
int collideConvexConvex(const Shape&, const Transform&, const Shape&, const Transform&, Real,
                        std::vector<ContactPoint>&);
int collideConvexBox(const Shape&, const Transform&, const Shape&, const Transform&, Real, std::vector<ContactPoint>&);
int collideConvexPlane(const Shape&, const Transform&, const Shape&, const Transform&, Real,
                       std::vector<ContactPoint>&);
/// libccd (MPR, then GJK/EPA) for any two convex shapes with support(); one point per call.
int collideCcd(const Shape&, const Transform&, const Shape&, const Transform&, Real, std::vector<ContactPoint>&);
/// Cylinder (shape 0) on a box: full manifold for a cap lying on a face, else the libccd point (cylinder_box.cpp).
int collideCylinderBox(const Shape&, const Transform&, const Shape&, const Transform&, Real,
                       std::vector<ContactPoint>&);

// --- support-feature manifolds (convex_manifold.cpp) ---------------------------------------------------------

/// Given the penetration normal n (from shape 1 towards shape 0) of two convex shapes, builds the manifold from
/// the two supporting features along it (face/cap polygon, segment, point), clipped against each other and
/// reduced to at most 4 points. Returns 0 (appending nothing) when either feature is a point or the features do
/// not overlap; the caller then keeps its single point.
int manifoldFromNormal(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, const Vec3& n,
                       Real margin, std::vector<ContactPoint>& out);
/// collideCcd, then manifoldFromNormal along its normal (the single point when no manifold results).
int collideCcdManifold(const Shape&, const Transform&, const Shape&, const Transform&, Real,
                       std::vector<ContactPoint>&);
/// out[begin, end) holds libccd's single point `single` (a copy: out is rewritten): replaces it by
/// manifoldFromNormal along its normal, or keeps it when no manifold results. Returns the number of points.
int manifoldOrSinglePoint(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1,
                          const ContactPoint single, Real margin, std::vector<ContactPoint>& out, size_t begin);

/// Shape vs height field: the normal points out of the height field (from shape 1 towards shape 0).
int collideSphereHeightField(const Shape&, const Transform&, const Shape&, const Transform&, Real,
                             std::vector<ContactPoint>&);
int collideCapsuleHeightField(const Shape&, const Transform&, const Shape&, const Transform&, Real,
                              std::vector<ContactPoint>&);
int collideBoxHeightField(const Shape&, const Transform&, const Shape&, const Transform&, Real,
                          std::vector<ContactPoint>&);
int collideConvexHeightField(const Shape&, const Transform&, const Shape&, const Transform&, Real,
                             std::vector<ContactPoint>&);
int collideCylinderHeightField(const Shape&, const Transform&, const Shape&, const Transform&, Real,
                               std::vector<ContactPoint>&);
int collideLineHeightField(const Shape&, const Transform&, const Shape&, const Transform&, Real,
                           std::vector<ContactPoint>&);

}  // namespace scree::detail
