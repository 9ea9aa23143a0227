// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Shapes: volumes and mass properties against closed forms, body mass aggregation, AABBs, quickhull
// invariants, height-field interpolation and the unequal-scale warning.
//
// Tolerances: closed forms are evaluated in double precision with a handful of operations, so the shapes must
// agree to ~1e-12 relative. Quickhull-derived values for exactly representable inputs (cube corners) are
// also exact to rounding. Rotated inputs carry rounding in every coordinate (~1e-16 relative), so 1e-10.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <set>

#include "scree/collide/geometry.h"
#include "scree/collide/shapes.h"
#include "scree/core/logger.h"
#include "scree/core/material.h"
#include "scree/core/rigid_body.h"

using namespace scree;

namespace {

constexpr Real kPi = std::numbers::pi_v<Real>;

bool closeRel(Real a, Real b, Real tol) { return std::abs(a - b) <= tol * std::max({std::abs(a), std::abs(b), Real(1e-300)}); }

void checkMat(const Mat3& a, const Mat3& b, Real tol) {
  const Real scale = std::max(a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff());
  INFO("a =\n" << a << "\nb =\n" << b);
  CHECK((a - b).cwiseAbs().maxCoeff() <= tol * scale);
}

/// Solid of revolution about y with squared-radius profile rho2(y) on [y0, y1]: mass properties at unit
/// density by 3-point Gauss-Legendre (exact for polynomials up to degree 5; the capsule's profile pieces are
/// polynomials of degree <= 4 in the integrands used). Independent of the closed forms in shapes.cpp.
struct RevolutionIntegral {
  Real mass = 0, axial = 0, transverse = 0;
  template <class F>
  void add(F rho2, Real y0, Real y1, int pieces = 8) {
    const Real xg[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)};
    const Real wg[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
    const Real step = (y1 - y0) / pieces;
    for (int p = 0; p < pieces; ++p) {
      const Real a = y0 + p * step, half = 0.5 * step, mid = a + half;
      for (int k = 0; k < 3; ++k) {
        const Real y = mid + half * xg[k], w = wg[k] * half;
        const Real r2 = rho2(y);
        // Thin disc at height y: area pi r^2, axial moment pi r^4/2, transverse pi r^4/4 + pi r^2 y^2.
        mass += w * kPi * r2;
        axial += w * kPi * r2 * r2 / 2;
        transverse += w * (kPi * r2 * r2 / 4 + kPi * r2 * y * y);
      }
    }
  }
};

Quat randomRotation(std::mt19937& rng) {
  std::normal_distribution<Real> n(0, 1);
  return Quat(n(rng), n(rng), n(rng), n(rng)).normalized();
}

}  // namespace

TEST_SUITE("collide") {

TEST_CASE("sphere volume and inertia match 4/3 pi r^3 and 2/5 m r^2") {
  Sphere s(0.3);
  const Real rho = 2700;
  const Real v = 4.0 / 3.0 * kPi * 0.027;
  CHECK(closeRel(s.getVolume(), v, 1e-14));
  MassProperties mp = s.computeMassProperties(rho);
  CHECK(closeRel(mp.mass, rho * v, 1e-14));
  checkMat(mp.inertia, Mat3::Identity() * 0.4 * mp.mass * 0.09, 1e-14);
  CHECK(mp.cm.norm() == 0);
}

TEST_CASE("box inertia is m/12 (b^2 + c^2) with full side lengths") {
  Box b(Vec3(0.5, 1.0, 1.5));
  const Real a = 1, bb = 2, c = 3, rho = 7.5;
  CHECK(closeRel(b.getVolume(), a * bb * c, 1e-15));
  MassProperties mp = b.computeMassProperties(rho);
  const Real m = rho * 6;
  CHECK(closeRel(mp.mass, m, 1e-15));
  Mat3 ref = Mat3::Zero();
  ref.diagonal() << m / 12 * (bb * bb + c * c), m / 12 * (a * a + c * c), m / 12 * (a * a + bb * bb);
  checkMat(mp.inertia, ref, 1e-14);
}

TEST_CASE("cylinder inertia: m r^2/2 about the y axis and m(3r^2+h^2)/12 across") {
  const Real r = 0.4, h = 1.7, rho = 900;
  Cylinder cyl(r, h);
  const Real m = rho * kPi * r * r * h;
  CHECK(closeRel(cyl.getVolume(), kPi * r * r * h, 1e-14));
  MassProperties mp = cyl.computeMassProperties(rho);
  CHECK(closeRel(mp.mass, m, 1e-14));
  CHECK(closeRel(mp.inertia(1, 1), m * r * r / 2, 1e-14));
  CHECK(closeRel(mp.inertia(0, 0), m * (3 * r * r + h * h) / 12, 1e-14));
  CHECK(closeRel(mp.inertia(2, 2), m * (3 * r * r + h * h) / 12, 1e-14));
  CHECK(mp.inertia(0, 1) == 0);
}

TEST_CASE("capsule mass properties match an independent integration over discs") {
  const Real r = 0.25, h = 1.1;
  Capsule cap(r, h);
  RevolutionIntegral ref;
  // Bottom hemisphere centred at -h/2, cylinder, top hemisphere centred at +h/2.
  ref.add([&](Real y) { const Real d = y + h / 2; return r * r - d * d; }, -h / 2 - r, -h / 2);
  ref.add([&](Real) { return r * r; }, -h / 2, h / 2);
  ref.add([&](Real y) { const Real d = y - h / 2; return r * r - d * d; }, h / 2, h / 2 + r);
  CHECK(closeRel(cap.getVolume(), ref.mass, 1e-12));
  MassProperties mp = cap.computeMassProperties(1.0);
  CHECK(closeRel(mp.mass, ref.mass, 1e-12));
  CHECK(closeRel(mp.inertia(1, 1), ref.axial, 1e-12));
  CHECK(closeRel(mp.inertia(0, 0), ref.transverse, 1e-12));
  CHECK(closeRel(mp.inertia(2, 2), ref.transverse, 1e-12));
  // Textbook closed form as a second reference (hemisphere centroid 3r/8 from its base).
  const Real mc = kPi * r * r * h, mh = 2.0 / 3.0 * kPi * r * r * r;
  const Real ixx = mc * (h * h / 12 + r * r / 4) + 2 * mh * (2 * r * r / 5 + h * h / 4 + 3 * h * r / 8);
  CHECK(closeRel(mp.inertia(0, 0), ixx, 1e-12));
}

TEST_CASE("convex hull of a cube's corners plus interior points equals the Box exactly") {
  std::vector<Vec3> pts;
  const Vec3 he(0.5, 0.75, 1.25);
  for (int c = 0; c < 8; ++c)
    pts.emplace_back((c & 1) ? he.x() : -he.x(), (c & 2) ? he.y() : -he.y(), (c & 4) ? he.z() : -he.z());
  std::mt19937 rng(7);
  std::uniform_real_distribution<Real> u(-1, 1);
  for (int k = 0; k < 200; ++k) pts.push_back(he.cwiseProduct(Vec3(u(rng), u(rng), u(rng))) * 0.999);
  // Points on faces and edges must not create extra faces either.
  pts.emplace_back(0, 0, he.z());
  pts.emplace_back(he.x(), 0, 0);
  std::shuffle(pts.begin(), pts.end(), rng);

  Convex cvx(pts);
  Box box(he);
  CHECK(cvx.getFaces().size() == 6);
  for (const auto& f : cvx.getFaces()) {
    CHECK(f.vertices.size() == 4);
    CHECK(std::abs(f.normal.cwiseAbs().maxCoeff() - 1) < 1e-15);
  }
  CHECK(cvx.getVertices().size() == 8);
  CHECK(closeRel(cvx.getVolume(), box.getVolume(), 1e-12));
  MassProperties a = cvx.computeMassProperties(1234.0), b = box.computeMassProperties(1234.0);
  CHECK(closeRel(a.mass, b.mass, 1e-12));
  CHECK(a.cm.norm() <= 1e-12);
  checkMat(a.inertia, b.inertia, 1e-12);
  for (int k = 0; k < 3; ++k) {
    Vec3 d = Vec3::Zero();
    d[k] = 1;
    CHECK((cvx.support(d) - box.support(d)).norm() < 1e-15);
  }
}

TEST_CASE("convex hull of a randomly rotated, offset box has the rotated box inertia") {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 5; ++trial) {
    const Quat q = randomRotation(rng);
    const Vec3 off(0.3 * trial, -1.0, 2.5);
    const Vec3 he(0.2 + 0.1 * trial, 0.7, 0.45);
    std::vector<Vec3> pts;
    for (int c = 0; c < 8; ++c)
      pts.push_back(q * Vec3((c & 1) ? he.x() : -he.x(), (c & 2) ? he.y() : -he.y(), (c & 4) ? he.z() : -he.z()) + off);
    Convex cvx(pts);
    MassProperties a = cvx.computeMassProperties(500.0);
    MassProperties b = Box(he).computeMassProperties(500.0);
    const Mat3 r = q.toRotationMatrix();
    CHECK(closeRel(a.mass, b.mass, 1e-10));
    CHECK((a.cm - off).norm() <= 1e-10);
    checkMat(a.inertia, r * b.inertia * r.transpose(), 1e-10);
    CHECK(cvx.getFaces().size() == 6);  // rounding-level non-planarity is merged
    // The world AABB of the convex equals the rotated box AABB.
    Transform t{Vec3(1, 2, 3), randomRotation(rng)};
    Aabb ca = cvx.getBoundingBox(t);
    Transform tb{t.apply(off), t.q * q};
    Aabb ba = Box(he).getBoundingBox(tb);
    CHECK((ca.lo - ba.lo).norm() < 1e-12);
    CHECK((ca.hi - ba.hi).norm() < 1e-12);
  }
}

TEST_CASE("tetrahedron mass properties match the closed form for a right tetrahedron") {
  // Right tetrahedron with legs a on the axes: V = a^3/6, centroid a/4 (1,1,1), and about the centroid
  // I_xx = 3/40 m a^2 (all three), products of inertia I_xy = +m a^2 / 80 (tensor entry -∫xy = +).
  const Real a = 2.0, rho = 3.0;
  std::vector<Vec3> pts = {Vec3::Zero(), Vec3(a, 0, 0), Vec3(0, a, 0), Vec3(0, 0, a)};
  Convex t(pts);
  const Real m = rho * a * a * a / 6;
  MassProperties mp = t.computeMassProperties(rho);
  CHECK(closeRel(mp.mass, m, 1e-14));
  CHECK((mp.cm - Vec3::Constant(a / 4)).norm() < 1e-14);
  Mat3 ref;
  const Real d = 3.0 / 40.0 * m * a * a, o = m * a * a / 80;
  ref << d, o, o, o, d, o, o, o, d;
  checkMat(mp.inertia, ref, 1e-13);
  CHECK(t.getFaces().size() == 4);
  // Faces point outward and are CCW seen from outside: Newell normal along the stored normal.
  for (const auto& f : t.getFaces()) {
    const Vec3& p0 = t.getVertices()[f.vertices[0]];
    const Vec3& p1 = t.getVertices()[f.vertices[1]];
    const Vec3& p2 = t.getVertices()[f.vertices[2]];
    CHECK((p1 - p0).cross(p2 - p0).normalized().dot(f.normal) > 1 - 1e-12);
    CHECK(f.normal.dot(mp.cm) < f.offset);
  }
}

TEST_CASE("quickhull of points on a sphere contains every point and is a closed polyhedron") {
  std::mt19937 rng(3);
  std::normal_distribution<Real> n(0, 1);
  for (int count : {10, 100, 2000}) {
    std::vector<Vec3> pts;
    for (int i = 0; i < count; ++i) pts.push_back(Vec3(n(rng), n(rng), n(rng)).normalized() * 2.0 + Vec3(5, -3, 1));
    Convex c(pts);
    const auto& V = c.getVertices();
    const auto& F = c.getFaces();
    // All input points inside or on the hull.
    Real worst = -1e300;
    for (const Vec3& p : pts)
      for (const auto& f : F) worst = std::max(worst, f.normal.dot(p) - f.offset);
    CHECK(worst <= 1e-12);
    // Every face's vertices lie on its plane.
    for (const auto& f : F)
      for (uint32_t v : f.vertices) CHECK(std::abs(f.normal.dot(V[v]) - f.offset) <= 1e-12);
    // Euler characteristic of a closed polyhedron (polygon faces): V - E + F = 2, each edge shared by two
    // faces with opposite directions.
    std::set<std::pair<uint32_t, uint32_t>> edges;
    size_t halfEdges = 0;
    for (const auto& f : F)
      for (size_t k = 0; k < f.vertices.size(); ++k) {
        edges.insert({f.vertices[k], f.vertices[(k + 1) % f.vertices.size()]});
        ++halfEdges;
      }
    CHECK(edges.size() == halfEdges);  // no directed edge twice
    for (const auto& [a, b] : edges) CHECK(edges.count({b, a}) == 1);
    const long E = long(halfEdges / 2);
    CHECK(long(V.size()) - E + long(F.size()) == 2);
    // Points on the sphere are all extreme: every one is a hull vertex.
    CHECK(V.size() == pts.size());
    // Volume tends to the sphere's from below.
    CHECK(c.getVolume() < 4.0 / 3.0 * kPi * 8);
    if (count == 2000) CHECK(c.getVolume() > 0.98 * 4.0 / 3.0 * kPi * 8);
  }
}

TEST_CASE("body mass properties: two offset spheres use the parallel-axis theorem") {
  // Spheres of radius r at x = -d (density 1000, default) and at y = +e (density 3000). Hand computation:
  //   m1 = 1000 V, m2 = 3000 V, V = 4/3 pi r^3; cm = (m1 (-d,0,0) + m2 (0,e,0)) / (m1 + m2)
  //   I = sum [2/5 m_i r^2 1 + m_i (|s_i|^2 1 - s_i s_i^T)], s_i = c_i - cm.
  const Real r = 0.1, d = 0.5, e = 0.3;
  auto body = std::make_shared<RigidBody>("b");
  auto g1 = std::make_shared<Geometry>(std::make_shared<Sphere>(r));
  auto g2 = std::make_shared<Geometry>(std::make_shared<Sphere>(r));
  g1->setLocalPosition(Vec3(-d, 0, 0));
  g2->setLocalPosition(Vec3(0, e, 0));
  auto heavy = std::make_shared<Material>("heavy");
  heavy->setDensity(3000);
  g2->setMaterial(heavy);
  body->add(g1);
  body->add(g2);
  const Real V = 4.0 / 3.0 * kPi * r * r * r, m1 = 1000 * V, m2 = 3000 * V, m = m1 + m2;
  const Vec3 cm = (m1 * Vec3(-d, 0, 0) + m2 * Vec3(0, e, 0)) / m;
  CHECK(closeRel(body->getMass(), m, 1e-14));
  CHECK((body->getCmLocal() - cm).norm() < 1e-14);
  // By hand: s1 = (-d - cmx, -cmy, 0), s2 = (-cmx, e - cmy, 0).
  const Real cmx = cm.x(), cmy = cm.y();
  const Real s1x = -d - cmx, s1y = -cmy, s2x = -cmx, s2y = e - cmy;
  const Real i0 = 0.4 * r * r;
  Mat3 ref;
  ref << m1 * (i0 + s1y * s1y) + m2 * (i0 + s2y * s2y), -(m1 * s1x * s1y + m2 * s2x * s2y), 0,
      -(m1 * s1x * s1y + m2 * s2x * s2y), m1 * (i0 + s1x * s1x) + m2 * (i0 + s2x * s2x), 0,
      0, 0, m1 * (i0 + s1x * s1x + s1y * s1y) + m2 * (i0 + s2x * s2x + s2y * s2y);
  checkMat(body->getInertiaTensor(), ref, 1e-12);

  // Moving a geometry updates the body at once; a sensor contributes nothing.
  g1->setLocalPosition(Vec3(0, -e, 0));
  CHECK(body->getCmLocal().x() == doctest::Approx(0).epsilon(1e-14));
  g2->setSensor(true);
  body->updateMassProperties();
  CHECK(closeRel(body->getMass(), m1, 1e-14));
  CHECK(body->remove(g2));
  CHECK(!body->remove(g2));
  CHECK(g2->getRigidBody() == nullptr);
  CHECK_THROWS_AS(body->add(nullptr), std::invalid_argument);
  auto other = std::make_shared<RigidBody>();
  CHECK_THROWS_AS(other->add(g1), std::invalid_argument);  // already on `body`
}

TEST_CASE("rotated geometry inertia is R I R^T in the body frame") {
  auto body = std::make_shared<RigidBody>();
  auto g = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.1, 0.2, 0.3)));
  const Quat q(Eigen::AngleAxis<Real>(0.7, Vec3(1, 2, 3).normalized()));
  g->setLocalRotation(q);
  g->setLocalPosition(Vec3(1, 2, 3));
  body->add(g);
  const Mat3 r = q.toRotationMatrix();
  const MassProperties mp = g->getShape()->computeMassProperties(1000);
  checkMat(body->getInertiaTensor(), r * mp.inertia * r.transpose(), 1e-13);
  CHECK((body->getCmLocal() - Vec3(1, 2, 3)).norm() < 1e-14);
  // World transform = body * local.
  body->setPosition(Vec3(10, 0, 0));
  g->updateTransform();
  CHECK((g->getPosition() - Vec3(11, 2, 3)).norm() < 1e-14);
}

TEST_CASE("bounding boxes are tight for rotated boxes, cylinders and capsules") {
  // Box rotated 45 degrees about z: x/y half extent (hx + hy)/sqrt(2).
  const Quat qz(Eigen::AngleAxis<Real>(kPi / 4, Vec3::UnitZ()));
  Transform t{Vec3(1, -2, 3), qz};
  Aabb b = Box(Vec3(1, 2, 0.5)).getBoundingBox(t);
  const Real ex = 3 / std::sqrt(2.0);
  CHECK((b.lo - Vec3(1 - ex, -2 - ex, 2.5)).norm() < 1e-14);
  CHECK((b.hi - Vec3(1 + ex, -2 + ex, 3.5)).norm() < 1e-14);

  // Cylinder (axis y) tipped to lie along x: x extent h/2, y and z extent r.
  const Quat toX(Eigen::AngleAxis<Real>(-kPi / 2, Vec3::UnitZ()));
  Aabb c = Cylinder(0.5, 4).getBoundingBox({Vec3::Zero(), toX});
  CHECK((c.hi - Vec3(2, 0.5, 0.5)).norm() < 1e-14);
  // Tilted 45 degrees in the y-z plane: y and z extent r/sqrt2 + (h/2)/sqrt2; x extent r.
  const Quat tilt(Eigen::AngleAxis<Real>(kPi / 4, Vec3::UnitX()));
  Aabb c2 = Cylinder(0.5, 4).getBoundingBox({Vec3::Zero(), tilt});
  CHECK((c2.hi - Vec3(0.5, 2.5 / std::sqrt(2.0), 2.5 / std::sqrt(2.0))).norm() < 1e-14);
  // Exactness: support points in the axis directions touch the AABB.
  Cylinder cyl(0.5, 4);
  for (int k = 0; k < 3; ++k) {
    Vec3 d = Vec3::Zero();
    d[k] = 1;
    CHECK((tilt * cyl.support(tilt.conjugate() * d))[k] == doctest::Approx(c2.hi[k]).epsilon(1e-14));
  }

  Aabb cp = Capsule(0.25, 2).getBoundingBox({Vec3(0, 0, 1), Quat::Identity()});
  CHECK((cp.lo - Vec3(-0.25, -1.25, 0.75)).norm() < 1e-14);
  CHECK((cp.hi - Vec3(0.25, 1.25, 1.25)).norm() < 1e-14);

  Aabb s = Sphere(2).getBoundingBox({Vec3(1, 1, 1), Quat::Identity()});
  CHECK((s.hi - Vec3(3, 3, 3)).norm() == 0);

  Aabb l = Line(Vec3(0, 0, 0), Vec3(1, 0, 0)).getBoundingBox({Vec3::Zero(), qz});
  CHECK(l.hi.y() == doctest::Approx(std::sqrt(0.5)).epsilon(1e-14));
}

TEST_CASE("plane AABB is bounded only along an axis-aligned normal") {
  Plane ground(Vec3(0, 0, 2), 0.5);  // z <= 0.5 after normalisation
  Aabb a = ground.getBoundingBox({Vec3(0, 0, 1), Quat::Identity()});  // world z <= 1.5
  CHECK(a.hi.z() == doctest::Approx(1.5));
  CHECK(a.lo.z() <= -1e299);
  CHECK(a.hi.x() >= 1e299);
  // Flipped normal: the solid side is above.
  Aabb f = Plane(Vec3(0, 0, -1), 0.0).getBoundingBox({Vec3(0, 0, 3), Quat::Identity()});  // z >= 3
  CHECK(f.lo.z() == doctest::Approx(3));
  CHECK(f.hi.z() >= 1e299);
  // Rotated so the normal is along x.
  Aabb r = Plane(Vec3::UnitZ(), 0).getBoundingBox({Vec3(2, 0, 0), Quat(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitY()))});
  CHECK(r.hi.x() == doctest::Approx(2));
  // Tilted normal: unbounded everywhere.
  Aabb u = Plane(Vec3(1, 0, 1), 0).getBoundingBox({});
  CHECK(u.hi.x() >= 1e299);
  CHECK(u.hi.z() >= 1e299);
}

TEST_CASE("height field interpolates a tilted plane exactly and bounds its corners") {
  const size_t nx = 7, ny = 5;
  HeightField hf(nx, ny, 3.0, 2.0);  // cells 0.5 x 0.5
  auto plane = [](Real x, Real y) { return 0.3 * x - 0.7 * y + 1.0; };
  std::vector<Real> h(nx * ny);
  for (size_t j = 0; j < ny; ++j)
    for (size_t i = 0; i < nx; ++i) h[j * nx + i] = plane(-1.5 + 0.5 * Real(i), -1.0 + 0.5 * Real(j));
  hf.setHeights(h);
  std::mt19937 rng(5);
  std::uniform_real_distribution<Real> ux(-1.5, 1.5), uy(-1.0, 1.0);
  for (int k = 0; k < 200; ++k) {
    const Real x = ux(rng), y = uy(rng);
    CHECK(hf.getHeightAt(x, y) == doctest::Approx(plane(x, y)).epsilon(1e-12));
  }
  CHECK(hf.getHeightAt(1.5, 1.0) == doctest::Approx(plane(1.5, 1.0)));  // the corner itself
  CHECK(std::isnan(hf.getHeightAt(1.6, 0)));
  CHECK(std::isnan(hf.getHeightAt(0, -1.1)));
  CHECK((hf.getVertex(6, 4) - Vec3(1.5, 1.0, plane(1.5, 1.0))).norm() < 1e-14);

  // Diagonal split: raise only vertex (i+1, j) of cell (0, 0); the point (0.25, 0.75) in cell units lies in
  // the upper triangle (00, 01, 11), which does not contain (1, 0), so its height does not change.
  HeightField d(2, 2, 1.0, 1.0);
  d.setHeight(1, 0, 1.0);
  CHECK(d.getHeightAt(-0.25, 0.25) == doctest::Approx(0));  // fu = 0.25 < fv = 0.75
  // fu = 0.75 >= fv = 0.25: triangle (00, 10, 11) is the plane z = u - v in cell units -> 0.5.
  CHECK(d.getHeightAt(0.25, -0.25) == doctest::Approx(0.5));
  CHECK(d.getMaxHeight() == 1.0);
  d.setHeight(1, 0, 0.0);
  CHECK(d.getMaxHeight() == 0.0);

  // AABB: the 8 corners of [-sx/2, sx/2] x [-sy/2, sy/2] x [min, max] transformed.
  Aabb b = hf.getBoundingBox({Vec3(10, 0, 0), Quat::Identity()});
  CHECK(b.lo.x() == doctest::Approx(8.5));
  CHECK(b.hi.y() == doctest::Approx(1.0));
  CHECK(b.hi.z() == doctest::Approx(hf.getMaxHeight()));
  CHECK(b.lo.z() == doctest::Approx(hf.getMinHeight()));
  CHECK(hf.getMinHeight() == doctest::Approx(plane(-1.5, 1.0)));
}

TEST_CASE("height field with unequal x and y spacing warns through the logger sink") {
  std::vector<std::string> messages;
  Logger::setSink([&](LogLevel level, const std::string& m) {
    if (level == LogLevel::WARNING) messages.push_back(m);
  });
  HeightField ok(11, 11, 1.0, 1.0);
  CHECK(messages.empty());
  HeightField skew(11, 6, 1.0, 1.0);  // 0.1 vs 0.2
  Logger::setSink({});
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].find("height field") != std::string::npos);
  CHECK(messages[0].find("scale") != std::string::npos);
}

TEST_CASE("support mappings return the farthest point") {
  std::mt19937 rng(1);
  std::normal_distribution<Real> n(0, 1);
  Capsule cap(0.3, 1.0);
  Cylinder cyl(0.3, 1.0);
  Box box(Vec3(0.1, 0.2, 0.3));
  for (int k = 0; k < 50; ++k) {
    const Vec3 d(n(rng), n(rng), n(rng));
    // Capsule: segment endpoint + r d/|d|.
    const Vec3 sc = cap.support(d);
    CHECK(d.dot(sc) == doctest::Approx(0.5 * std::abs(d.y()) + 0.3 * d.norm()));
    const Vec3 sy = cyl.support(d);
    CHECK(d.dot(sy) == doctest::Approx(0.5 * std::abs(d.y()) + 0.3 * std::hypot(d.x(), d.z())));
    CHECK(d.dot(box.support(d)) == doctest::Approx(d.cwiseAbs().dot(Vec3(0.1, 0.2, 0.3))));
  }
  Line line(Vec3(0, 0, 0), Vec3(1, 1, 0));
  CHECK(line.support(Vec3(1, 0, 0)) == Vec3(1, 1, 0));
  CHECK(line.support(Vec3(-1, 0, 0)) == Vec3(0, 0, 0));
}

}  // TEST_SUITE
