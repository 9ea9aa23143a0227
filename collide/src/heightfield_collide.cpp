// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Shapes against a HeightField. All work happens in the height field's frame (so rotated and translated height
// fields behave like the axis-aligned one) and results are rotated back to the world.
//
// Triangulation (shapes.h): vertex (i, j) at (-sizeX/2 + i dx, -sizeY/2 + j dy, h(i, j)); cell (i, j) holds
// triangle 0 = (i,j),(i+1,j),(i+1,j+1) and triangle 1 = (i,j),(i+1,j+1),(i,j+1), both counter-clockwise from above
// (+z), so their normals point out of the solid. Triangle index = 2 (j (nx-1) + i) + t.
//
// Sphere (and the capsule's sphere sites): exact closest feature per triangle (Ericson 5.1.5). Face regions use
// the triangle normal. An edge or vertex contact is kept only when the sphere centre lies in that feature's
// Voronoi region of the whole surface, i.e. the neighbouring triangles find the same closest point; that removes
// the "internal edge" contacts of flat or concave joins, makes convex ridges give the edge normal (c - q)/|c - q|,
// which turns continuously from one face normal to the next as a sphere rolls over, and the lowest-index triangle
// owns a shared edge or vertex so it is reported once. Feature id = triangle * 8 + region (0 face, 1..3 edges,
// 4..6 vertices); the capsule uses triangle * 8 + site (0, 1 end spheres, 2 the segment's closest point).
//
// Box and convex: exact SAT per triangle under the shape's footprint (height-field frame): the triangle
// normal (+n only: solid below), the shape's face normals, and triangle edge x shape edge directions. Internal
// edges: an axis other than the triangle normal is only accepted as the contact normal when it lies in the normal
// cone of the triangle feature supporting it (validNormal: every neighbouring grid vertex on or below the plane
// through that face, edge or vertex), so a flat or concave join only ever gives the face normal and a convex
// ridge gives normals between its two faces; any axis still counts for separation. Ties prefer the triangle
// normal, then shape faces, then edges (5% + 1e-7 hysteresis as in convex_convex.cpp). Points: triangle normal ->
// the shape face most anti-parallel to it clipped by the triangle (crossings of a flat internal join dropped: the
// neighbour continues the region); shape face -> the triangle clipped by that face; edge axis -> midpoint of the
// closest points of the two edges. Points of all triangles are merged (first, i.e. lowest triangle, wins a
// duplicate position) and reduced; id = triangle * 8 + local (a 3-bit hash of face and clip label, 7 for edges).
// Cylinder: its true circle, no polygonal stand-in (see "cylinder against the triangles" below for the axes and
// points). Per triangle an SAT over the face normal, the cap normal and, for each triangle edge that is not a flat
// internal join, the normal at the edge point of least signed distance to the cylinder (a convex 1D minimum, in
// closed form unless the point is near a rim). The cylinder's support along any axis is exact, so depths are exact
// on faces, edges and vertices (edge against the curved side, a vertex anywhere, an edge against a rim when apart);
// only an edge pressed into a rim is measured along the side or cap normal there, not along the true common
// normal of edge and circle (the overlap along a nearby axis: an over-estimate while it lasts, exact again once the
// speculative contact parts them or they touch). Manifold: a lying cylinder gives the two
// ends of its line of contact, an upright one 4 rim points fixed in its frame; both get ids from the cylinder's
// own features, and each such point is reported by the one triangle whose footprint holds it, so ids survive
// the cylinder's moving from cell to cell (warm starting). The capsule needs nothing of the sort: its sphere
// sites are exact.
// All pairs reduce to at most 4 points, deepest first.
#include <algorithm>
#include <cmath>
#include <limits>

#include "narrowphase_internal.h"

namespace scree::detail {

namespace {

struct Grid {
  const HeightField& hf;
  long nx, ny;
  Real dx, dy, x0, y0;
  explicit Grid(const HeightField& h)
      : hf(h), nx(long(h.getResolutionX())), ny(long(h.getResolutionY())), dx(h.getCellSizeX()),
        dy(h.getCellSizeY()), x0(-Real(0.5) * h.getSizeX()), y0(-Real(0.5) * h.getSizeY()) {}
  Vec3 vert(long i, long j) const { return {x0 + Real(i) * dx, y0 + Real(j) * dy, hf.getHeight(size_t(i), size_t(j))}; }
  bool validCell(long i, long j) const { return i >= 0 && j >= 0 && i < nx - 1 && j < ny - 1; }
  uint32_t triIndex(long i, long j, int t) const { return uint32_t((j * (nx - 1) + i) * 2 + t); }
  /// Grid coordinates of the three vertices of triangle t of cell (i, j).
  void triVerts(long i, long j, int t, long (&v)[3][2]) const {
    v[0][0] = i;
    v[0][1] = j;
    if (t == 0) {
      v[1][0] = i + 1, v[1][1] = j, v[2][0] = i + 1, v[2][1] = j + 1;
    } else {
      v[1][0] = i + 1, v[1][1] = j + 1, v[2][0] = i, v[2][1] = j + 1;
    }
  }
  /// Cell range covering [lo, hi] in x and y; false when it misses the grid.
  bool cellRange(const Vec3& lo, const Vec3& hi, long& i0, long& i1, long& j0, long& j1) const {
    const Real fx0 = (lo.x() - x0) / dx, fx1 = (hi.x() - x0) / dx;
    const Real fy0 = (lo.y() - y0) / dy, fy1 = (hi.y() - y0) / dy;
    if (fx1 < 0 || fy1 < 0 || fx0 > Real(nx - 1) || fy0 > Real(ny - 1)) return false;
    i0 = std::max<long>(0, long(std::floor(fx0)));
    j0 = std::max<long>(0, long(std::floor(fy0)));
    i1 = std::min<long>(nx - 2, long(std::floor(fx1)));
    j1 = std::min<long>(ny - 2, long(std::floor(fy1)));
    return i0 <= i1 && j0 <= j1;
  }
  /// Triangle whose footprint contains (x, y); false outside the grid.
  bool locate(Real x, Real y, long& i, long& j, int& t) const {
    const Real fx = (x - x0) / dx, fy = (y - y0) / dy;
    if (fx < 0 || fy < 0 || fx > Real(nx - 1) || fy > Real(ny - 1)) return false;
    i = std::min<long>(nx - 2, long(fx));
    j = std::min<long>(ny - 2, long(fy));
    t = (fx - Real(i)) >= (fy - Real(j)) ? 0 : 1;  // triangle 0 lies below the diagonal (fx >= fy)
    return true;
  }
};

struct Tri {
  long v[3][2];
  Vec3 a, b, c, n;
  uint32_t index;
};

Tri makeTri(const Grid& g, long i, long j, int t) {
  Tri T;
  g.triVerts(i, j, t, T.v);
  T.a = g.vert(T.v[0][0], T.v[0][1]);
  T.b = g.vert(T.v[1][0], T.v[1][1]);
  T.c = g.vert(T.v[2][0], T.v[2][1]);
  T.n = (T.b - T.a).cross(T.c - T.a).normalized();
  T.index = g.triIndex(i, j, t);
  return T;
}

/// Neighbouring triangle across edge region 1..3 of triangle t of cell (i, j) (see the file comment).
bool edgeNeighbour(const Grid& g, long i, long j, int t, int region, long& ni, long& nj, int& nt) {
  static constexpr int kOff[2][3][2] = {{{0, -1}, {1, 0}, {0, 0}}, {{0, 0}, {0, 1}, {-1, 0}}};
  ni = i + kOff[t][region - 1][0];
  nj = j + kOff[t][region - 1][1];
  nt = 1 - t;
  return g.validCell(ni, nj);
}

/// Is the closest surface point of triangle (i, j, t) to c, found in an edge or vertex region, also the closest
/// point of every other triangle sharing that feature, and is this triangle the feature's owner (lowest index)?
bool featureOwnedAndValid(const Grid& g, long i, long j, int t, int region, const Vec3& c, const Vec3& q,
                          uint32_t myIndex) {
  const Real tol = Real(1e-9) * (g.dx + g.dy);
  int reg;
  if (region >= TRI_EDGE_AB && region <= TRI_EDGE_CA) {
    long ni, nj;
    int nt;
    if (!edgeNeighbour(g, i, j, t, region, ni, nj, nt)) return true;  // boundary edge
    const Tri N = makeTri(g, ni, nj, nt);
    const Vec3 q2 = closestPointTriangle(c, N.a, N.b, N.c, reg);
    if ((q2 - q).norm() > tol) return false;
    return myIndex < N.index;
  }
  // Vertex: every triangle around it.
  long vv[3][2];
  g.triVerts(i, j, t, vv);
  const long vi = vv[region - TRI_VERT_A][0], vj = vv[region - TRI_VERT_A][1];
  for (long cj = vj - 1; cj <= vj; ++cj) {
    for (long ci = vi - 1; ci <= vi; ++ci) {
      if (!g.validCell(ci, cj)) continue;
      for (int ct = 0; ct < 2; ++ct) {
        const Tri N = makeTri(g, ci, cj, ct);
        bool has = false;
        for (auto& p : N.v) has |= (p[0] == vi && p[1] == vj);
        if (!has || N.index == myIndex) continue;
        const Vec3 q2 = closestPointTriangle(c, N.a, N.b, N.c, reg);
        if ((q2 - q).norm() > tol) return false;
        if (N.index < myIndex) return false;
      }
    }
  }
  return true;
}

/// Sphere (c, r) against triangle (i, j, t), height-field frame. Appends (local frame) and returns true on a
/// contact within the margin. `fidLocal` < 0 uses the region as local feature.
bool sphereTriangle(const Grid& g, long i, long j, int t, const Vec3& c, Real r, Real margin, int fidLocal,
                    std::vector<ContactPoint>& out) {
  const Tri T = makeTri(g, i, j, t);
  int region;
  const Vec3 q = closestPointTriangle(c, T.a, T.b, T.c, region);
  Vec3 n;
  Real depth;
  if (region == TRI_FACE) {
    const Real sep = T.n.dot(c - T.a);
    depth = r - sep;
    n = T.n;
  } else {
    const Vec3 d = c - q;
    const Real dist = d.norm();
    depth = r - dist;
    if (depth < -margin) return false;
    if (d.dot(T.n) < 0) return false;  // below this triangle: a neighbour's face region handles it
    if (!featureOwnedAndValid(g, i, j, t, region, c, q, T.index)) return false;
    n = dist > Real(1e-12) ? Vec3(d / dist) : T.n;
  }
  if (depth < -margin) return false;
  // Midway between the sphere surface point c - n r and the surface point c - n (r - depth).
  const Vec3 p = c - n * (r - Real(0.5) * depth);
  out.push_back(makeContact(p, n, depth, T.index * 8 + uint32_t(fidLocal < 0 ? region : fidLocal)));
  return true;
}

/// Local height-field frame results -> world.
int finish(std::vector<ContactPoint>& out, size_t begin, const Transform& thf) {
  for (size_t k = begin; k < out.size(); ++k) {
    out[k].point = thf.apply(out[k].point);
    out[k].normal = thf.rotate(out[k].normal);
  }
  return reduceManifold(out, begin, 4);
}

/// The shape's local AABB in the height-field frame, inflated by the margin; false when it cannot touch.
bool footprint(const Shape& s, const Transform& rel, const Grid& g, Real margin, long& i0, long& i1, long& j0,
               long& j1) {
  Aabb box = s.getBoundingBox(rel);
  box.inflate(margin);
  if (box.lo.z() > g.hf.getMaxHeight()) return false;
  return g.cellRange(box.lo, box.hi, i0, i1, j0, j1);
}

// --- exact per-triangle SAT for box / convex / cylinder ---------------------------------------------------------

constexpr Real kRelTol = 0.05;  // an axis must beat the preferred one by this much (relative) ...
constexpr Real kAbsTol = 1e-7;  // ... plus this (absolute), so ties keep the triangle normal

/// Unique unit edge directions of a polytope.
void uniqueEdgeDirs(const Polytope& P, std::vector<Vec3>& dirs) {
  dirs.clear();
  for (const auto& e : P.edges) {
    Vec3 d = P.verts[e.second] - P.verts[e.first];
    const Real len = d.norm();
    if (len < Real(1e-12)) continue;
    d /= len;
    bool dup = false;
    for (const Vec3& o : dirs) dup = dup || o.cross(d).squaredNorm() < Real(1e-12);
    if (!dup) dirs.push_back(d);
  }
}

/// Opposite vertex of the neighbour across edge `k` (0 ab, 1 bc, 2 ca) of triangle (i, j, t); false on the border.
bool neighbourApex(const Grid& g, long i, long j, int t, int k, Vec3& w) {
  long ni, nj;
  int nt;
  if (!edgeNeighbour(g, i, j, t, k + 1, ni, nj, nt)) return false;
  const Tri N = makeTri(g, ni, nj, nt);
  long tv[3][2];
  g.triVerts(i, j, t, tv);
  const Vec3 nv[3] = {N.a, N.b, N.c};
  for (int m = 0; m < 3; ++m) {
    bool shared = false;
    for (const auto& p : tv) shared = shared || (p[0] == N.v[m][0] && p[1] == N.v[m][1]);
    if (!shared) {
      w = nv[m];
      return true;
    }
  }
  return false;
}

/// Is edge k of the triangle an internal flat join (the neighbour lies in the same plane)?
bool flatJoin(const Grid& g, long i, long j, int t, const Tri& T, int k, Real tol) {
  Vec3 w;
  if (!neighbourApex(g, i, j, t, k, w)) return false;
  return std::abs(T.n.dot(w - T.a)) <= tol;
}

/// Is L (unit, from the height field towards the shape) a valid surface normal at the triangle's feature that
/// supports it? The feature (face, edge or vertex: the triangle points farthest along L) must be the support of
/// the whole local surface along L, i.e. every neighbouring grid vertex lies on or below the plane through the
/// feature with normal L. That is the Gauss-map cone test: for an edge, L lies between the two triangle normals
/// of a convex join (none for a flat or concave join but the face normal); for a vertex, in its normal cone.
bool validNormal(const Grid& g, long i, long j, int t, const Tri& T, const Vec3& L, Real tol) {
  if (L.dot(T.n) <= Real(1e-9)) return false;
  const Vec3 v[3] = {T.a, T.b, T.c};
  const Real h[3] = {L.dot(T.a), L.dot(T.b), L.dot(T.c)};
  const Real hi = std::max({h[0], h[1], h[2]});
  bool sup[3];
  int count = 0;
  for (int m = 0; m < 3; ++m) count += (sup[m] = h[m] >= hi - tol) ? 1 : 0;
  if (count == 3) return L.dot(T.n) >= 1 - Real(1e-9);
  if (count == 2) {
    const int k = !sup[0] ? 1 : (!sup[1] ? 2 : 0);  // edge (k, k+1) holds the two supporting vertices
    Vec3 w;
    if (!neighbourApex(g, i, j, t, k, w)) return true;
    return L.dot(w - v[k]) <= tol;
  }
  const int m = sup[0] ? 0 : (sup[1] ? 1 : 2);
  static constexpr int kNb[6][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, -1}};
  for (const auto& o : kNb) {
    const long ni = T.v[m][0] + o[0], nj = T.v[m][1] + o[1];
    if (ni < 0 || nj < 0 || ni >= g.nx || nj >= g.ny) continue;
    if (L.dot(g.vert(ni, nj) - v[m]) > tol) return false;
  }
  return true;
}

uint32_t localId(uint32_t a, uint32_t b) {
  uint32_t h = a * 0x9E3779B1u ^ (b * 0x85EBCA6Bu + 0x7F4A7C15u);
  h ^= h >> 15;
  return h & 7u;
}

/// Triangle (i, j, t) against polytope P (height-field frame). Appends points (deduplicated against
/// out[begin..)).
void polytopeTriangle(const Grid& g, long i, long j, int t, const Polytope& P, const std::vector<Vec3>& dirs,
                      Real margin, size_t begin, std::vector<ContactPoint>& out) {
  const Tri T = makeTri(g, i, j, t);
  const Vec3 tv[3] = {T.a, T.b, T.c};
  const Real scale = g.dx + g.dy + std::abs(T.a.z());
  const Real tol = Real(1e-9) * scale;
  // 1. triangle normal (always valid; the height field is solid below, so only +n).
  Real sepN = std::numeric_limits<Real>::max();
  for (const Vec3& v : P.verts) sepN = std::min(sepN, T.n.dot(v - T.a));
  if (sepN > margin) return;
  int kind = 0, fBest = -1, eTri = -1;
  Vec3 N = T.n, eDir = Vec3::Zero();
  Real best = sepN;
  // 2. polytope face normals: the triangle outside face f, normal -m.
  for (size_t f = 0; f < P.faces.size(); ++f) {
    const auto& F = P.faces[f];
    Real s = std::numeric_limits<Real>::max();
    for (const Vec3& x : tv) s = std::min(s, F.normal.dot(x) - F.offset);
    if (s > margin) return;
    if (s > best + kRelTol * std::abs(best) + kAbsTol && validNormal(g, i, j, t, T, -F.normal, tol)) {
      best = s;
      kind = 1;
      fBest = int(f);
      N = -F.normal;
    }
  }
  // 3. triangle edge x polytope edge directions.
  const Real faceBest = best;
  Real bestE = -std::numeric_limits<Real>::max();
  Vec3 NE = Vec3::Zero(), dE = Vec3::Zero();
  int kE = -1;
  for (int k = 0; k < 3; ++k) {
    const Vec3 e = tv[(k + 1) % 3] - tv[k];
    for (const Vec3& d : dirs) {
      Vec3 L = e.cross(d);
      const Real len = L.norm();
      if (len < Real(1e-6) * e.norm()) continue;
      L /= len;
      Real pLo = std::numeric_limits<Real>::max(), pHi = -pLo, tLo = pLo, tHi = -pLo;
      for (const Vec3& v : P.verts) {
        const Real x = L.dot(v);
        pLo = std::min(pLo, x);
        pHi = std::max(pHi, x);
      }
      for (const Vec3& v : tv) {
        const Real x = L.dot(v);
        tLo = std::min(tLo, x);
        tHi = std::max(tHi, x);
      }
      const Real s1 = pLo - tHi, s2 = tLo - pHi;
      const Real s = std::max(s1, s2);
      if (s > margin) return;
      const Vec3 Ls = s1 >= s2 ? L : Vec3(-L);
      if (s > bestE && validNormal(g, i, j, t, T, Ls, tol)) {
        bestE = s;
        NE = Ls;
        dE = d;
        kE = k;
      }
    }
  }
  if (kE >= 0 && bestE > faceBest + kRelTol * std::abs(faceBest) + kAbsTol) {
    kind = 2;
    best = bestE;
    N = NE;
    eDir = dE;
    eTri = kE;
  }

  if (kind == 2) {
    // Closest points of the triangle edge and the polytope's supporting edge along -N.
    int pe = -1;
    Real low = std::numeric_limits<Real>::max();
    for (size_t q = 0; q < P.edges.size(); ++q) {
      const Vec3 a = P.verts[P.edges[q].first], b = P.verts[P.edges[q].second];
      if ((b - a).normalized().cross(eDir).squaredNorm() > Real(1e-10)) continue;
      const Real v = N.dot(a + b);
      if (v < low) {
        low = v;
        pe = int(q);
      }
    }
    if (pe < 0) return;
    const Vec3 a0 = tv[eTri], a1 = tv[(eTri + 1) % 3];
    const Vec3 b0 = P.verts[P.edges[size_t(pe)].first], b1 = P.verts[P.edges[size_t(pe)].second];
    Real s, u;
    closestSegmentSegment(a0, a1, b0, b1, s, u);
    const Vec3 p = Real(0.5) * ((a0 + s * (a1 - a0)) + (b0 + u * (b1 - b0)));
    if (!nearExisting(out, begin, p)) out.push_back(makeContact(p, N, -best, T.index * 8 + 7));
    return;
  }

  thread_local std::vector<Vec3> ref, inc;
  thread_local std::vector<ClipVertex> poly, scratch;
  ref.clear();
  inc.clear();
  if (kind == 0) {
    // Reference: the triangle; incident: the polytope face most anti-parallel to n.
    int fi = 0;
    Real lo = std::numeric_limits<Real>::max();
    for (size_t f = 0; f < P.faces.size(); ++f) {
      const Real d = P.faces[f].normal.dot(T.n);
      if (d < lo) {
        lo = d;
        fi = int(f);
      }
    }
    const auto& IF = P.faces[size_t(fi)];
    for (uint32_t k = 0; k < IF.count; ++k) inc.push_back(P.verts[P.indices[IF.first + k]]);
    initIncident(inc.data(), int(inc.size()), poly);
    clipToReference(poly, tv, 3, T.n, scratch);
    bool flat[3];
    for (int k = 0; k < 3; ++k) flat[k] = flatJoin(g, i, j, t, T, k, tol);
    for (const ClipVertex& v : poly) {
      // Crossings of a flat internal join lie inside the merged contact region (the neighbour continues it).
      const bool onA = v.la >= 64, onB = v.lb >= 64;
      if ((onA || onB) && (!onA || flat[v.la - 64]) && (!onB || flat[v.lb - 64])) continue;
      const Real sep = T.n.dot(v.p - T.a);
      if (sep > margin) continue;
      const Vec3 p = v.p - T.n * (Real(0.5) * sep);
      if (nearExisting(out, begin, p)) continue;
      out.push_back(makeContact(p, T.n, -sep, T.index * 8 + localId(uint32_t(fi), clipLabel(v))));
    }
    return;
  }
  // kind 1: reference = polytope face fBest, incident = the triangle.
  const auto& RF = P.faces[size_t(fBest)];
  for (uint32_t k = 0; k < RF.count; ++k) ref.push_back(P.verts[P.indices[RF.first + k]]);
  initIncident(tv, 3, poly);
  clipToReference(poly, ref.data(), int(ref.size()), RF.normal, scratch);
  for (const ClipVertex& v : poly) {
    const Real sep = RF.normal.dot(v.p) - RF.offset;
    if (sep > margin) continue;
    const Vec3 p = v.p - RF.normal * (Real(0.5) * sep);
    if (nearExisting(out, begin, p)) continue;
    out.push_back(makeContact(p, N, -sep, T.index * 8 + localId(uint32_t(fBest) | 0x100u, clipLabel(v))));
  }
}

/// The triangles of cells [i0, i1] x [j0, j1] (rows j outer, cells i, then the cell's two triangles t) that are not
/// wholly below the shape: f(i, j, t, vv) for each whose highest vertex is at or above zlo - margin (zlo the shape's
/// lowest point in the field frame; a lower triangle lies below the shape by more than the margin). vv holds the
/// triangle's grid vertices (Grid::triVerts). One loop and one cull for every shape that collides per triangle.
template <class F>
void forEachTriangleAbove(const Grid& g, long i0, long i1, long j0, long j1, Real zlo, Real margin, F&& f) {
  for (long j = j0; j <= j1; ++j) {
    for (long i = i0; i <= i1; ++i) {
      for (int t = 0; t < 2; ++t) {
        long vv[3][2];
        g.triVerts(i, j, t, vv);
        Real zhi = -std::numeric_limits<Real>::max();
        for (const auto& p : vv) zhi = std::max(zhi, g.hf.getHeight(size_t(p[0]), size_t(p[1])));
        if (zhi < zlo - margin) continue;
        f(i, j, t, vv);
      }
    }
  }
}

int polytopeHeightField(Polytope& P, const Grid& g, long i0, long i1, long j0, long j1, Real margin,
                        std::vector<ContactPoint>& out) {
  const size_t begin = out.size();
  thread_local std::vector<Vec3> dirs;
  uniqueEdgeDirs(P, dirs);
  Real zlo = std::numeric_limits<Real>::max();
  for (const Vec3& v : P.verts) zlo = std::min(zlo, v.z());
  forEachTriangleAbove(g, i0, i1, j0, j1, zlo, margin, [&](long i, long j, int t, const long(&)[3][2]) {
    polytopeTriangle(g, i, j, t, P, dirs, margin, begin, out);
  });
  return int(out.size() - begin);
}

// --- cylinder against the triangles with its true circle ----------------------------------------------------
//
// Per triangle a SAT over the axes that can be the contact normal of a triangle and a round cylinder, each with
// the cylinder's exact support min_x L.x = L.c - hh |L.w| - r |L - (L.w) w| (no polygonal stand-in):
//   face  L = n: depth n.a - min_cyl(n);
//   cap   L = w (or -w, whichever points out of the field): a triangle feature pressing into a cap;
//   edge  for each triangle edge that is not a flat internal join: the edge point x* of least signed distance to
//         the cylinder, f(s) = sd(a + s (b - a)), and L = the cylinder's normal there (x* to its closest cylinder
//         point when apart, the nearest side or cap normal when inside). This is the exact edge/vertex-side and,
//         when apart, edge/vertex-rim common normal; its overlap along L is the SAT value.
// f is convex (the signed distance of a convex set). With g1 = rho - r (radial) and g2 = |y| - hh (axial) along the
// edge, f = hypot(g1, g2) when both are positive and max(g1, g2) otherwise, so f >= max(g1, g2) and f rises with
// each: the minimiser lies between s1 = argmin g1 (closed form, the distance of two lines) and s2 = argmin g2
// (y = 0). If f equals g1 at s1 (or g2 at s2) that point is the minimum; otherwise (an edge near the rim) golden
// section on [s1, s2] to 1e-13 of the edge.
// Choice: least overlap, the face normal preferred, then the cap, then edges (5 % + 1e-7 hysteresis); a cap or
// edge normal must lie in the normal cone of the triangle feature supporting it (validNormal) so flat and concave
// joins never give one. Any axis separating by more than the margin drops the triangle.
// Points (all positions in xy are owned by exactly one triangle, so per-cylinder features get ids that survive
// crossing from cell to cell: kCylFeature | feature):
//   face, cap upright (axis within 2.6 deg of n, as cylinderPlane in narrowphase.cpp): 4 rim points at fixed
//     angles of the cylinder frame, each from the triangle whose footprint holds it;
//   face, otherwise: the lowest generator c - r u +- hh w (u = n without its w part, normalised) clipped to the
//     triangle's footprint: its ends (the two rim points ending the line of contact of a lying cylinder, or the
//     lowest rim point of a tilted one) where the triangle owns them, and its crossings of non-flat edges;
//   cap: triangle vertices within the disc, crossings of the edges with the rim, and the 8 fixed rim points
//     whose projection along the axis falls on the triangle;
//   edge: x* (two points, the ends of the overlap, when the edge runs along the axis within 0.06 deg).
constexpr uint32_t kCylFeature = 0x80000000u;
constexpr int kRimPoints = 4;
constexpr Real kUprightSin = 0.045;  // |n x w| below this: the cap lies on the face (cylinderPlane's threshold)

struct CylinderHF {
  Vec3 c, w, ex, ez;  ///< centre, axis (local y), local x and z, height-field frame
  Real r, hh;
};

/// min over the cylinder of L.x (exact support).
Real cylMin(const CylinderHF& C, const Vec3& L) {
  const Real lw = L.dot(C.w);
  return L.dot(C.c) - C.hh * std::abs(lw) - C.r * (L - lw * C.w).norm();
}

struct SdPoint {
  Real f, g1, g2, y, rho;
  Vec3 q;  ///< radial part of x - c
};

SdPoint signedDistance(const CylinderHF& C, const Vec3& x) {
  SdPoint e;
  const Vec3 d = x - C.c;
  e.y = d.dot(C.w);
  e.q = d - e.y * C.w;
  e.rho = e.q.norm();
  e.g1 = e.rho - C.r;
  e.g2 = std::abs(e.y) - C.hh;
  e.f = (e.g1 > 0 && e.g2 > 0) ? std::hypot(e.g1, e.g2) : std::max(e.g1, e.g2);
  return e;
}

/// Normal (from the field point x towards the cylinder, i.e. the direction the cylinder must move) at x.
Vec3 cylNormalAt(const CylinderHF& C, const Vec3& x, const SdPoint& e, const Vec3& fallback) {
  if (e.f > 0) {
    const Real yc = std::clamp(e.y, -C.hh, C.hh);
    const Vec3 qc = e.rho > C.r ? Vec3(e.q * (C.r / e.rho)) : e.q;
    const Vec3 d = C.c + yc * C.w + qc - x;
    const Real len = d.norm();
    if (len > Real(1e-14) * (C.r + C.hh)) return d / len;
  }
  if (e.g1 >= e.g2) return e.rho > Real(1e-14) * C.r ? Vec3(-e.q / e.rho) : fallback;
  return e.y >= 0 ? Vec3(-C.w) : C.w;
}

/// Parameter in [0, 1] of the point of segment p0-p1 with the least signed distance to the cylinder.
Real minSignedDistanceOnEdge(const CylinderHF& C, const Vec3& p0, const Vec3& p1, SdPoint& best) {
  const Vec3 e = p1 - p0, d0 = p0 - C.c;
  const Real ye = e.dot(C.w), y0 = d0.dot(C.w);
  const Vec3 qe = e - ye * C.w, q0 = d0 - y0 * C.w;
  const Real qq = qe.squaredNorm(), ee = e.squaredNorm();
  const Real s1 = qq > Real(1e-24) * ee ? std::clamp(-q0.dot(qe) / qq, Real(0), Real(1)) : Real(0.5);
  const Real s2 = std::abs(ye) > Real(1e-12) * std::sqrt(ee) ? std::clamp(-y0 / ye, Real(0), Real(1)) : s1;
  best = signedDistance(C, p0 + s1 * e);
  if (best.g1 >= best.g2 && best.g2 <= 0) return s1;  // f = g1 at its minimiser
  const SdPoint e2 = signedDistance(C, p0 + s2 * e);
  if (e2.g2 >= e2.g1 && e2.g1 <= 0) {  // f = g2 at its minimiser
    best = e2;
    return s2;
  }
  // Golden section on the bracket (f is convex there).
  constexpr Real kInvPhi = 0.6180339887498949;
  Real lo = std::min(s1, s2), hi = std::max(s1, s2);
  Real a = hi - kInvPhi * (hi - lo), b = lo + kInvPhi * (hi - lo);
  SdPoint fa = signedDistance(C, p0 + a * e), fb = signedDistance(C, p0 + b * e);
  for (int it = 0; it < 100 && hi - lo > Real(1e-13); ++it) {
    if (fa.f <= fb.f) {
      hi = b;
      b = a;
      fb = fa;
      a = hi - kInvPhi * (hi - lo);
      fa = signedDistance(C, p0 + a * e);
    } else {
      lo = a;
      a = b;
      fa = fb;
      b = lo + kInvPhi * (hi - lo);
      fb = signedDistance(C, p0 + b * e);
    }
  }
  Real s = Real(0.5) * (lo + hi);
  best = signedDistance(C, p0 + s * e);
  for (const auto& cand : {std::make_pair(s1, signedDistance(C, p0 + s1 * e)), std::make_pair(s2, e2)})
    if (cand.second.f < best.f) {
      best = cand.second;
      s = cand.first;
    }
  return s;
}

/// Is (x, y) in triangle (i, j, t)'s footprint by the grid's own partition (Grid::locate)?
bool owns(const Grid& g, long i, long j, int t, const Vec3& p) {
  long oi, oj;
  int ot;
  return g.locate(p.x(), p.y(), oi, oj, ot) && oi == i && oj == j && ot == t;
}

/// Appends unless a point at p is there already (a neighbour reported the same edge, vertex or crossing); counts
/// either way in `found`.
void emitCyl(std::vector<ContactPoint>& out, size_t begin, const Vec3& p, const Vec3& n, Real depth, uint32_t id,
             int* found = nullptr) {
  if (found) ++*found;
  if (!nearExisting(out, begin, p)) out.push_back(makeContact(p, n, depth, id));
}

/// The points of the face (kind 0) or cap (kind 1) axis N of triangle T (see the comment above); returns how many
/// it found, duplicates of a neighbour's included.
int emitFaceOrCap(const Grid& g, long i, long j, int t, const Tri& T, const CylinderHF& C, int kind, const Vec3& N,
                   const bool (&flat)[3], Real margin, size_t begin, std::vector<ContactPoint>& out) {
  const Vec3 tv[3] = {T.a, T.b, T.c};
  const Real nw = T.n.dot(C.w);
  int found = 0;
  if (kind == 1) {
    const Vec3 cc = C.c - C.hh * N;  // centre of the cap facing the field
    const uint32_t capIdx = N.dot(C.w) > 0 ? 0 : 1;
    for (int m = 0; m < 3; ++m) {
      const Vec3 d = tv[m] - cc;
      const Real ya = N.dot(d);
      if ((d - ya * N).norm() <= C.r && ya >= -margin)
        emitCyl(out, begin, tv[m] - N * (Real(0.5) * ya), N, ya, T.index * 8 + localId(0x200u | uint32_t(m), 0), &found);
    }
    for (int k = 0; k < 3; ++k) {
      if (flat[k]) continue;
      const Vec3 &p0 = tv[k], e = tv[(k + 1) % 3] - tv[k];
      const Vec3 d0 = p0 - C.c;
      const Vec3 q0 = d0 - d0.dot(C.w) * C.w, qe = e - e.dot(C.w) * C.w;
      const Real A = qe.squaredNorm(), B = q0.dot(qe), Cq = q0.squaredNorm() - C.r * C.r;
      const Real disc = B * B - A * Cq;
      if (A <= 0 || disc < 0) continue;
      const Real sq = std::sqrt(disc);
      for (int root = 0; root < 2; ++root) {
        const Real s = (-B + (root ? sq : -sq)) / A;
        if (s <= 0 || s >= 1) continue;
        const Vec3 x = p0 + s * e;
        const Real ya = N.dot(x - cc);
        if (ya >= -margin)
          emitCyl(out, begin, x - N * (Real(0.5) * ya), N, ya,
                  T.index * 8 + localId(0x300u | uint32_t(k), uint32_t(root)), &found);
      }
    }
    const Real nN = T.n.dot(N);
    for (int k = 0; k < kRimPoints; ++k) {
      const Real ang = Real(6.283185307179586) * Real(k) / kRimPoints;
      const Vec3 p = cc + C.r * (std::cos(ang) * C.ex + std::sin(ang) * C.ez);
      const Real tt = T.n.dot(T.a - p) / nN;  // along N onto the triangle's plane
      if (tt < -margin) continue;
      const Vec3 x = p + tt * N;
      bool inside = true;
      for (int m = 0; m < 3 && inside; ++m) inside = T.n.dot((tv[(m + 1) % 3] - tv[m]).cross(x - tv[m])) >= 0;
      if (inside)
        emitCyl(out, begin, p + N * (Real(0.5) * tt), N, tt, T.index * 8 + localId(0x400u | capIdx, uint32_t(k)), &found);
    }
    return found;
  }

  // kind 0: the face.
  const Vec3 radial = T.n - nw * C.w;
  const Real rl = radial.norm();
  if (rl < kUprightSin) {
    const Real side = nw > 0 ? -1 : 1;  // the cap facing the triangle
    const uint32_t capIdx = nw > 0 ? 0 : 1;
    const Vec3 cc = C.c + side * C.hh * C.w;
    for (int k = 0; k < kRimPoints; ++k) {
      const Real ang = Real(6.283185307179586) * Real(k) / kRimPoints;
      const Vec3 p = cc + C.r * (std::cos(ang) * C.ex + std::sin(ang) * C.ez);
      const Real sep = T.n.dot(p - T.a);
      if (sep > margin || !owns(g, i, j, t, p)) continue;
      emitCyl(out, begin, p - T.n * (Real(0.5) * sep), T.n, -sep, kCylFeature | (capIdx << 3) | uint32_t(k), &found);
    }
    return found;
  }
  const Vec3 low = C.c - C.r * (radial / rl);
  const Vec3 P0 = low - C.hh * C.w, P1 = low + C.hh * C.w;
  // Clip the generator to the triangle's footprint (xy; counter-clockwise from above). Points within 1e-12 of the
  // cell size outside count as inside, so an end on a shared edge or vertex is inside every triangle there and
  // its owner (Grid::locate) reports it.
  const Real cellTol = Real(1e-12) * (g.dx + g.dy);
  Real tlo = 0, thi = 1;
  int klo = -1, khi = -1;
  for (int k = 0; k < 3; ++k) {
    const Vec3 &v = tv[k], e = tv[(k + 1) % 3] - tv[k];
    const Real el = std::hypot(e.x(), e.y());
    const Real d0 = (e.x() * (P0.y() - v.y()) - e.y() * (P0.x() - v.x())) / el + cellTol;
    const Real d1 = (e.x() * (P1.y() - v.y()) - e.y() * (P1.x() - v.x())) / el + cellTol;
    if (d0 < 0 && d1 < 0) return found;
    if (d0 < 0) {
      const Real tt = d0 / (d0 - d1);
      if (tt > tlo) tlo = tt, klo = k;
    } else if (d1 < 0) {
      const Real tt = d0 / (d0 - d1);
      if (tt < thi) thi = tt, khi = k;
    }
  }
  if (tlo > thi) return found;
  const std::pair<Real, int> ends[2] = {{tlo, klo}, {thi, khi}};
  for (int end = 0; end < 2; ++end) {
    const auto [tt, k] = ends[end];
    if (k >= 0 && flat[k]) continue;  // a flat join: the neighbour continues the line of contact
    const Vec3 p = P0 + tt * (P1 - P0);
    const Real sep = T.n.dot(p - T.a);
    if (sep > margin) continue;
    if (k < 0 && !owns(g, i, j, t, p)) {  // a generator end on a shared edge: its owner reports it
      ++found;
      continue;
    }
    const uint32_t id = k < 0 ? kCylFeature | 0x100u | uint32_t(end) : T.index * 8 + 1 + uint32_t(k);
    emitCyl(out, begin, p - T.n * (Real(0.5) * sep), T.n, -sep, id, &found);
  }
  return found;
}

void cylinderTriangle(const Grid& g, long i, long j, int t, const CylinderHF& C, Real margin, size_t begin,
                      std::vector<ContactPoint>& out) {
  const Tri T = makeTri(g, i, j, t);
  const Vec3 tv[3] = {T.a, T.b, T.c};
  const Real tol = Real(1e-9) * (g.dx + g.dy + std::abs(T.a.z()));
  auto triMax = [&](const Vec3& L) { return std::max({L.dot(T.a), L.dot(T.b), L.dot(T.c)}); };
  auto beats = [](Real ov, Real best) { return ov < best - (kRelTol * std::abs(best) + kAbsTol); };
  // 1. face
  const Real ovN = T.n.dot(T.a) - cylMin(C, T.n);
  if (ovN < -margin) return;
  int kind = 0;
  Real best = ovN;
  Vec3 N = T.n;
  // 2. cap
  const Real nw = T.n.dot(C.w);
  if (std::abs(nw) > Real(1e-9)) {
    const Vec3 L = nw > 0 ? C.w : Vec3(-C.w);
    const Real ov = triMax(L) - (L.dot(C.c) - C.hh);
    if (ov < -margin) return;
    if (beats(ov, best) && validNormal(g, i, j, t, T, L, tol)) {
      kind = 1;
      best = ov;
      N = L;
    }
  }
  // 3. edges (flat internal joins have no normal but the face's and separate nothing the face does not)
  bool flat[3];
  for (int k = 0; k < 3; ++k) flat[k] = flatJoin(g, i, j, t, T, k, tol);
  const Real faceBest = best;
  Real bestE = std::numeric_limits<Real>::max();
  int kE = -1;
  Vec3 NE = Vec3::Zero(), xE = Vec3::Zero();
  SdPoint evE{};
  for (int k = 0; k < 3; ++k) {
    if (flat[k]) continue;
    const Vec3 &p0 = tv[k], &p1 = tv[(k + 1) % 3];
    SdPoint ev;
    const Real s = minSignedDistanceOnEdge(C, p0, p1, ev);
    const Vec3 x = p0 + s * (p1 - p0);
    const Vec3 L = cylNormalAt(C, x, ev, T.n);
    const Real tm = triMax(L);
    const Real ov = tm - cylMin(C, L);
    if (ov < -margin) return;
    if (ov < bestE && L.dot(x) >= tm - tol && validNormal(g, i, j, t, T, L, tol)) {
      bestE = ov;
      kE = k;
      NE = L;
      xE = x;
      evE = ev;
    }
  }
  if (kE >= 0 && beats(bestE, faceBest)) {
    kind = 2;
    best = bestE;
    N = NE;
  }

  // Edge axis (also the fallback when the face or cap axis won but its features do not overlap in projection,
  // e.g. a rim just above a ridge: the cap's disc does not reach the ridge, the rim does).
  auto emitEdge = [&]() {
    const Vec3 &p0 = tv[kE], &p1 = tv[(kE + 1) % 3];
    const Vec3 e = p1 - p0;
    if (evE.g1 >= evE.g2 && e.cross(C.w).norm() < Real(1e-3) * e.norm()) {
      // The edge runs along the axis (a cylinder lying along a ridge): the ends of the edge's part within the
      // cylinder's length.
      const Real ye = e.dot(C.w), y0 = (p0 - C.c).dot(C.w);
      Real lo = (-C.hh - y0) / ye, hi = (C.hh - y0) / ye;
      if (lo > hi) std::swap(lo, hi);
      lo = std::max<Real>(lo, 0);
      hi = std::min<Real>(hi, 1);
      if (lo <= hi) {
        uint32_t end = 0;
        for (const Real s : {lo, hi}) {
          const Vec3 x = p0 + s * e;
          const Real d = NE.dot(x) - cylMin(C, NE);
          if (d >= -margin) emitCyl(out, begin, x - NE * (Real(0.5) * d), NE, d, end ? T.index * 8 + 7 : T.index * 8 + 4 + uint32_t(kE));
          ++end;
        }
        return;
      }
    }
    emitCyl(out, begin, xE - NE * (Real(0.5) * bestE), NE, bestE, T.index * 8 + 4 + uint32_t(kE));
  };
  if (kind == 2) {
    emitEdge();
    return;
  }
  if (emitFaceOrCap(g, i, j, t, T, C, kind, N, flat, margin, begin, out) == 0 && kE >= 0) emitEdge();
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
int collideSphereHeightField(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
                             std::vector<ContactPoint>& out) {
  const Grid g(static_cast<const HeightField&>(s1));
  const Real r = static_cast<const Sphere&>(s0).getRadius();
  const Transform rel = t1.inverse() * t0;
  long i0, i1, j0, j1;
  if (!footprint(s0, rel, g, margin, i0, i1, j0, j1)) return 0;
  const size_t begin = out.size();
  // A cell whose four vertices all lie more than r + margin below the centre cannot touch the sphere (every
  // point of its triangles is at least that far away): skipped without building its triangles. The 1e-9
  // relative slack keeps the skip conservative against rounding, so the contacts are exactly those of the full
  // loop (particles resting on or above a terrain cell meet this test most).
  const Real zReach = (r + margin) * (1 + Real(1e-9));
  for (long j = j0; j <= j1; ++j)
    for (long i = i0; i <= i1; ++i) {
      const size_t ui = size_t(i), uj = size_t(j);
      const Real zTop = std::max(std::max(g.hf.getHeight(ui, uj), g.hf.getHeight(ui + 1, uj)),
                                 std::max(g.hf.getHeight(ui, uj + 1), g.hf.getHeight(ui + 1, uj + 1)));
      if (rel.p.z() - zTop > zReach) continue;
      for (int t = 0; t < 2; ++t) sphereTriangle(g, i, j, t, rel.p, r, margin, -1, out);
    }
  return finish(out, begin, t1);
}

int collideCapsuleHeightField(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1,
                              Real margin, std::vector<ContactPoint>& out) {
  const Grid g(static_cast<const HeightField&>(s1));
  const auto& cap = static_cast<const Capsule&>(s0);
  const Real r = cap.getRadius();
  const Transform rel = t1.inverse() * t0;
  long i0, i1, j0, j1;
  if (!footprint(s0, rel, g, margin, i0, i1, j0, j1)) return 0;
  const Vec3 half = rel.rotate(Vec3(0, Real(0.5) * cap.getHeight(), 0));
  const Vec3 a = rel.p - half, b = rel.p + half;
  const size_t begin = out.size();
  for (long j = j0; j <= j1; ++j) {
    for (long i = i0; i <= i1; ++i) {
      for (int t = 0; t < 2; ++t) {
        sphereTriangle(g, i, j, t, a, r, margin, 0, out);
        sphereTriangle(g, i, j, t, b, r, margin, 1, out);
      }
    }
  }
  // Interior sites: the segment point closest to each triangle's edges catches a ridge under the middle of a
  // lying capsule. Such a point only matters when it is deeper than both ends; on a plane it is not, and
  // keeping it would only add redundant collinear points with unstable ids.
  Real endDepth = -std::numeric_limits<Real>::max();
  for (size_t k = begin; k < out.size(); ++k) endDepth = std::max(endDepth, out[k].depth);
  thread_local std::vector<ContactPoint> mid;
  mid.clear();
  for (long j = j0; j <= j1; ++j) {
    for (long i = i0; i <= i1; ++i) {
      for (int t = 0; t < 2; ++t) {
        const Tri T = makeTri(g, i, j, t);
        const Vec3 e[3][2] = {{T.a, T.b}, {T.b, T.c}, {T.c, T.a}};
        Real bestD = std::numeric_limits<Real>::max(), bestS = 0;
        for (const auto& ed : e) {
          Real s, u;
          closestSegmentSegment(a, b, ed[0], ed[1], s, u);
          const Real dd = ((a + s * (b - a)) - (ed[0] + u * (ed[1] - ed[0]))).squaredNorm();
          if (dd < bestD) {
            bestD = dd;
            bestS = s;
          }
        }
        if (bestS > Real(1e-6) && bestS < 1 - Real(1e-6))
          sphereTriangle(g, i, j, t, a + bestS * (b - a), r, margin, 2, mid);
      }
    }
  }
  for (const ContactPoint& c : mid)
    if (c.depth > endDepth + Real(1e-9)) out.push_back(c);
  return finish(out, begin, t1);
}

int collideBoxHeightField(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
                          std::vector<ContactPoint>& out) {
  const Grid g(static_cast<const HeightField&>(s1));
  const Transform rel = t1.inverse() * t0;
  long i0, i1, j0, j1;
  if (!footprint(s0, rel, g, margin, i0, i1, j0, j1)) return 0;
  thread_local Polytope P;
  makeBoxPolytope(static_cast<const Box&>(s0).getHalfExtents(), rel, P);
  const size_t begin = out.size();
  polytopeHeightField(P, g, i0, i1, j0, j1, margin, out);
  return finish(out, begin, t1);
}

int collideConvexHeightField(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real margin,
                             std::vector<ContactPoint>& out) {
  const Grid g(static_cast<const HeightField&>(s1));
  const Transform rel = t1.inverse() * t0;
  long i0, i1, j0, j1;
  if (!footprint(s0, rel, g, margin, i0, i1, j0, j1)) return 0;
  thread_local Polytope P;
  makeConvexPolytope(static_cast<const Convex&>(s0), rel, P);
  const size_t begin = out.size();
  polytopeHeightField(P, g, i0, i1, j0, j1, margin, out);
  return finish(out, begin, t1);
}

int collideCylinderHeightField(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1,
                               Real margin, std::vector<ContactPoint>& out) {
  const Grid g(static_cast<const HeightField&>(s1));
  const auto& cyl = static_cast<const Cylinder&>(s0);
  const Transform rel = t1.inverse() * t0;
  long i0, i1, j0, j1;
  if (!footprint(s0, rel, g, margin, i0, i1, j0, j1)) return 0;
  CylinderHF C;
  C.c = rel.p;
  C.w = rel.rotate(Vec3::UnitY());
  C.ex = rel.rotate(Vec3::UnitX());
  C.ez = rel.rotate(Vec3::UnitZ());
  C.r = cyl.getRadius();
  C.hh = Real(0.5) * cyl.getHeight();
  const Real zlo = cylMin(C, Vec3::UnitZ());
  const size_t begin = out.size();
  forEachTriangleAbove(g, i0, i1, j0, j1, zlo, margin, [&](long i, long j, int t, const long (&vv)[3][2]) {
    // Cheap cull: the cylinder's own bounding box (|x|, |z| <= r, |y| <= hh in its frame) against the
    // triangle's vertices, one axis at a time.
    for (int ax = 0; ax < 3; ++ax) {
      const Vec3& d = ax == 0 ? C.ex : (ax == 1 ? C.w : C.ez);
      const Real ext = (ax == 1 ? C.hh : C.r) + margin + Real(1e-9) * (C.r + C.hh), dc = d.dot(C.c);
      Real lo = std::numeric_limits<Real>::max(), hi = -lo;
      for (const auto& p : vv) {
        const Real x = d.dot(g.vert(p[0], p[1])) - dc;
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
      if (lo > ext || hi < -ext) return;
    }
    cylinderTriangle(g, i, j, t, C, margin, begin, out);
  });
  return finish(out, begin, t1);
}

int collideLineHeightField(const Shape& s0, const Transform& t0, const Shape& s1, const Transform& t1, Real,
                           std::vector<ContactPoint>& out) {
  const Grid g(static_cast<const HeightField&>(s1));
  const auto& line = static_cast<const Line&>(s0);
  const Transform rel = t1.inverse() * t0;
  const Vec3 a = rel.apply(line.getFirstPoint()), d = rel.apply(line.getSecondPoint()) - a;
  long i0, i1, j0, j1;
  if (!g.cellRange(a.cwiseMin(a + d), a.cwiseMax(a + d), i0, i1, j0, j1)) return 0;
  // Moeller-Trumbore against every triangle under the segment's footprint; the first hit from above is the entry,
  // the first hit from below after it the exit.
  Real tin = std::numeric_limits<Real>::max(), tout = 1;
  Vec3 nIn = Vec3::UnitZ();
  thread_local std::vector<std::pair<Real, bool>> hits;
  hits.clear();
  for (long j = j0; j <= j1; ++j) {
    for (long i = i0; i <= i1; ++i) {
      for (int t = 0; t < 2; ++t) {
        const Tri T = makeTri(g, i, j, t);
        const Vec3 e1 = T.b - T.a, e2 = T.c - T.a, pv = d.cross(e2);
        const Real det = e1.dot(pv);
        if (std::abs(det) < Real(1e-14)) continue;
        const Vec3 tv = a - T.a;
        const Real u = tv.dot(pv) / det;
        if (u < 0 || u > 1) continue;
        const Vec3 qv = tv.cross(e1);
        const Real v = d.dot(qv) / det;
        if (v < 0 || u + v > 1) continue;
        const Real s = e2.dot(qv) / det;
        if (s < 0 || s > 1) continue;
        const bool entering = d.dot(T.n) < 0;
        hits.emplace_back(s, entering);
        if (entering && s < tin) {
          tin = s;
          nIn = T.n;
        }
      }
    }
  }
  if (tin > 1) return 0;
  for (const auto& h : hits)
    if (!h.second && h.first > tin && h.first < tout) tout = h.first;
  out.push_back(makeContact(t1.apply(a + tin * d), t1.rotate(nIn), (tout - tin) * d.norm(), 0));
  return 1;
}

}  // namespace scree::detail
