// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Narrowphase pair routines: hand-computed depths, normals and points for resting, penetrating and speculative
// configurations; the normal convention under swapped arguments; box-box manifolds and feature-id stability.
// Analytic pairs are checked to 1e-9; libccd pairs to 1e-4 (MPR stops on a portal tolerance and converges
// linearly on curved boundaries; 1e-4 is the accuracy its documentation and our adapter promise).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <set>

#include "scree/collide/geometry.h"
#include "scree/collide/narrowphase.h"
#include "scree/collide/shapes.h"

using namespace scree;

namespace {

constexpr Real kTol = 1e-9;
constexpr Real kCcdTol = 1e-4;
const Real kPi = std::acos(Real(-1));

std::unique_ptr<Geometry> place(ShapeRef s, const Vec3& p, const Quat& q = Quat::Identity()) {
  auto g = std::make_unique<Geometry>(std::move(s));
  g->setPosition(p);
  g->setRotation(q);
  return g;
}

std::vector<ContactPoint> collide(const Geometry& a, const Geometry& b, Real margin = 0) {
  std::vector<ContactPoint> out;
  const int n = collideGeometries(a, b, margin, out);
  CHECK(n == int(out.size()));
  return out;
}

bool near(const Vec3& a, const Vec3& b, Real tol) { return (a - b).norm() <= tol; }

Quat rotZ(Real a) { return Quat(Eigen::AngleAxis<Real>(a, Vec3::UnitZ())); }
Quat rotX(Real a) { return Quat(Eigen::AngleAxis<Real>(a, Vec3::UnitX())); }

bool hasPoint(const std::vector<ContactPoint>& c, const Vec3& p, Real tol) {
  return std::any_of(c.begin(), c.end(), [&](const ContactPoint& x) { return near(x.point, p, tol); });
}

/// Every point checked against the conventions: unit normal, at most 4 points, depth within margin.
void checkConventions(const std::vector<ContactPoint>& c, Real margin) {
  CHECK(c.size() <= 4);
  for (const auto& p : c) {
    CHECK(std::abs(p.normal.norm() - 1) < 1e-9);
    CHECK(p.depth >= -margin - 1e-12);
  }
}

std::shared_ptr<Convex> cubeHull(Real h) {
  std::vector<Vec3> pts;
  for (int k = 0; k < 8; ++k) pts.emplace_back((k & 1) ? h : -h, (k & 2) ? h : -h, (k & 4) ? h : -h);
  return std::make_shared<Convex>(pts);
}

}  // namespace

TEST_SUITE("collide.narrowphase") {
  TEST_CASE("dispatch table covers the pairs in either order and skips plane-plane, line-line") {
    for (int a = 0; a < Shape::NUM_TYPES; ++a)
      for (int b = 0; b < Shape::NUM_TYPES; ++b)
        CHECK(hasCollider(Shape::Type(a), Shape::Type(b)) == hasCollider(Shape::Type(b), Shape::Type(a)));
    CHECK_FALSE(hasCollider(Shape::PLANE, Shape::PLANE));
    CHECK_FALSE(hasCollider(Shape::HEIGHT_FIELD, Shape::HEIGHT_FIELD));
    CHECK_FALSE(hasCollider(Shape::LINE, Shape::LINE));
    CHECK_FALSE(hasCollider(Shape::PLANE, Shape::HEIGHT_FIELD));
    CHECK(hasCollider(Shape::CYLINDER, Shape::CONVEX));
    CHECK(hasCollider(Shape::HEIGHT_FIELD, Shape::BOX));
    CHECK(hasCollider(Shape::LINE, Shape::HEIGHT_FIELD));
  }

  TEST_CASE("sphere-sphere: depth, normal from geometry 1 to 0, midpoint; swapped order flips the normal") {
    auto a = place(std::make_shared<Sphere>(1.0), Vec3(0, 0, 0));
    auto b = place(std::make_shared<Sphere>(0.5), Vec3(1.4, 0, 0));
    auto c = collide(*a, *b);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.1).epsilon(kTol));
    CHECK(near(c[0].normal, Vec3(-1, 0, 0), kTol));
    // Surface points (1,0,0) on sphere 0 and (0.9,0,0) on sphere 1.
    CHECK(near(c[0].point, Vec3(0.95, 0, 0), kTol));
    CHECK(c[0].featureId == 0);
    auto s = collide(*b, *a);
    REQUIRE(s.size() == 1);
    CHECK(near(s[0].normal, Vec3(1, 0, 0), kTol));
    CHECK(s[0].depth == doctest::Approx(0.1).epsilon(kTol));
  }

  TEST_CASE("speculative contacts: a gap within the margin is reported with negative depth, beyond it nothing") {
    auto a = place(std::make_shared<Sphere>(1.0), Vec3(0, 0, 0));
    auto b = place(std::make_shared<Sphere>(1.0), Vec3(2.05, 0, 0));
    auto c = collide(*a, *b, 0.1);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(-0.05).epsilon(kTol));
    CHECK(collide(*a, *b, 0.04).empty());
    CHECK(collide(*a, *b, 0).empty());

    auto box0 = place(std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)), Vec3(0, 0, 0));
    auto box1 = place(std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)), Vec3(0, 0, 1.03));
    auto bb = collide(*box0, *box1, 0.05);
    CHECK(bb.size() == 4);
    for (const auto& p : bb) CHECK(p.depth == doctest::Approx(-0.03).epsilon(kTol));
    CHECK(collide(*box0, *box1, 0.02).empty());
  }

  TEST_CASE("sphere-plane, including a plane placed by its geometry") {
    auto pl = place(std::make_shared<Plane>(Vec3(0, 0, 1), 0.0), Vec3::Zero());
    auto s = place(std::make_shared<Sphere>(0.5), Vec3(1, 2, 0.4));
    auto c = collide(*s, *pl);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.1).epsilon(kTol));
    CHECK(near(c[0].normal, Vec3(0, 0, 1), kTol));
    CHECK(near(c[0].point, Vec3(1, 2, -0.05), kTol));
    auto cs = collide(*pl, *s);
    REQUIRE(cs.size() == 1);
    CHECK(near(cs[0].normal, Vec3(0, 0, -1), kTol));
    // Plane normal z rotated by +90 deg about x becomes -y; distance 1 along it, then shifted by the position.
    auto pl2 = place(std::make_shared<Plane>(Vec3(0, 0, 1), 1.0), Vec3(0, -0.5, 0), rotX(kPi / 2));
    // World plane: n = (0,-1,0), n.x = 1 + n.p = 1.5, i.e. y = -1.5. Sphere at y = -1.8 => centre 0.3 above.
    auto s2 = place(std::make_shared<Sphere>(0.5), Vec3(0, -1.8, 0));
    auto c2 = collide(*s2, *pl2);
    REQUIRE(c2.size() == 1);
    CHECK(c2[0].depth == doctest::Approx(0.2).epsilon(kTol));
    CHECK(near(c2[0].normal, Vec3(0, -1, 0), kTol));
  }

  TEST_CASE("sphere-box: face, edge, and centre inside the box") {
    auto box = place(std::make_shared<Box>(Vec3(1, 1, 1)), Vec3::Zero(), rotZ(kPi / 2));
    auto face = place(std::make_shared<Sphere>(0.5), Vec3(0, 0, 1.3));
    auto c = collide(*face, *box);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.2).epsilon(kTol));
    CHECK(near(c[0].normal, Vec3(0, 0, 1), kTol));
    CHECK(near(c[0].point, Vec3(0, 0, 0.9), kTol));
    // Edge along y at (1, *, 1): centre on the diagonal at distance 0.4 from the edge.
    const Real e = 0.4 / std::sqrt(2.0);
    auto edge = place(std::make_shared<Sphere>(0.5), Vec3(1 + e, 0.3, 1 + e));
    c = collide(*edge, *box);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.1).epsilon(kTol));
    CHECK(near(c[0].normal, Vec3(1, 0, 1).normalized(), kTol));
    // Inside, nearest face +x at distance 0.2: depth = r + 0.2.
    auto in = place(std::make_shared<Sphere>(0.5), Vec3(0.8, 0.1, -0.3));
    c = collide(*box, *in);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.7).epsilon(kTol));
    CHECK(near(c[0].normal, Vec3(-1, 0, 0), kTol));  // swapped: from the sphere towards the box
  }

  TEST_CASE("sphere-capsule and sphere-cylinder") {
    auto cap = place(std::make_shared<Capsule>(0.5, 2.0), Vec3::Zero());  // axis y, ends at y = +-1
    auto s = place(std::make_shared<Sphere>(0.25), Vec3(0.7, 0.5, 0));
    auto c = collide(*s, *cap);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.05).epsilon(kTol));
    CHECK(near(c[0].normal, Vec3(1, 0, 0), kTol));
    auto tip = place(std::make_shared<Sphere>(0.25), Vec3(0, 1.6, 0));
    c = collide(*cap, *tip);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.15).epsilon(kTol));
    CHECK(near(c[0].normal, Vec3(0, -1, 0), kTol));

    auto cyl = place(std::make_shared<Cylinder>(0.5, 2.0), Vec3::Zero(), rotX(kPi / 2));  // axis along world z
    auto side = place(std::make_shared<Sphere>(0.25), Vec3(0, 0.7, 0.3));
    c = collide(*side, *cyl);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.05).epsilon(kTol));
    CHECK(near(c[0].normal, Vec3(0, 1, 0), kTol));
    auto capS = place(std::make_shared<Sphere>(0.25), Vec3(0.1, 0.1, 1.2));
    c = collide(*capS, *cyl);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.05).epsilon(kTol));
    CHECK(near(c[0].normal, Vec3(0, 0, 1), kTol));
    CHECK(near(c[0].point, Vec3(0.1, 0.1, 0.975), kTol));
    auto rim = place(std::make_shared<Sphere>(0.25), Vec3(0, 0.5 + 0.1, 1 + 0.1));
    c = collide(*rim, *cyl);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.25 - std::sqrt(0.02)).epsilon(kTol));
    auto inside = place(std::make_shared<Sphere>(0.1), Vec3(0.4, 0, 0));
    c = collide(*inside, *cyl);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.2).epsilon(kTol));
    CHECK(near(c[0].normal, Vec3(1, 0, 0), kTol));
  }

  TEST_CASE("capsule-capsule: crossing gives one point, side by side gives two") {
    auto a = place(std::make_shared<Capsule>(0.5, 2.0), Vec3::Zero(), Quat(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitZ())));  // axis x
    auto b = place(std::make_shared<Capsule>(0.5, 2.0), Vec3(0.2, 0.1, 0.9));  // axis y, crossing above
    auto c = collide(*b, *a);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.1).epsilon(kTol));
    CHECK(near(c[0].normal, Vec3(0, 0, 1), kTol));
    CHECK(near(c[0].point, Vec3(0.2, 0, 0.45), kTol));

    auto p = place(std::make_shared<Capsule>(0.5, 2.0), Vec3(0.5, 0, 0.95), Quat(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitZ())));
    c = collide(*p, *a);
    REQUIRE(c.size() == 2);
    for (const auto& x : c) {
      CHECK(x.depth == doctest::Approx(0.05).epsilon(kTol));
      CHECK(near(x.normal, Vec3(0, 0, 1), kTol));
    }
    // Overlap of the segments along x is [-0.5, 1].
    CHECK(hasPoint(c, Vec3(-0.5, 0, 0.475), kTol));
    CHECK(hasPoint(c, Vec3(1.0, 0, 0.475), kTol));
    CHECK(c[0].featureId != c[1].featureId);
  }

  TEST_CASE("capsule-plane and capsule lying on a box face give two points") {
    const Quat lying(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitZ()));  // axis along x
    auto cap = place(std::make_shared<Capsule>(0.25, 1.0), Vec3(0, 0, 0.2), lying);
    auto pl = place(std::make_shared<Plane>(Vec3(0, 0, 1), 0.0), Vec3::Zero());
    auto c = collide(*cap, *pl);
    REQUIRE(c.size() == 2);
    CHECK(hasPoint(c, Vec3(-0.5, 0, -0.025), kTol));
    CHECK(hasPoint(c, Vec3(0.5, 0, -0.025), kTol));
    for (const auto& x : c) CHECK(x.depth == doctest::Approx(0.05).epsilon(kTol));

    auto box = place(std::make_shared<Box>(Vec3(2, 2, 0.5)), Vec3(0, 0, -0.5));
    c = collide(*cap, *box);
    REQUIRE(c.size() == 2);
    for (const auto& x : c) {
      CHECK(x.depth == doctest::Approx(0.05).epsilon(kTol));
      CHECK(near(x.normal, Vec3(0, 0, 1), kTol));
    }
    CHECK(hasPoint(c, Vec3(-0.5, 0, -0.025), kTol));
    // Overhanging the box's +x edge at x = 0.25: the segment is clipped to the face.
    auto small = place(std::make_shared<Box>(Vec3(0.25, 2, 0.5)), Vec3(0, 0, -0.5));
    c = collide(*small, *cap);
    REQUIRE(c.size() == 2);
    CHECK(near(c[0].normal, Vec3(0, 0, -1), kTol));
    CHECK(hasPoint(c, Vec3(0.25, 0, -0.025), kTol));
    // Standing upright on the box: one point under the lower end.
    auto up = place(std::make_shared<Capsule>(0.25, 1.0), Vec3(0.1, 0, 0.7), rotX(kPi / 2));
    c = collide(*up, *box);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.05).epsilon(kTol));
    CHECK(near(c[0].point, Vec3(0.1, 0, -0.025), kTol));
    // Capsule pushed into the box (segment inside): still the face normal.
    auto deep = place(std::make_shared<Capsule>(0.25, 1.0), Vec3(0, 0, -0.1), lying);
    c = collide(*deep, *box);
    REQUIRE(c.size() == 2);
    for (const auto& x : c) CHECK(x.depth == doctest::Approx(0.35).epsilon(kTol));
  }

  TEST_CASE("box-plane: four deepest vertices, ids are vertex indices") {
    auto pl = place(std::make_shared<Plane>(Vec3(0, 0, 1), 0.0), Vec3::Zero());
    auto box = place(std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)), Vec3(0, 0, 0.49), rotZ(0.3));
    auto c = collide(*box, *pl);
    REQUIRE(c.size() == 4);
    std::set<uint32_t> ids;
    for (const auto& x : c) {
      CHECK(x.depth == doctest::Approx(0.01).epsilon(kTol));
      CHECK(near(x.normal, Vec3(0, 0, 1), kTol));
      CHECK(x.point.z() == doctest::Approx(-0.005).epsilon(kTol));
      ids.insert(x.featureId);
    }
    CHECK(ids == std::set<uint32_t>{0, 1, 2, 3});  // the -z vertices
    // Resting on an edge (45 deg about x): two points.
    auto edge = place(std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)), Vec3(0, 0, std::sqrt(0.5) - 0.02), rotX(kPi / 4));
    c = collide(*pl, *edge);
    REQUIRE(c.size() == 2);
    for (const auto& x : c) {
      CHECK(x.depth == doctest::Approx(0.02).epsilon(kTol));
      CHECK(near(x.normal, Vec3(0, 0, -1), kTol));
    }
  }

  TEST_CASE("box-box: unit cube resting face to face gives 4 points at the set depth") {
    auto lower = place(std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)), Vec3(0, 0, 0));
    auto upper = place(std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)), Vec3(0.1, 0, 0.99));
    auto c = collide(*upper, *lower);
    checkConventions(c, 0);
    REQUIRE(c.size() == 4);
    for (const auto& x : c) {
      CHECK(x.depth == doctest::Approx(0.01).epsilon(kTol));
      CHECK(near(x.normal, Vec3(0, 0, 1), kTol));
      CHECK(x.point.z() == doctest::Approx(0.495).epsilon(kTol));
    }
    CHECK(hasPoint(c, Vec3(-0.4, -0.5, 0.495), kTol));
    CHECK(hasPoint(c, Vec3(0.5, 0.5, 0.495), kTol));
    auto s = collide(*lower, *upper);
    REQUIRE(s.size() == 4);
    for (const auto& x : s) CHECK(near(x.normal, Vec3(0, 0, -1), kTol));
  }

  TEST_CASE("box-box: rotated 45 deg about z, the octagon is reduced to 4 points") {
    auto lower = place(std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)), Vec3(0, 0, 0));
    auto upper = place(std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)), Vec3(0, 0, 0.98), rotZ(kPi / 4));
    auto c = collide(*upper, *lower);
    checkConventions(c, 0);
    REQUIRE(c.size() == 4);
    // The clip polygon of two unit squares at 45 deg is a regular octagon with vertices at distance
    // 0.5 / cos(22.5 deg) from the centre; all four kept points are octagon vertices, spanning both diagonals.
    const Real rad = 0.5 / std::cos(kPi / 8);
    for (const auto& x : c) {
      CHECK(x.depth == doctest::Approx(0.02).epsilon(kTol));
      CHECK(near(x.normal, Vec3(0, 0, 1), kTol));
      CHECK(std::hypot(x.point.x(), x.point.y()) == doctest::Approx(rad).epsilon(1e-9));
    }
    std::set<uint32_t> ids;
    for (const auto& x : c) ids.insert(x.featureId);
    CHECK(ids.size() == 4);
    // The largest quadrilateral on 8 octagon vertices is a square: opposite points are diametrical.
    CHECK((c[0].point - c[1].point).norm() == doctest::Approx(2 * rad).epsilon(1e-9));
  }

  TEST_CASE("box-box: edge-edge crossing gives one point with the edge depth") {
    // Lower box: edge along y on top at x=0 after rotating 45 deg about y. Upper box: edge along x at the bottom
    // after rotating 45 deg about x. The edges cross at right angles above the origin.
    const Real h = std::sqrt(0.5);
    auto lower = place(std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)), Vec3(0, 0, -h),
                       Quat(Eigen::AngleAxis<Real>(kPi / 4, Vec3::UnitY())));
    auto upper = place(std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)), Vec3(0, 0, h - 0.03),
                       Quat(Eigen::AngleAxis<Real>(kPi / 4, Vec3::UnitX())));
    auto c = collide(*upper, *lower);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.03).epsilon(kTol));
    CHECK(near(c[0].normal, Vec3(0, 0, 1), kTol));
    CHECK(near(c[0].point, Vec3(0, 0, -0.015), kTol));
    auto s = collide(*lower, *upper);
    REQUIRE(s.size() == 1);
    CHECK(near(s[0].normal, Vec3(0, 0, -1), kTol));
  }

  TEST_CASE("box-box: feature ids stay the same under small motion") {
    auto lower = place(std::make_shared<Box>(Vec3(1, 1, 0.5)), Vec3(0, 0, 0));
    auto upper = place(std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)), Vec3(0, 0, 0.99), rotZ(0.2));
    auto ref = collide(*upper, *lower);
    REQUIRE(ref.size() == 4);
    std::set<uint32_t> ids0;
    for (const auto& x : ref) ids0.insert(x.featureId);
    for (int step = 1; step <= 10; ++step) {
      const Real s = step * 1e-3;
      upper->setPosition(Vec3(s, -0.5 * s, 0.99 + 0.1 * s));
      upper->setRotation(rotZ(0.2 + s) * Quat(Eigen::AngleAxis<Real>(0.2 * s, Vec3::UnitX())));
      auto c = collide(*upper, *lower, 0.01);
      std::set<uint32_t> ids;
      for (const auto& x : c) ids.insert(x.featureId);
      CHECK(ids == ids0);
    }
    // Also for the overlapping-incident case (upper bigger than lower: clip points from side planes).
    auto big = place(std::make_shared<Box>(Vec3(1, 1, 0.5)), Vec3(0, 0, 1.49), rotZ(0.3));
    auto base = place(std::make_shared<Box>(Vec3(0.5, 0.5, 1.0)), Vec3(0, 0, 0));
    auto r0 = collide(*big, *base);
    REQUIRE(r0.size() == 4);
    std::set<uint32_t> a0;
    for (const auto& x : r0) a0.insert(x.featureId);
    big->setPosition(Vec3(0.002, 0.001, 1.489));
    auto r1 = collide(*big, *base);
    std::set<uint32_t> a1;
    for (const auto& x : r1) a1.insert(x.featureId);
    CHECK(a0 == a1);
  }

  TEST_CASE("cylinder-plane: upright gives 4 rim points, lying gives 2") {
    auto pl = place(std::make_shared<Plane>(Vec3(0, 0, 1), 0.0), Vec3::Zero());
    auto up = place(std::make_shared<Cylinder>(0.5, 1.0), Vec3(0, 0, 0.49), rotX(kPi / 2));  // axis y -> z
    auto c = collide(*up, *pl);
    REQUIRE(c.size() == 4);
    for (const auto& x : c) {
      CHECK(x.depth == doctest::Approx(0.01).epsilon(kTol));
      CHECK(std::hypot(x.point.x(), x.point.y()) == doctest::Approx(0.5).epsilon(kTol));
    }
    auto lying = place(std::make_shared<Cylinder>(0.5, 1.0), Vec3(0, 0, 0.48));  // axis along y
    c = collide(*pl, *lying);
    REQUIRE(c.size() == 2);
    for (const auto& x : c) {
      CHECK(x.depth == doctest::Approx(0.02).epsilon(kTol));
      CHECK(near(x.normal, Vec3(0, 0, -1), kTol));
    }
    CHECK(hasPoint(c, Vec3(0, 0.5, -0.01), kTol));
    CHECK(hasPoint(c, Vec3(0, -0.5, -0.01), kTol));
  }

  TEST_CASE("lines report the entry point, the surface normal there and the length inside") {
    auto line = place(std::make_shared<Line>(Vec3(-3, 0, 0), Vec3(3, 0, 0)), Vec3(0, 0.3, 0));
    auto sphere = place(std::make_shared<Sphere>(0.5), Vec3(1, 0, 0));
    auto c = collide(*line, *sphere);
    REQUIRE(c.size() == 1);
    const Real hx = std::sqrt(0.25 - 0.09);
    CHECK(near(c[0].point, Vec3(1 - hx, 0.3, 0), kTol));
    CHECK(near(c[0].normal, Vec3(-hx, 0.3, 0) / 0.5, kTol));
    CHECK(c[0].depth == doctest::Approx(2 * hx).epsilon(kTol));
    auto sw = collide(*sphere, *line);
    REQUIRE(sw.size() == 1);
    CHECK(near(sw[0].normal, -c[0].normal, kTol));

    auto box = place(std::make_shared<Box>(Vec3(0.5, 1, 1)), Vec3(2, 0, 0));
    c = collide(*line, *box);
    REQUIRE(c.size() == 1);
    CHECK(near(c[0].point, Vec3(1.5, 0.3, 0), kTol));
    CHECK(near(c[0].normal, Vec3(-1, 0, 0), kTol));
    CHECK(c[0].depth == doctest::Approx(1.0).epsilon(kTol));

    auto down = place(std::make_shared<Line>(Vec3(0, 0, 2), Vec3(0, 0, -1)), Vec3(0.5, 0.5, 0));
    auto pl = place(std::make_shared<Plane>(Vec3(0, 0, 1), 0.0), Vec3::Zero());
    c = collide(*down, *pl);
    REQUIRE(c.size() == 1);
    CHECK(near(c[0].point, Vec3(0.5, 0.5, 0), kTol));
    CHECK(near(c[0].normal, Vec3(0, 0, 1), kTol));
    CHECK(c[0].depth == doctest::Approx(1.0).epsilon(kTol));
    auto upLine = place(std::make_shared<Line>(Vec3(0, 0, -1), Vec3(0, 0, 2)), Vec3::Zero());
    CHECK(collide(*upLine, *pl).empty());  // the plane's back side

    auto cap = place(std::make_shared<Capsule>(0.5, 2.0), Vec3(0, 0, 0));  // axis y
    auto l2 = place(std::make_shared<Line>(Vec3(0, 3, 0), Vec3(0, -3, 0)), Vec3::Zero());
    c = collide(*l2, *cap);
    REQUIRE(c.size() == 1);
    CHECK(near(c[0].point, Vec3(0, 1.5, 0), kTol));
    CHECK(near(c[0].normal, Vec3(0, 1, 0), kTol));
    CHECK(c[0].depth == doctest::Approx(3.0).epsilon(kTol));
    auto l3 = place(std::make_shared<Line>(Vec3(3, 0.2, 0), Vec3(-3, 0.2, 0)), Vec3::Zero());
    c = collide(*l3, *cap);
    REQUIRE(c.size() == 1);
    CHECK(near(c[0].point, Vec3(0.5, 0.2, 0), kTol));
    CHECK(near(c[0].normal, Vec3(1, 0, 0), kTol));
  }

  TEST_CASE("convex hulls: plane, box and convex pairs give face manifolds like boxes") {
    auto hull = place(cubeHull(0.5), Vec3(0.1, 0, 0.99));
    auto pl = place(std::make_shared<Plane>(Vec3(0, 0, 1), 0.5), Vec3::Zero());
    auto c = collide(*hull, *pl);
    REQUIRE(c.size() == 4);
    for (const auto& x : c) {
      CHECK(x.depth == doctest::Approx(0.01).epsilon(kTol));
      CHECK(near(x.normal, Vec3(0, 0, 1), kTol));
    }
    auto box = place(std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)), Vec3(0, 0, 0));
    c = collide(*hull, *box);
    checkConventions(c, 0);
    REQUIRE(c.size() == 4);
    for (const auto& x : c) {
      CHECK(x.depth == doctest::Approx(0.01).epsilon(kTol));
      CHECK(near(x.normal, Vec3(0, 0, 1), kTol));
    }
    CHECK(hasPoint(c, Vec3(-0.4, -0.5, 0.495), kTol));
    c = collide(*box, *hull);
    REQUIRE(c.size() == 4);
    for (const auto& x : c) CHECK(near(x.normal, Vec3(0, 0, -1), kTol));
    auto lower = place(cubeHull(0.5), Vec3(0, 0, 0));
    auto rotated = place(cubeHull(0.5), Vec3(0, 0, 0.98), rotZ(kPi / 4));
    c = collide(*rotated, *lower);
    REQUIRE(c.size() == 4);
    for (const auto& x : c) CHECK(x.depth == doctest::Approx(0.02).epsilon(kTol));
    // Tetrahedron resting on its face on a box, speculative gap 0.01 within margin 0.02.
    auto tet = place(std::make_shared<Convex>(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}),
                     Vec3(-0.5, -0.5, 0.51));
    c = collide(*tet, *box, 0.02);
    REQUIRE(c.size() == 3);
    for (const auto& x : c) CHECK(x.depth == doctest::Approx(-0.01).epsilon(kTol));
  }

  TEST_CASE("cylinder-box: a cap on a face gives a 4-point manifold, clipped at the face edge") {
    // Upright cylinder (axis y -> z) overlapping the top face by 0.05: four rim points at depth 0.05, the normal
    // exactly the face normal (the manifold is analytic once libccd has picked the face).
    auto box = place(std::make_shared<Box>(Vec3(2, 2, 0.5)), Vec3(0, 0, -0.5));
    auto cyl = place(std::make_shared<Cylinder>(0.5, 1.0), Vec3(0.1, 0.2, 0.45), rotX(kPi / 2));
    auto c = collide(*cyl, *box);
    REQUIRE(c.size() == 4);
    for (const auto& p : c) {
      CHECK(p.depth == doctest::Approx(0.05).epsilon(kTol));
      CHECK(near(p.normal, Vec3(0, 0, 1), kTol));
      CHECK(std::hypot(p.point.x() - 0.1, p.point.y() - 0.2) == doctest::Approx(0.5).epsilon(kTol));
      CHECK(p.point.z() == doctest::Approx(-0.025).epsilon(kTol));
    }
    // The four points span the cap (they are not bunched on one side): their centroid is the cap centre.
    Vec3 mean = Vec3::Zero();
    for (const auto& p : c) mean += p.point / 4.0;
    CHECK(near(Vec3(mean.x(), mean.y(), 0), Vec3(0.1, 0.2, 0), 1e-9));
    auto s = collide(*box, *cyl);
    REQUIRE(s.size() == 4);
    for (const auto& p : s) CHECK(near(p.normal, Vec3(0, 0, -1), kTol));
    // Half over the edge x = 2: every point lies on the face (x <= 2), two of them on the edge itself.
    cyl->setPosition(Vec3(2.0, 0.0, 0.45));
    c = collide(*cyl, *box);
    REQUIRE(c.size() >= 3);
    int onEdge = 0;
    for (const auto& p : c) {
      CHECK(p.point.x() <= 2.0 + 1e-9);
      CHECK(p.depth == doctest::Approx(0.05).epsilon(kTol));
      if (std::abs(p.point.x() - 2.0) < 1e-9) ++onEdge;
    }
    CHECK(onEdge == 2);
    // Tilted by 0.3 rad: not a cap-on-face contact, the single libccd point stays.
    cyl->setPosition(Vec3(0.1, 0.2, 0.45));
    cyl->setRotation(rotX(kPi / 2 + 0.3));
    CHECK(collide(*cyl, *box).size() == 1);
  }

  TEST_CASE("libccd pairs: cylinder on cylinder, speculative gap, sphere on hull") {
    std::vector<ContactPoint> c;
    // Two lying cylinders (axis y) side by side along x, overlapping by 0.04.
    auto c0 = place(std::make_shared<Cylinder>(0.5, 2.0), Vec3(0, 0, 0));
    auto c1 = place(std::make_shared<Cylinder>(0.5, 2.0), Vec3(0.96, 0, 0));
    // Their side lines touch along the whole length: two points, its ends (support-feature manifold,
    // convex_manifold.cpp; one libccd point before issue 20).
    c = collide(*c1, *c0);
    REQUIRE(c.size() == 2);
    for (const auto& p : c) {
      CHECK(p.depth == doctest::Approx(0.04).epsilon(kCcdTol));
      CHECK(near(p.normal, Vec3(1, 0, 0), kCcdTol));
    }
    CHECK(std::abs(c[0].point.y() - c[1].point.y()) == doctest::Approx(2.0).epsilon(1e-9));
    // Separated by 0.03: speculative within a 0.05 margin, nothing within 0.02.
    c1->setPosition(Vec3(1.03, 0, 0));
    c = collide(*c1, *c0, 0.05);
    REQUIRE(c.size() == 2);
    for (const auto& p : c) CHECK(p.depth == doctest::Approx(-0.03).epsilon(kCcdTol));
    CHECK(collide(*c1, *c0, 0.02).empty());
    // Sphere on a convex hull (libccd too).
    auto hull = place(cubeHull(0.5), Vec3::Zero());
    auto sph = place(std::make_shared<Sphere>(0.25), Vec3(0.1, 0.1, 0.7));
    c = collide(*sph, *hull);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.05).epsilon(kCcdTol));
    CHECK(near(c[0].normal, Vec3(0, 0, 1), kCcdTol));
  }

  TEST_CASE("normals follow the caller's order for every pair") {
    std::vector<ShapeRef> shapes = {std::make_shared<Sphere>(0.5),      std::make_shared<Box>(Vec3(0.5, 0.4, 0.3)),
                                    std::make_shared<Capsule>(0.3, 0.6), std::make_shared<Cylinder>(0.4, 0.8),
                                    cubeHull(0.4)};
    for (size_t i = 0; i < shapes.size(); ++i) {
      for (size_t j = 0; j < shapes.size(); ++j) {
        // Shape j sits below shape i and slightly overlaps it: the normal must point up (towards geometry 0).
        auto a = place(shapes[i], Vec3(0.05, 0.02, 0.5), rotZ(0.1));
        auto b = place(shapes[j], Vec3(0, 0, 0));
        auto c = collide(*a, *b);
        CAPTURE(i);
        CAPTURE(j);
        REQUIRE(!c.empty());
        checkConventions(c, 0);
        for (const auto& x : c) CHECK(x.normal.z() > 0.5);
        auto s = collide(*b, *a);
        REQUIRE(s.size() == c.size());
        for (const auto& x : s) CHECK(x.normal.z() < -0.5);
      }
    }
  }
}
