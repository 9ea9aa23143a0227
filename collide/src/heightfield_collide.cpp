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
// Box and convex: (a) shape vertices below (or within the margin above) the triangle under them, with the triangle
// normal (id = triangle * 8 + vertex index mod 8); (b) sharp height-field vertices (peaks and ridge points: all
// grid neighbours on or below the plane through the vertex, at least one strictly) inside the shape, pushed out
// through the least-penetrated downward-facing shape face (id = 0x80000000 | vertex index). Known gap: a
// height-field ridge edge crossing a shape edge between grid vertices is not seen until a vertex reaches the
// other shape (a full triangle-vs-polytope SAT needs the Gauss-map limits of each edge to avoid internal-edge
// normals, left for later).
// Cylinder: as (a)/(b) with rim points as vertices (4 fixed points per cap when nearly upright, else each cap's
// deepest rim point along the height field's -z) and caps + side as faces.
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

// --- vertex-based contacts for box / convex / cylinder ----------------------------------------------------------

/// (a) shape vertices under the surface.
void verticesBelow(const Grid& g, const std::vector<Vec3>& verts, Real margin, std::vector<ContactPoint>& out) {
  for (size_t k = 0; k < verts.size(); ++k) {
    const Vec3& v = verts[k];
    long i, j;
    int t;
    if (!g.locate(v.x(), v.y(), i, j, t)) continue;
    const Tri T = makeTri(g, i, j, t);
    const Real sep = T.n.dot(v - T.a);
    if (sep > margin) continue;
    out.push_back(makeContact(v - T.n * (Real(0.5) * sep), T.n, -sep, T.index * 8 + uint32_t(k & 7)));
  }
}

/// A convex shape's "faces" for the inside test: outward normal and signed distance of a point.
struct FaceDist {
  Vec3 m;
  Real sep;
};

/// (b) sharp height-field vertices inside the shape. `inside(p, faces)` fills the face distances of point p
/// (height-field frame). Only faces facing down (m.z < -0.1) can take the push: the height field is solid below
/// and never pushes a shape sideways or down through itself.
template <class InsideFn>
void sharpVerticesInside(const Grid& g, long i0, long i1, long j0, long j1, Real margin, InsideFn inside,
                         std::vector<ContactPoint>& out) {
  static constexpr int kNb[6][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, -1}};
  thread_local std::vector<FaceDist> faces;
  const Real tol = Real(1e-9) * (g.dx + g.dy);
  for (long vj = j0; vj <= j1 + 1; ++vj) {
    for (long vi = i0; vi <= i1 + 1; ++vi) {
      const Vec3 p = g.vert(vi, vj);
      faces.clear();
      inside(p, faces);
      Real maxSep = -std::numeric_limits<Real>::max();
      const FaceDist* best = nullptr;
      bool in = !faces.empty();
      for (const FaceDist& f : faces) {
        if (f.sep > margin) {
          in = false;
          break;
        }
        if (f.m.z() < Real(-0.1) && f.sep > maxSep) {
          maxSep = f.sep;
          best = &f;
        }
      }
      if (!in || !best) continue;
      const Vec3 N = -best->m;  // from the height field towards the shape
      // Sharp vertex: no neighbour above the plane through p with normal N, at least one strictly below.
      bool sharp = false, blocked = false;
      for (const auto& o : kNb) {
        const long ni = vi + o[0], nj = vj + o[1];
        if (ni < 0 || nj < 0 || ni >= g.nx || nj >= g.ny) continue;
        const Real h = N.dot(g.vert(ni, nj) - p);
        if (h > tol) blocked = true;
        if (h < -tol) sharp = true;
      }
      if (blocked || !sharp) continue;
      const Real depth = -maxSep;
      out.push_back(makeContact(p + N * (Real(0.5) * depth), N, depth, 0x80000000u | uint32_t(vj * g.nx + vi)));
    }
  }
}

int polytopeHeightField(const Polytope& P, const Grid& g, long i0, long i1, long j0, long j1, Real margin,
                        std::vector<ContactPoint>& out) {
  const size_t begin = out.size();
  verticesBelow(g, P.verts, margin, out);
  sharpVerticesInside(
      g, i0, i1, j0, j1, margin,
      [&P](const Vec3& p, std::vector<FaceDist>& f) {
        for (const auto& F : P.faces) f.push_back({F.normal, F.normal.dot(p) - F.offset});
      },
      out);
  return int(out.size() - begin);
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
  for (long j = j0; j <= j1; ++j)
    for (long i = i0; i <= i1; ++i)
      for (int t = 0; t < 2; ++t) sphereTriangle(g, i, j, t, rel.p, r, margin, -1, out);
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
  const Real r = cyl.getRadius(), hh = Real(0.5) * cyl.getHeight();
  const Transform rel = t1.inverse() * t0;
  long i0, i1, j0, j1;
  if (!footprint(s0, rel, g, margin, i0, i1, j0, j1)) return 0;
  // Rim points (height-field frame) as in cylinderPlane, with the height field's +z as "up".
  const Vec3 upL = rel.rotateInverse(Vec3::UnitZ());
  thread_local std::vector<Vec3> rim;
  rim.clear();
  const Vec3 radial(upL.x(), 0, upL.z());
  const Real rl = radial.norm();
  if (rl < Real(0.045)) {
    const Real cy = upL.y() > 0 ? -hh : hh;
    for (const Vec3& l : {Vec3(r, cy, 0), Vec3(0, cy, r), Vec3(-r, cy, 0), Vec3(0, cy, -r)}) rim.push_back(rel.apply(l));
  } else {
    const Vec3 u = -radial / rl;
    rim.push_back(rel.apply(Vec3(u.x() * r, -hh, u.z() * r)));
    rim.push_back(rel.apply(Vec3(u.x() * r, hh, u.z() * r)));
  }
  const size_t begin = out.size();
  verticesBelow(g, rim, margin, out);
  const Vec3 w = rel.rotate(Vec3::UnitY());
  sharpVerticesInside(
      g, i0, i1, j0, j1, margin,
      [&](const Vec3& p, std::vector<FaceDist>& f) {
        const Vec3 q = rel.applyInverse(p);
        f.push_back({w, q.y() - hh});
        f.push_back({-w, -q.y() - hh});
        const Real rho = std::hypot(q.x(), q.z());
        if (rho > Real(1e-12)) f.push_back({rel.rotate(Vec3(q.x() / rho, 0, q.z() / rho)), rho - r});
      },
      out);
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
