// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Collision shapes: validation, volumes, exact mass properties, bounding boxes, support mappings, and the
// quickhull used by Convex.
//
// Mass-property conventions: MassProperties::inertia is about the centre of mass in the shape's own axes.
// Closed forms used below (m = mass):
//   sphere      I = 2/5 m r^2
//   box         I_xx = m/3 (b^2 + c^2) with half extents (a, b, c)   [= m/12 (B^2 + C^2) for full sizes]
//   cylinder    axis y: I_yy = m r^2 / 2, I_xx = I_zz = m (3 r^2 + h^2) / 12
//   capsule     cylinder (height h) + two hemispheres; a hemisphere's centroid sits 3r/8 from its flat face
//               and its inertia about a transverse axis through that centroid is (2/5 - 9/64) m r^2
//               = 83/320 m r^2; the parallel-axis offset to the capsule centre is h/2 + 3r/8.
//   convex      exact polyhedral integration by the divergence theorem, written as a sum over signed
//               tetrahedra (apex, triangle) of the canonical second-moment matrix (Blow & Binstock 2004,
//               "How to find the inertia tensor of a 3D solid body represented by a triangle mesh";
//               equivalent to Mirtich 1996 / Eberly "Polyhedral Mass Properties").
#include "scree/collide/shapes.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <numbers>
#include <numeric>
#include <sstream>
#include <string>
#include <unordered_map>

#include "scree/core/errors.h"
#include "scree/core/logger.h"

namespace scree {

namespace {

constexpr Real kPi = std::numbers::pi_v<Real>;
constexpr Real kHuge = 1e300;

/// Inertia of a solid about its centre of mass from its second-moment (covariance) matrix C = ∫ρ x x^T dV:
/// I = tr(C) 1 - C.
Mat3 inertiaFromCovariance(const Mat3& c) { return Mat3::Identity() * c.trace() - c; }

/// AABB of an axis-aligned box of half extents `he` centred at `c` in the shape frame, placed by `t`.
/// |R| he is the tight world half extent of a rotated box.
Aabb rotatedBox(const Transform& t, const Vec3& c, const Vec3& he) {
  const Mat3 r = t.q.toRotationMatrix();
  const Vec3 centre = t.apply(c);
  const Vec3 ext = r.cwiseAbs() * he;
  Aabb b;
  b.lo = centre - ext;
  b.hi = centre + ext;
  return b;
}

Real signOrPlus(Real v) { return v < 0 ? Real(-1) : Real(1); }

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// Shape defaults
// ---------------------------------------------------------------------------------------------------------

MassProperties Shape::computeMassProperties(Real) const { return {}; }

Vec3 Shape::support(const Vec3&) const { return Vec3::Zero(); }

// ---------------------------------------------------------------------------------------------------------
// Sphere
// ---------------------------------------------------------------------------------------------------------

Sphere::Sphere(Real radius) : Shape(SPHERE), r_(0) {
  detail::requirePositive("Sphere::Sphere", "radius", radius);
  r_ = radius;
}

void Sphere::setRadius(Real r) {
  detail::requirePositive("Sphere::setRadius", "radius", r);
  r_ = r;
  touch();
}

Real Sphere::getVolume() const { return 4.0 / 3.0 * kPi * r_ * r_ * r_; }

MassProperties Sphere::computeMassProperties(Real density) const {
  MassProperties mp;
  mp.mass = density * getVolume();
  mp.inertia = Mat3::Identity() * (0.4 * mp.mass * r_ * r_);
  return mp;
}

Aabb Sphere::getBoundingBox(const Transform& t) const {
  Aabb b;
  b.lo = t.p.array() - r_;
  b.hi = t.p.array() + r_;
  return b;
}

Vec3 Sphere::support(const Vec3& dir) const {
  const Real n = dir.norm();
  if (!(n > 0)) return Vec3(r_, 0, 0);
  return dir * (r_ / n);
}

// ---------------------------------------------------------------------------------------------------------
// Box
// ---------------------------------------------------------------------------------------------------------

namespace {
void validateHalfExtents(const char* where, const Vec3& he) {
  if (!(he.allFinite() && (he.array() > 0).all()))
    detail::throwInvalid(where, "halfExtents", he, "every component must be finite and > 0");
}
}  // namespace

Box::Box(const Vec3& halfExtents) : Shape(BOX), he_(Vec3::Ones()) {
  validateHalfExtents("Box::Box", halfExtents);
  he_ = halfExtents;
}

void Box::setHalfExtents(const Vec3& he) {
  validateHalfExtents("Box::setHalfExtents", he);
  he_ = he;
  touch();
}

Real Box::getVolume() const { return 8.0 * he_.x() * he_.y() * he_.z(); }

MassProperties Box::computeMassProperties(Real density) const {
  MassProperties mp;
  mp.mass = density * getVolume();
  const Vec3 s = he_.cwiseProduct(he_);
  mp.inertia.diagonal() = Vec3(s.y() + s.z(), s.x() + s.z(), s.x() + s.y()) * (mp.mass / 3.0);
  return mp;
}

Aabb Box::getBoundingBox(const Transform& t) const { return rotatedBox(t, Vec3::Zero(), he_); }

Vec3 Box::support(const Vec3& dir) const {
  return Vec3(signOrPlus(dir.x()) * he_.x(), signOrPlus(dir.y()) * he_.y(), signOrPlus(dir.z()) * he_.z());
}

// ---------------------------------------------------------------------------------------------------------
// Capsule (axis y, segment length h between hemisphere centres)
// ---------------------------------------------------------------------------------------------------------

Capsule::Capsule(Real radius, Real height) : Shape(CAPSULE), r_(0), h_(0) {
  detail::requirePositive("Capsule::Capsule", "radius", radius);
  detail::requirePositive("Capsule::Capsule", "height", height);
  r_ = radius;
  h_ = height;
}

void Capsule::setRadius(Real r) {
  detail::requirePositive("Capsule::setRadius", "radius", r);
  r_ = r;
  touch();
}

void Capsule::setHeight(Real h) {
  detail::requirePositive("Capsule::setHeight", "height", h);
  h_ = h;
  touch();
}

Real Capsule::getVolume() const { return kPi * r_ * r_ * h_ + 4.0 / 3.0 * kPi * r_ * r_ * r_; }

MassProperties Capsule::computeMassProperties(Real density) const {
  const Real r2 = r_ * r_;
  const Real mc = density * kPi * r2 * h_;                // cylinder part
  const Real mh = density * 2.0 / 3.0 * kPi * r2 * r_;    // one hemisphere
  const Real d = 0.5 * h_ + 3.0 / 8.0 * r_;               // capsule centre -> hemisphere centroid
  MassProperties mp;
  mp.mass = mc + 2 * mh;
  const Real axial = 0.5 * mc * r2 + 2.0 * (0.4 * mh * r2);
  const Real transverse = mc * (3.0 * r2 + h_ * h_) / 12.0 + 2.0 * (83.0 / 320.0 * mh * r2 + mh * d * d);
  mp.inertia.diagonal() = Vec3(transverse, axial, transverse);
  return mp;
}

Aabb Capsule::getBoundingBox(const Transform& t) const {
  // Segment endpoints +-h/2 along the world axis a = R e_y, swept by a sphere of radius r.
  const Vec3 a = t.q * Vec3::UnitY();
  const Vec3 ext = a.cwiseAbs() * (0.5 * h_) + Vec3::Constant(r_);
  Aabb b;
  b.lo = t.p - ext;
  b.hi = t.p + ext;
  return b;
}

Vec3 Capsule::support(const Vec3& dir) const {
  const Real n = dir.norm();
  Vec3 s(0, signOrPlus(dir.y()) * 0.5 * h_, 0);
  if (n > 0) s += dir * (r_ / n);
  else s.x() += r_;
  return s;
}

// ---------------------------------------------------------------------------------------------------------
// Cylinder (axis y, full height h)
// ---------------------------------------------------------------------------------------------------------

Cylinder::Cylinder(Real radius, Real height) : Shape(CYLINDER), r_(0), h_(0) {
  detail::requirePositive("Cylinder::Cylinder", "radius", radius);
  detail::requirePositive("Cylinder::Cylinder", "height", height);
  r_ = radius;
  h_ = height;
}

void Cylinder::setRadius(Real r) {
  detail::requirePositive("Cylinder::setRadius", "radius", r);
  r_ = r;
  touch();
}

void Cylinder::setHeight(Real h) {
  detail::requirePositive("Cylinder::setHeight", "height", h);
  h_ = h;
  touch();
}

Real Cylinder::getVolume() const { return kPi * r_ * r_ * h_; }

MassProperties Cylinder::computeMassProperties(Real density) const {
  MassProperties mp;
  mp.mass = density * getVolume();
  const Real axial = 0.5 * mp.mass * r_ * r_;
  const Real transverse = mp.mass * (3.0 * r_ * r_ + h_ * h_) / 12.0;
  mp.inertia.diagonal() = Vec3(transverse, axial, transverse);
  return mp;
}

Aabb Cylinder::getBoundingBox(const Transform& t) const {
  // The cap discs have world axis a; a disc of radius r with normal a extends r sqrt(1 - a_k^2) along
  // world axis k. Adding the half height |a_k| h/2 gives the tight box.
  const Vec3 a = t.q * Vec3::UnitY();
  Vec3 ext;
  for (int k = 0; k < 3; ++k)
    ext[k] = r_ * std::sqrt(std::max(Real(0), 1 - a[k] * a[k])) + std::abs(a[k]) * 0.5 * h_;
  Aabb b;
  b.lo = t.p - ext;
  b.hi = t.p + ext;
  return b;
}

Vec3 Cylinder::support(const Vec3& dir) const {
  Vec3 s(0, signOrPlus(dir.y()) * 0.5 * h_, 0);
  const Real rad = std::sqrt(dir.x() * dir.x() + dir.z() * dir.z());
  if (rad > 0) {
    s.x() = r_ * dir.x() / rad;
    s.z() = r_ * dir.z() / rad;
  }
  return s;
}

// ---------------------------------------------------------------------------------------------------------
// Plane
// ---------------------------------------------------------------------------------------------------------

Plane::Plane(const Vec3& normal, Real distance) : Shape(PLANE), n_(Vec3::UnitZ()), d_(0) {
  if (!(normal.allFinite() && normal.norm() > 1e-12))
    detail::throwInvalid("Plane::Plane", "normal", normal, "must be finite and non-zero");
  detail::requireFinite("Plane::Plane", "distance", distance);
  n_ = normal.normalized();
  d_ = distance;
}

Aabb Plane::getBoundingBox(const Transform& t) const {
  Aabb b;
  b.lo = Vec3::Constant(-kHuge);
  b.hi = Vec3::Constant(kHuge);
  // World plane: nw . x = dw. When nw is axis-aligned the solid half space is bounded on that axis.
  const Vec3 nw = t.q * n_;
  const Real dw = d_ + nw.dot(t.p);
  for (int k = 0; k < 3; ++k) {
    const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
    if (std::abs(nw[k1]) < 1e-12 && std::abs(nw[k2]) < 1e-12) {
      if (nw[k] > 0) b.hi[k] = dw / nw[k];
      else b.lo[k] = dw / nw[k];
    }
  }
  return b;
}

// ---------------------------------------------------------------------------------------------------------
// Convex: quickhull (Barber, Dobkin & Huhdanpaa 1996) with tolerance-based visibility, then coplanar
// triangles merged into polygon faces.
// ---------------------------------------------------------------------------------------------------------

namespace {

struct HullTri {
  uint32_t v[3];
  Vec3 n;
  Real d;
  bool alive = true;
  std::vector<uint32_t> outside;  // points strictly above the plane by more than the tolerance
};

uint64_t edgeKey(uint32_t a, uint32_t b) { return (uint64_t(a) << 32) | b; }

class QuickHull {
 public:
  QuickHull(const std::vector<Vec3>& p, Real tol) : pts_(p), tol_(tol) {}

  /// Builds the hull; returns triangles (CCW from outside) or throws on degenerate input.
  std::vector<std::array<uint32_t, 3>> run() {
    initialSimplex();
    // Faces are appended as the hull grows; each face is processed once, in creation order: its farthest
    // outside point is added (which always kills the face itself since the point is above it).
    for (size_t fi = 0; fi < tris_.size(); ++fi) {
      if (!tris_[fi].alive || tris_[fi].outside.empty()) continue;
      addPoint(fi);
    }
    std::vector<std::array<uint32_t, 3>> out;
    for (const HullTri& t : tris_)
      if (t.alive) out.push_back({t.v[0], t.v[1], t.v[2]});
    return out;
  }

 private:
  Real dist(const HullTri& t, uint32_t i) const { return t.n.dot(pts_[i]) - t.d; }

  /// Creates face (a, b, c), CCW from outside; returns its index.
  uint32_t makeTri(uint32_t a, uint32_t b, uint32_t c) {
    HullTri t;
    t.v[0] = a;
    t.v[1] = b;
    t.v[2] = c;
    // Normal from the cross product of the two edges at the vertex opposite the longest edge would be
    // slightly more accurate; a plain cross product is adequate at the tolerances used here.
    t.n = (pts_[b] - pts_[a]).cross(pts_[c] - pts_[a]);
    const Real len = t.n.norm();
    t.n = len > 0 ? Vec3(t.n / len) : Vec3::UnitZ();
    t.d = t.n.dot((pts_[a] + pts_[b] + pts_[c]) / 3.0);
    const uint32_t id = uint32_t(tris_.size());
    tris_.push_back(std::move(t));
    edges_[edgeKey(a, b)] = id;
    edges_[edgeKey(b, c)] = id;
    edges_[edgeKey(c, a)] = id;
    return id;
  }

  void initialSimplex() {
    const size_t n = pts_.size();
    // Extreme points along the axes; the most distant pair starts the simplex.
    uint32_t ext[6] = {0, 0, 0, 0, 0, 0};
    for (uint32_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) {
        if (pts_[i][k] < pts_[ext[2 * k]][k]) ext[2 * k] = i;
        if (pts_[i][k] > pts_[ext[2 * k + 1]][k]) ext[2 * k + 1] = i;
      }
    uint32_t i0 = 0, i1 = 0;
    Real best = -1;
    for (int a = 0; a < 6; ++a)
      for (int b = a + 1; b < 6; ++b) {
        const Real d2 = (pts_[ext[a]] - pts_[ext[b]]).squaredNorm();
        if (d2 > best) {
          best = d2;
          i0 = ext[a];
          i1 = ext[b];
        }
      }
    if (!(std::sqrt(best) > degTol()))
      throw std::invalid_argument("Convex::Convex: points are degenerate (all coincide within tolerance)");
    // Farthest from the line i0-i1.
    const Vec3 u = (pts_[i1] - pts_[i0]).normalized();
    uint32_t i2 = 0;
    best = -1;
    for (uint32_t i = 0; i < n; ++i) {
      const Vec3 w = pts_[i] - pts_[i0];
      const Real d2 = (w - u * u.dot(w)).squaredNorm();
      if (d2 > best) {
        best = d2;
        i2 = i;
      }
    }
    if (!(std::sqrt(best) > degTol()))
      throw std::invalid_argument("Convex::Convex: points are degenerate (all collinear within tolerance)");
    // Farthest from the plane i0-i1-i2.
    const Vec3 nrm = (pts_[i1] - pts_[i0]).cross(pts_[i2] - pts_[i0]).normalized();
    uint32_t i3 = 0;
    best = -1;
    Real signedBest = 0;
    for (uint32_t i = 0; i < n; ++i) {
      const Real d = nrm.dot(pts_[i] - pts_[i0]);
      if (std::abs(d) > best) {
        best = std::abs(d);
        signedBest = d;
        i3 = i;
      }
    }
    if (!(best > degTol()))
      throw std::invalid_argument("Convex::Convex: points are degenerate (all coplanar within tolerance)");
    // Orient so every face normal points away from the fourth vertex.
    if (signedBest > 0) std::swap(i1, i2);  // now i3 lies below plane (i0, i1, i2)
    makeTri(i0, i1, i2);
    makeTri(i0, i3, i1);
    makeTri(i1, i3, i2);
    makeTri(i2, i3, i0);
    // Distribute the points over the faces (each point to the face it is farthest above).
    std::vector<uint32_t> all(n);
    std::iota(all.begin(), all.end(), 0u);
    assignOutside(all, 0);
  }

  /// Gives each point in `cand` to the live face created at index >= firstTri that it is farthest above;
  /// points above none are inside the (current) hull and dropped for good.
  void assignOutside(const std::vector<uint32_t>& cand, size_t firstTri) {
    for (uint32_t p : cand) {
      Real best = tol_;
      size_t bestTri = SIZE_MAX;
      for (size_t t = firstTri; t < tris_.size(); ++t) {
        if (!tris_[t].alive) continue;
        const Real d = dist(tris_[t], p);
        if (d > best) {
          best = d;
          bestTri = t;
        }
      }
      if (bestTri != SIZE_MAX) tris_[bestTri].outside.push_back(p);
    }
  }

  void addPoint(size_t fi) {
    // Farthest outside point of this face: the new hull vertex.
    HullTri& f = tris_[fi];
    uint32_t eye = f.outside[0];
    Real best = dist(f, eye);
    for (uint32_t p : f.outside) {
      const Real d = dist(f, p);
      if (d > best) {
        best = d;
        eye = p;
      }
    }
    // Visible set: flood fill from fi over neighbours the eye sees (distance > tol). Flooding (rather than
    // testing every face) keeps the visible region connected, so the horizon is a single loop.
    visible_.clear();
    visible_.push_back(uint32_t(fi));
    tris_[fi].alive = false;  // mark as visited/visible
    for (size_t k = 0; k < visible_.size(); ++k) {
      const HullTri& t = tris_[visible_[k]];
      for (int e = 0; e < 3; ++e) {
        auto it = edges_.find(edgeKey(t.v[(e + 1) % 3], t.v[e]));
        if (it == edges_.end()) continue;
        const uint32_t nb = it->second;
        if (!tris_[nb].alive) continue;
        if (dist(tris_[nb], eye) > tol_) {
          tris_[nb].alive = false;
          visible_.push_back(nb);
        }
      }
    }
    // Horizon: edges of visible faces whose neighbour survives. Collect orphaned points at the same time.
    horizon_.clear();
    orphans_.clear();
    for (uint32_t vi : visible_) {
      HullTri& t = tris_[vi];
      for (int e = 0; e < 3; ++e) {
        const uint32_t a = t.v[e], b = t.v[(e + 1) % 3];
        auto it = edges_.find(edgeKey(b, a));
        if (it != edges_.end() && tris_[it->second].alive) horizon_.push_back({a, b});
      }
      for (uint32_t p : t.outside)
        if (p != eye) orphans_.push_back(p);
      t.outside.clear();
      t.outside.shrink_to_fit();
    }
    for (uint32_t vi : visible_) {
      const HullTri& t = tris_[vi];
      for (int e = 0; e < 3; ++e) {
        auto it = edges_.find(edgeKey(t.v[e], t.v[(e + 1) % 3]));
        if (it != edges_.end() && it->second == vi) edges_.erase(it);
      }
    }
    // Cone from the eye over the horizon; each new face keeps the horizon edge's orientation.
    const size_t first = tris_.size();
    for (const auto& [a, b] : horizon_) makeTri(a, b, eye);
    assignOutside(orphans_, first);
  }

  Real degTol() const { return 10 * tol_; }

  const std::vector<Vec3>& pts_;
  Real tol_;
  std::vector<HullTri> tris_;
  std::unordered_map<uint64_t, uint32_t> edges_;  // directed edge (a -> b) -> face owning it
  std::vector<uint32_t> visible_, orphans_;
  std::vector<std::pair<uint32_t, uint32_t>> horizon_;
};

}  // namespace

Convex::Convex(const std::vector<Vec3>& points) : Shape(CONVEX) {
  constexpr const char* where = "Convex::Convex";
  if (points.size() < 4)
    detail::throwInvalid(where, "points.size()", (long long)points.size(), "need at least 4 non-coplanar points");
  for (size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite()) detail::throwInvalid(where, "points[" + std::to_string(i) + "]", points[i], "must be finite");

  // Tolerance: a few ulps of the coordinate magnitude, widened so rounding in the plane of nearly coplanar
  // points (e.g. a rotated box's face) is not mistaken for a real fold. Relative to the extent of the cloud.
  Vec3 lo = points[0], hi = points[0], maxAbs = Vec3::Zero();
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    maxAbs = maxAbs.cwiseMax(p.cwiseAbs());
  }
  const Real scale = maxAbs.sum() + (hi - lo).maxCoeff();
  const Real tol = 64 * DBL_EPSILON * scale;

  QuickHull qh(points, tol);
  std::vector<std::array<uint32_t, 3>> tris = qh.run();

  // Compact the vertex list to hull vertices only.
  std::vector<uint32_t> remap(points.size(), UINT32_MAX);
  for (auto& t : tris)
    for (uint32_t& v : t) {
      if (remap[v] == UINT32_MAX) {
        remap[v] = uint32_t(verts_.size());
        verts_.push_back(points[v]);
      }
      v = remap[v];
    }

  // --- merge coplanar neighbours into polygons (union-find over triangles) ---------------------------------
  const size_t nt = tris.size();
  std::vector<Vec3> tn(nt);
  std::vector<Real> td(nt);
  for (size_t i = 0; i < nt; ++i) {
    const Vec3& a = verts_[tris[i][0]];
    const Vec3& b = verts_[tris[i][1]];
    const Vec3& c = verts_[tris[i][2]];
    tn[i] = (b - a).cross(c - a).normalized();
    td[i] = tn[i].dot((a + b + c) / 3.0);
  }
  std::unordered_map<uint64_t, uint32_t> edgeTri;
  for (size_t i = 0; i < nt; ++i)
    for (int e = 0; e < 3; ++e) edgeTri[edgeKey(tris[i][e], tris[i][(e + 1) % 3])] = uint32_t(i);
  std::vector<uint32_t> parent(nt);
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  // Merge when the neighbour's far vertex lies within a small distance of this triangle's plane (and vice
  // versa) and the normals agree: then the two are one face up to rounding.
  const Real mergeTol = 16 * tol;
  for (size_t i = 0; i < nt; ++i)
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = tris[i][e], b = tris[i][(e + 1) % 3];
      auto it = edgeTri.find(edgeKey(b, a));
      if (it == edgeTri.end() || it->second < i) continue;
      const uint32_t j = it->second;
      if (tn[i].dot(tn[j]) < 1 - 1e-10) continue;
      bool coplanar = true;
      for (int k = 0; k < 3 && coplanar; ++k) {
        coplanar = std::abs(tn[i].dot(verts_[tris[j][k]]) - td[i]) <= mergeTol &&
                   std::abs(tn[j].dot(verts_[tris[i][k]]) - td[j]) <= mergeTol;
      }
      if (coplanar) parent[find(uint32_t(i))] = find(j);
    }

  // Group triangles, then walk each group's boundary (directed edges whose reverse is not in the group).
  std::unordered_map<uint32_t, std::vector<uint32_t>> groups;
  std::vector<uint32_t> groupOrder;
  for (uint32_t i = 0; i < nt; ++i) {
    const uint32_t r = find(i);
    auto [it, inserted] = groups.try_emplace(r);
    if (inserted) groupOrder.push_back(r);
    it->second.push_back(i);
  }
  auto addTriangleFace = [&](uint32_t t) {
    Face f;
    f.vertices = {tris[t][0], tris[t][1], tris[t][2]};
    f.normal = tn[t];
    f.offset = td[t];
    faces_.push_back(std::move(f));
  };
  for (uint32_t r : groupOrder) {
    const std::vector<uint32_t>& g = groups[r];
    if (g.size() == 1) {
      addTriangleFace(g[0]);
      continue;
    }
    std::unordered_map<uint64_t, bool> inGroup;
    for (uint32_t t : g)
      for (int e = 0; e < 3; ++e) inGroup[edgeKey(tris[t][e], tris[t][(e + 1) % 3])] = true;
    std::unordered_map<uint32_t, uint32_t> next;  // boundary: start vertex -> end vertex
    bool simple = true;
    for (uint32_t t : g)
      for (int e = 0; e < 3; ++e) {
        const uint32_t a = tris[t][e], b = tris[t][(e + 1) % 3];
        if (inGroup.count(edgeKey(b, a))) continue;
        if (!next.emplace(a, b).second) simple = false;  // a vertex with two outgoing boundary edges
      }
    Face f;
    if (simple && !next.empty()) {
      uint32_t start = next.begin()->first;
      // Deterministic start: the smallest vertex index.
      for (const auto& kv : next) start = std::min(start, kv.first);
      uint32_t v = start;
      do {
        f.vertices.push_back(v);
        auto it = next.find(v);
        if (it == next.end() || f.vertices.size() > next.size()) {
          simple = false;
          break;
        }
        v = it->second;
      } while (v != start);
      if (f.vertices.size() != next.size()) simple = false;
    }
    if (!simple) {
      // Not a single loop (should not happen for a convex hull): keep the triangles unmerged.
      for (uint32_t t : g) addTriangleFace(t);
      continue;
    }
    // Newell's method: area-weighted normal of the polygon, robust for nearly-planar loops.
    Vec3 nrm = Vec3::Zero();
    Vec3 centre = Vec3::Zero();
    for (size_t k = 0; k < f.vertices.size(); ++k) {
      const Vec3& p = verts_[f.vertices[k]];
      const Vec3& q = verts_[f.vertices[(k + 1) % f.vertices.size()]];
      nrm += Vec3((p.y() - q.y()) * (p.z() + q.z()), (p.z() - q.z()) * (p.x() + q.x()),
                  (p.x() - q.x()) * (p.y() + q.y()));
      centre += p;
    }
    f.normal = nrm.normalized();
    f.offset = f.normal.dot(centre / Real(f.vertices.size()));
    faces_.push_back(std::move(f));
  }

  // Drop vertices that ended up strictly inside a merged face (referenced by no polygon).
  std::vector<uint32_t> used(verts_.size(), UINT32_MAX);
  std::vector<Vec3> kept;
  for (Face& f : faces_)
    for (uint32_t& v : f.vertices) {
      if (used[v] == UINT32_MAX) {
        used[v] = uint32_t(kept.size());
        kept.push_back(verts_[v]);
      }
      v = used[v];
    }
  verts_ = std::move(kept);

  volume_ = computeMassProperties(1.0).mass;
  if (!(volume_ > 0)) throw std::invalid_argument("Convex::Convex: points are degenerate (zero hull volume)");
}

Real Convex::getVolume() const { return volume_; }

MassProperties Convex::computeMassProperties(Real density) const {
  // Reference point o = vertex mean; integrate in coordinates relative to o to limit cancellation.
  Vec3 o = Vec3::Zero();
  for (const Vec3& v : verts_) o += v;
  o /= Real(std::max<size_t>(1, verts_.size()));

  // Canonical tetrahedron (0, e1, e2, e3): ∫ x x^T dV = 1/120 [[2,1,1],[1,2,1],[1,1,2]]. A tetrahedron
  // (0, a, b, c) is the image under A = [a b c], so its second moment is det(A)/120 · A M A^T, its volume
  // det(A)/6 and its first moment det(A)/24 (a + b + c). Signed dets make the sum over the fan triangles of
  // every face the integral over the solid (divergence theorem).
  Mat3 m;
  m << 2, 1, 1, 1, 2, 1, 1, 1, 2;
  Real vol = 0;
  Vec3 first = Vec3::Zero();
  Mat3 second = Mat3::Zero();
  for (const Face& f : faces_) {
    const Vec3 a = verts_[f.vertices[0]] - o;
    for (size_t k = 1; k + 1 < f.vertices.size(); ++k) {
      Mat3 A;
      A.col(0) = a;
      A.col(1) = verts_[f.vertices[k]] - o;
      A.col(2) = verts_[f.vertices[k + 1]] - o;
      const Real det = A.determinant();
      vol += det / 6.0;
      first += det / 24.0 * (A.col(0) + A.col(1) + A.col(2));
      second += det / 120.0 * (A * m * A.transpose());
    }
  }
  MassProperties mp;
  if (!(vol > 0)) return mp;
  const Vec3 c = first / vol;  // centroid relative to o
  // Shift the second moment to the centroid: C_cm = C_o - V c c^T.
  const Mat3 ccm = second - vol * c * c.transpose();
  mp.mass = density * vol;
  mp.cm = o + c;
  mp.inertia = density * inertiaFromCovariance(ccm);
  mp.inertia = 0.5 * (mp.inertia + mp.inertia.transpose()).eval();
  return mp;
}

Aabb Convex::getBoundingBox(const Transform& t) const {
  Aabb b;
  const Mat3 r = t.q.toRotationMatrix();
  for (const Vec3& v : verts_) b.expand(r * v + t.p);
  return b;
}

Vec3 Convex::support(const Vec3& dir) const {
  // Linear scan: hulls here are small (tens to hundreds of vertices); hill climbing over an adjacency
  // graph would pay off only for much larger hulls.
  size_t best = 0;
  Real bestDot = -std::numeric_limits<Real>::infinity();
  for (size_t i = 0; i < verts_.size(); ++i) {
    const Real d = verts_[i].dot(dir);
    if (d > bestDot) {
      bestDot = d;
      best = i;
    }
  }
  return verts_[best];
}

// ---------------------------------------------------------------------------------------------------------
// HeightField
// ---------------------------------------------------------------------------------------------------------

HeightField::HeightField(size_t resolutionX, size_t resolutionY, Real sizeX, Real sizeY)
    : Shape(HEIGHT_FIELD), nx_(2), ny_(2), sx_(1), sy_(1) {
  constexpr const char* where = "HeightField::HeightField";
  if (resolutionX < 2) detail::throwInvalid(where, "resolutionX", (long long)resolutionX, "must be >= 2");
  if (resolutionY < 2) detail::throwInvalid(where, "resolutionY", (long long)resolutionY, "must be >= 2");
  detail::requirePositive(where, "sizeX", sizeX);
  detail::requirePositive(where, "sizeY", sizeY);
  // Guard the product against overflow and absurd allocations before resizing.
  if (resolutionX > (size_t(1) << 31) || resolutionY > (size_t(1) << 31) ||
      resolutionX * resolutionY > (size_t(1) << 34))
    detail::throwInvalid(where, "resolutionX * resolutionY", (long long)(resolutionX * resolutionY),
                         "too large");
  nx_ = resolutionX;
  ny_ = resolutionY;
  sx_ = sizeX;
  sy_ = sizeY;
  h_.assign(nx_ * ny_, 0.0);
  tilesX_ = std::max<size_t>(1, (nx_ - 2) / kTileSize + 1);
  tilesY_ = std::max<size_t>(1, (ny_ - 2) / kTileSize + 1);
  tileMin_.assign(tilesX_ * tilesY_, 0.0);
  tileMax_.assign(tilesX_ * tilesY_, 0.0);
  const Real cx = getCellSizeX(), cy = getCellSizeY();
  if (std::abs(cx - cy) > 1e-9 * std::max(cx, cy)) {
    std::ostringstream s;
    s.precision(17);
    s << "HeightField: height field has different x and y scale (cell size x = " << cx << " m, y = " << cy
      << " m); contacts and terrain operations assume square cells";
    Logger::warning(s.str());
  }
}

void HeightField::setHeight(size_t i, size_t j, Real h) {
  constexpr const char* where = "HeightField::setHeight";
  if (i >= nx_) detail::throwInvalid(where, "i", (long long)i, "must be < resolutionX = " + std::to_string(nx_));
  if (j >= ny_) detail::throwInvalid(where, "j", (long long)j, "must be < resolutionY = " + std::to_string(ny_));
  detail::requireFinite(where, "height", h);
  h_[j * nx_ + i] = h;
  markDirty(i, j, i, j);
}

void HeightField::setHeights(const std::vector<Real>& heights) {
  constexpr const char* where = "HeightField::setHeights";
  if (heights.size() != nx_ * ny_)
    detail::throwInvalid(where, "heights.size()", (long long)heights.size(),
                         "must equal resolutionX * resolutionY = " + std::to_string(nx_ * ny_));
  for (size_t k = 0; k < heights.size(); ++k)
    if (!std::isfinite(heights[k]))
      detail::throwInvalid(where, "heights[" + std::to_string(k) + "]", heights[k], "must be finite");
  h_ = heights;
  markDirty(0, 0, nx_ - 1, ny_ - 1);
}

void HeightField::setHeights(size_t i0, size_t j0, size_t i1, size_t j1, const std::vector<Real>& values) {
  constexpr const char* where = "HeightField::setHeights";
  if (i1 >= nx_) detail::throwInvalid(where, "i1", (long long)i1, "must be < resolutionX = " + std::to_string(nx_));
  if (j1 >= ny_) detail::throwInvalid(where, "j1", (long long)j1, "must be < resolutionY = " + std::to_string(ny_));
  if (i0 > i1) detail::throwInvalid(where, "i0", (long long)i0, "must be <= i1 = " + std::to_string(i1));
  if (j0 > j1) detail::throwInvalid(where, "j0", (long long)j0, "must be <= j1 = " + std::to_string(j1));
  const size_t w = i1 - i0 + 1, n = w * (j1 - j0 + 1);
  if (values.size() != n)
    detail::throwInvalid(where, "values.size()", (long long)values.size(),
                         "must equal (i1 - i0 + 1) * (j1 - j0 + 1) = " + std::to_string(n));
  for (size_t k = 0; k < n; ++k)
    if (!std::isfinite(values[k]))
      detail::throwInvalid(where, "values[" + std::to_string(k) + "]", values[k], "must be finite");
  for (size_t j = j0; j <= j1; ++j)
    std::copy_n(values.begin() + std::ptrdiff_t((j - j0) * w), w, h_.begin() + std::ptrdiff_t(j * nx_ + i0));
  markDirty(i0, j0, i1, j1);
}

namespace {
void growRect(HeightField::Rect& r, size_t i0, size_t j0, size_t i1, size_t j1) {
  if (r.empty()) {
    r = {i0, j0, i1, j1};
    return;
  }
  r.i0 = std::min(r.i0, i0);
  r.j0 = std::min(r.j0, j0);
  r.i1 = std::max(r.i1, i1);
  r.j1 = std::max(r.j1, j1);
}
}  // namespace

void HeightField::markDirty(size_t i0, size_t j0, size_t i1, size_t j1) {
  growRect(dirty_, i0, j0, i1, j1);
  growRect(pending_, i0, j0, i1, j1);
  if (editDepth_ == 0) {
    updateBounds(pending_);
    pending_ = Rect{};
  }
  touch();
}

void HeightField::endHeightEdit() {
  if (editDepth_ == 0) return;
  if (--editDepth_ == 0 && !pending_.empty()) {
    updateBounds(pending_);
    pending_ = Rect{};
  }
}

void HeightField::updateBounds() { updateBounds(Rect{0, 0, nx_ - 1, ny_ - 1}); }

void HeightField::updateBounds(const Rect& r) {
  // A vertex on a tile seam belongs to both tiles: recompute every tile whose vertex range meets the rectangle.
  const size_t T = kTileSize;
  const size_t ti0 = r.i0 == 0 ? 0 : std::min((r.i0 - 1) / T, tilesX_ - 1);
  const size_t tj0 = r.j0 == 0 ? 0 : std::min((r.j0 - 1) / T, tilesY_ - 1);
  const size_t ti1 = std::min(r.i1 / T, tilesX_ - 1), tj1 = std::min(r.j1 / T, tilesY_ - 1);
  for (size_t tj = tj0; tj <= tj1; ++tj)
    for (size_t ti = ti0; ti <= ti1; ++ti) {
      const size_t ia = ti * T, ib = std::min(ia + T, nx_ - 1);
      const size_t ja = tj * T, jb = std::min(ja + T, ny_ - 1);
      Real mn = h_[ja * nx_ + ia], mx = mn;
      for (size_t j = ja; j <= jb; ++j) {
        const auto row = h_.begin() + std::ptrdiff_t(j * nx_);
        auto [lo, hi] = std::minmax_element(row + std::ptrdiff_t(ia), row + std::ptrdiff_t(ib + 1));
        mn = std::min(mn, *lo);
        mx = std::max(mx, *hi);
      }
      tileMin_[tj * tilesX_ + ti] = mn;
      tileMax_[tj * tilesX_ + ti] = mx;
    }
  minH_ = *std::min_element(tileMin_.begin(), tileMin_.end());
  maxH_ = *std::max_element(tileMax_.begin(), tileMax_.end());
}

Vec3 HeightField::getVertex(size_t i, size_t j) const {
  return Vec3(-0.5 * sx_ + Real(i) * getCellSizeX(), -0.5 * sy_ + Real(j) * getCellSizeY(), getHeight(i, j));
}

Real HeightField::getHeightAt(Real x, Real y) const {
  const Real u = (x + 0.5 * sx_) / getCellSizeX();
  const Real v = (y + 0.5 * sy_) / getCellSizeY();
  // Accept points a hair outside so the border itself (x = +-sizeX/2) is inside despite rounding.
  const Real eps = 1e-9;
  if (!(u >= -eps && v >= -eps && u <= Real(nx_ - 1) + eps && v <= Real(ny_ - 1) + eps))
    return std::numeric_limits<Real>::quiet_NaN();
  const size_t i = std::min(size_t(std::max<Real>(0, std::floor(u))), nx_ - 2);
  const size_t j = std::min(size_t(std::max<Real>(0, std::floor(v))), ny_ - 2);
  const Real fu = std::clamp(u - Real(i), Real(0), Real(1));
  const Real fv = std::clamp(v - Real(j), Real(0), Real(1));
  const Real h00 = getHeight(i, j), h10 = getHeight(i + 1, j), h01 = getHeight(i, j + 1),
             h11 = getHeight(i + 1, j + 1);
  // The diagonal (i,j)-(i+1,j+1) splits the cell: below it (fu >= fv) the triangle (00, 10, 11), above it
  // (00, 01, 11). Linear interpolation on each triangle.
  if (fu >= fv) return h00 + fu * (h10 - h00) + fv * (h11 - h10);
  return h00 + fv * (h01 - h00) + fu * (h11 - h01);
}

Aabb HeightField::getBoundingBox(const Transform& t) const {
  Aabb b;
  const Real lz = std::min(minH_, maxH_), hz = std::max(minH_, maxH_);
  for (int c = 0; c < 8; ++c) {
    const Vec3 p((c & 1) ? 0.5 * sx_ : -0.5 * sx_, (c & 2) ? 0.5 * sy_ : -0.5 * sy_, (c & 4) ? hz : lz);
    b.expand(t.apply(p));
  }
  return b;
}

// ---------------------------------------------------------------------------------------------------------
// Line
// ---------------------------------------------------------------------------------------------------------

namespace {
void validateLine(const char* where, const Vec3& p1, const Vec3& p2) {
  detail::requireFinite(where, "p1", p1);
  detail::requireFinite(where, "p2", p2);
  if (!((p2 - p1).norm() > 0)) detail::throwInvalid(where, "p2", p2, "must differ from p1 (zero-length line)");
}
}  // namespace

Line::Line(const Vec3& p1, const Vec3& p2) : Shape(LINE), p1_(Vec3::Zero()), p2_(Vec3::UnitX()) {
  validateLine("Line::Line", p1, p2);
  p1_ = p1;
  p2_ = p2;
}

void Line::set(const Vec3& p1, const Vec3& p2) {
  validateLine("Line::set", p1, p2);
  p1_ = p1;
  p2_ = p2;
  touch();
}

Aabb Line::getBoundingBox(const Transform& t) const {
  Aabb b;
  b.expand(t.apply(p1_));
  b.expand(t.apply(p2_));
  return b;
}

Vec3 Line::support(const Vec3& dir) const { return p1_.dot(dir) >= p2_.dot(dir) ? p1_ : p2_; }

}  // namespace scree
