// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Shapes against height fields: flat, rotated/translated, and a sharp ridge. Tolerance 1e-9 throughout (all
// height-field routines are analytic).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "scree/collide/geometry.h"
#include "scree/collide/narrowphase.h"
#include "scree/collide/shapes.h"

using namespace scree;

namespace {

constexpr Real kTol = 1e-9;

std::unique_ptr<Geometry> place(ShapeRef s, const Vec3& p, const Quat& q = Quat::Identity()) {
  auto g = std::make_unique<Geometry>(std::move(s));
  g->setPosition(p);
  g->setRotation(q);
  return g;
}

std::vector<ContactPoint> collide(const Geometry& a, const Geometry& b, Real margin = 0) {
  std::vector<ContactPoint> out;
  collideGeometries(a, b, margin, out);
  CHECK(out.size() <= 4);
  return out;
}

bool near(const Vec3& a, const Vec3& b, Real tol) { return (a - b).norm() <= tol; }

/// n x n vertices over size x size, heights from f(x, y).
template <class F>
std::shared_ptr<HeightField> field(size_t n, Real size, F f) {
  auto hf = std::make_shared<HeightField>(n, n, size, size);
  std::vector<Real> h(n * n);
  for (size_t j = 0; j < n; ++j)
    for (size_t i = 0; i < n; ++i) {
      const Real x = -size / 2 + Real(i) * size / Real(n - 1), y = -size / 2 + Real(j) * size / Real(n - 1);
      h[j * n + i] = f(x, y);
    }
  hf->setHeights(h);
  return hf;
}

std::shared_ptr<HeightField> flat(size_t n = 11, Real size = 10) {
  return field(n, size, [](Real, Real) { return Real(0); });
}

// A roof: 5 x 5 vertices over 4 x 4 (cells of 1), only the row x = 0 raised to 1, so the ridge runs along y
// through the vertices (0, j) and the slopes fall to 0 at x = +-1. Shapes crossing it between y = 0 and y = 1
// touch only the ridge EDGE: no shape vertex is below the surface and no height-field vertex is inside the shape,
// so the old vertex-based method reported nothing for all of these.
std::shared_ptr<HeightField> roof() {
  return field(5, 4, [](Real x, Real) { return std::abs(x) < 1e-12 ? Real(1) : Real(0); });
}

}  // namespace

TEST_SUITE("collide.heightfield") {
  TEST_CASE("sphere on a flat height field: one face contact, also straight above a grid vertex or edge") {
    auto hf = place(flat(), Vec3::Zero());
    for (const Vec3& xy : {Vec3(0.3, 0.2, 0), Vec3(1, 1, 0), Vec3(0.5, 0.5, 0), Vec3(2, 0.4, 0)}) {
      auto s = place(std::make_shared<Sphere>(0.5), Vec3(xy.x(), xy.y(), 0.4));
      auto c = collide(*s, *hf);
      CAPTURE(xy);
      REQUIRE(c.size() == 1);
      CHECK(c[0].depth == doctest::Approx(0.1).epsilon(kTol));
      CHECK(near(c[0].normal, Vec3(0, 0, 1), kTol));
      CHECK(near(c[0].point, Vec3(xy.x(), xy.y(), -0.05), kTol));
      auto sw = collide(*hf, *s);
      REQUIRE(sw.size() == 1);
      CHECK(near(sw[0].normal, Vec3(0, 0, -1), kTol));
    }
    // Speculative: gap 0.05 within a margin of 0.1; nothing with 0.01.
    auto s = place(std::make_shared<Sphere>(0.5), Vec3(0.3, 0.2, 0.55));
    auto c = collide(*s, *hf, 0.1);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(-0.05).epsilon(kTol));
    CHECK(collide(*s, *hf, 0.01).empty());
  }

  TEST_CASE("a rotated and translated height field gives the transformed contact") {
    const Quat q = Quat(Eigen::AngleAxis<Real>(0.3, Vec3::UnitX())) * Quat(Eigen::AngleAxis<Real>(0.5, Vec3::UnitZ()));
    const Transform T{Vec3(1, 2, 3), q};
    auto hf = place(flat(), T.p, T.q);
    auto s = place(std::make_shared<Sphere>(0.5), T.apply(Vec3(0.3, 0.2, 0.4)));
    auto c = collide(*s, *hf);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.1).epsilon(kTol));
    CHECK(near(c[0].normal, T.rotate(Vec3::UnitZ()), kTol));
    CHECK(near(c[0].point, T.apply(Vec3(0.3, 0.2, -0.05)), kTol));
  }

  TEST_CASE("sphere rolling across a ridge edge: constant depth and a continuous normal") {
    // Ridge along y at x = 0, slopes of 1/2: z = -|x| / 2. The sphere centre follows the offset surface at
    // distance r - 0.01 (slope planes offset along their normals, a cylinder about the ridge edge), so the depth is 0.01
    // everywhere and the normal turns from the left face normal through the edge region to the right one.
    auto hf = place(field(9, 8, [](Real x, Real) { return -std::abs(x) / 2; }), Vec3::Zero());
    const Real r = 0.5, d = r - 0.01, k = std::sqrt(1.25);
    Vec3 prev = Vec3::Zero();
    const int steps = 400;
    for (int s = 0; s <= steps; ++s) {
      const Real x = -1 + 2 * Real(s) / steps;
      // The edge's Voronoi region: the centre's direction from the edge lies between the two face normals
      // (+-0.5, 0, 1) / k, i.e. |x| <= d * 0.5 / k.
      const bool edgeRegion = std::abs(x) <= d * 0.5 / k;
      const Real z = edgeRegion ? std::sqrt(d * d - x * x) : -std::abs(x) / 2 + d * k;
      auto sph = place(std::make_shared<Sphere>(r), Vec3(x, 0.3, z));
      auto c = collide(*sph, *hf);
      CAPTURE(x);
      REQUIRE(!c.empty());
      for (const auto& p : c) CHECK(p.depth == doctest::Approx(0.01).epsilon(1e-9));
      const Vec3 n = c[0].normal;
      if (s > 0) {
        // In the edge region x = d sin(theta), so a step dx turns the normal by dx / (d cos theta) <= 0.005 /
        // (0.49 cos(atan 0.5)) = 0.0114 rad; a face/edge switch without continuity would jump by up to 0.46 rad.
        CHECK(std::acos(std::clamp(n.dot(prev), Real(-1), Real(1))) < 0.0115);
      }
      for (const auto& p : c) CHECK(p.normal.dot(n) > 1 - 1e-9);
      prev = n;
    }
    // On the slopes the normal is the triangle normal.
    auto left = place(std::make_shared<Sphere>(r), Vec3(-1, 0.3, -0.5 + d * k));
    auto c = collide(*left, *hf);
    REQUIRE(c.size() == 1);
    CHECK(near(c[0].normal, Vec3(-0.5, 0, 1) / k, kTol));  // z = x / 2 on the left slope
  }

  TEST_CASE("box on a flat, rotated height field equals the box on the equivalent plane") {
    const Quat q = Quat(Eigen::AngleAxis<Real>(0.4, Vec3(1, 2, 0).normalized()));
    const Transform T{Vec3(0.5, -1, 2), q};
    auto hf = place(flat(21, 10), T.p, T.q);
    const Vec3 n = T.rotate(Vec3::UnitZ());
    auto plane = place(std::make_shared<Plane>(n, n.dot(T.p)), Vec3::Zero());
    // Box resting flat (rotated about the surface normal), bottom 0.01 below the surface.
    const Quat bq = T.q * Quat(Eigen::AngleAxis<Real>(0.7, Vec3::UnitZ()));
    auto box = place(std::make_shared<Box>(Vec3(0.6, 0.4, 0.3)), T.apply(Vec3(0.13, 0.21, 0.29)), bq);
    auto a = collide(*box, *hf);
    auto b = collide(*box, *plane);
    REQUIRE(a.size() == 4);
    REQUIRE(b.size() == 4);
    for (const auto& p : b) {
      const auto it = std::find_if(a.begin(), a.end(), [&](const ContactPoint& x) { return near(x.point, p.point, kTol); });
      REQUIRE(it != a.end());
      CHECK(it->depth == doctest::Approx(p.depth).epsilon(kTol));
      CHECK(near(it->normal, p.normal, kTol));
    }
  }

  TEST_CASE("capsule, cylinder and convex resting on a flat height field") {
    auto hf = place(flat(), Vec3(0, 0, 1));
    auto cap = place(std::make_shared<Capsule>(0.25, 1.0), Vec3(0.15, 0.35, 1.2),
                     Quat(Eigen::AngleAxis<Real>(0.3, Vec3::UnitZ())) * Quat(Eigen::AngleAxis<Real>(M_PI / 2, Vec3::UnitZ())));
    auto c = collide(*cap, *hf);
    REQUIRE(c.size() == 2);
    for (const auto& p : c) {
      CHECK(p.depth == doctest::Approx(0.05).epsilon(kTol));
      CHECK(near(p.normal, Vec3(0, 0, 1), kTol));
    }
    CHECK(c[0].featureId != c[1].featureId);

    auto cyl = place(std::make_shared<Cylinder>(0.5, 1.0), Vec3(0.2, 0.1, 1.49),
                     Quat(Eigen::AngleAxis<Real>(M_PI / 2, Vec3::UnitX())));
    c = collide(*cyl, *hf);
    REQUIRE(c.size() == 4);
    for (const auto& p : c) {
      CHECK(p.depth == doctest::Approx(0.01).epsilon(kTol));
      CHECK(std::hypot(p.point.x() - 0.2, p.point.y() - 0.1) == doctest::Approx(0.5).epsilon(kTol));
    }

    std::vector<Vec3> pts;
    for (int k = 0; k < 8; ++k) pts.emplace_back((k & 1) ? 0.3 : -0.3, (k & 2) ? 0.3 : -0.3, (k & 4) ? 0.3 : -0.3);
    auto hull = place(std::make_shared<Convex>(pts), Vec3(-0.4, 0.3, 1.28));
    c = collide(*hf, *hull);
    REQUIRE(c.size() == 4);
    for (const auto& p : c) {
      CHECK(p.depth == doctest::Approx(0.02).epsilon(kTol));
      CHECK(near(p.normal, Vec3(0, 0, -1), kTol));
    }
  }

  TEST_CASE("box resting across a sharp ridge touches the ridge vertices") {
    auto hf = place(field(41, 4, [](Real x, Real) { return -std::abs(x) / 2; }), Vec3::Zero());
    auto box = place(std::make_shared<Box>(Vec3(0.5, 0.5, 0.25)), Vec3(0, 0.3, 0.24));
    auto c = collide(*box, *hf);
    REQUIRE(c.size() >= 2);
    for (const auto& p : c) {
      CHECK(p.depth == doctest::Approx(0.01).epsilon(kTol));
      CHECK(near(p.normal, Vec3(0, 0, 1), kTol));
      CHECK(std::abs(p.point.x()) < kTol);
      CHECK(p.point.y() >= -0.2 - kTol);
      CHECK(p.point.y() <= 0.8 + kTol);
    }
  }

  TEST_CASE("a line entering a height field reports the entry point") {
    auto hf = place(field(11, 10, [](Real x, Real y) { return 0.1 * x + 0.05 * y; }), Vec3::Zero());
    auto line = place(std::make_shared<Line>(Vec3(0.3, 0.2, 2), Vec3(0.3, 0.2, -1)), Vec3::Zero());
    auto c = collide(*line, *hf);
    REQUIRE(c.size() == 1);
    const Real z = 0.03 + 0.01;
    CHECK(near(c[0].point, Vec3(0.3, 0.2, z), kTol));
    CHECK(near(c[0].normal, Vec3(-0.1, -0.05, 1).normalized(), kTol));
    CHECK(c[0].depth == doctest::Approx(z + 1).epsilon(kTol));
  }

  TEST_CASE("box lying across a sharp ridge between its vertices: face and edge crossings") {
    auto hf = place(roof(), Vec3::Zero());
    // Flat box, bottom face 0.01 below the ridge top, spanning y in [0.3, 0.7] and x in [-0.5, 0.5] (the slopes are
    // at 0.5 there, far below): two points where the ridge leaves the bottom face, depth 0.01, normal +z.
    auto box = place(std::make_shared<Box>(Vec3(0.5, 0.2, 0.25)), Vec3(0, 0.5, 1.24));
    auto c = collide(*box, *hf);
    REQUIRE(c.size() == 2);
    for (const auto& p : c) {
      CHECK(p.depth == doctest::Approx(0.01).epsilon(kTol));
      CHECK(near(p.normal, Vec3(0, 0, 1), kTol));
      CHECK(std::abs(p.point.x()) < kTol);
      CHECK(p.point.z() == doctest::Approx(0.995).epsilon(kTol));
      CHECK((std::abs(p.point.y() - 0.3) < kTol || std::abs(p.point.y() - 0.7) < kTol));
    }
    CHECK(c[0].featureId != c[1].featureId);
    auto sw = collide(*hf, *box);
    REQUIRE(sw.size() == 2);
    CHECK(near(sw[0].normal, Vec3(0, 0, -1), kTol));

    // Box turned 45 degrees about x: its lowest edge (along x, at y = 0.5) crosses the ridge edge (along y):
    // an edge-edge contact at (0, 0.5), depth 0.01.
    const Real h = 0.2, zc = 0.99 + h * std::sqrt(Real(2));
    auto tilted = place(std::make_shared<Box>(Vec3(0.5, h, h)), Vec3(0, 0.5, zc),
                        Quat(Eigen::AngleAxis<Real>(M_PI / 4, Vec3::UnitX())));
    c = collide(*tilted, *hf);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.01).epsilon(kTol));
    CHECK(near(c[0].normal, Vec3(0, 0, 1), kTol));
    CHECK(near(c[0].point, Vec3(0, 0.5, 0.995), kTol));
    // Within the margin but apart: speculative point with depth -0.02.
    tilted->setPosition(Vec3(0, 0.5, zc + 0.03));
    c = collide(*tilted, *hf, 0.05);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(-0.02).epsilon(kTol));
    CHECK(collide(*tilted, *hf, 0.01).empty());
  }

  TEST_CASE("box on a fine flat rotated height field still equals the plane result") {
    const Quat q = Quat(Eigen::AngleAxis<Real>(-0.6, Vec3(2, -1, 1).normalized()));
    const Transform T{Vec3(-0.3, 0.7, -1), q};
    auto hf = place(flat(41, 4), T.p, T.q);  // cells of 0.1: many triangles under the box
    const Vec3 n = T.rotate(Vec3::UnitZ());
    auto plane = place(std::make_shared<Plane>(n, n.dot(T.p)), Vec3::Zero());
    const Quat bq = T.q * Quat(Eigen::AngleAxis<Real>(-0.35, Vec3::UnitZ()));
    auto box = place(std::make_shared<Box>(Vec3(0.45, 0.3, 0.2)), T.apply(Vec3(0.07, -0.12, 0.18)), bq);
    auto a = collide(*box, *hf);
    auto b = collide(*box, *plane);
    REQUIRE(a.size() == 4);
    REQUIRE(b.size() == 4);
    for (const auto& p : b) {
      const auto it = std::find_if(a.begin(), a.end(), [&](const ContactPoint& x) { return near(x.point, p.point, kTol); });
      REQUIRE(it != a.end());
      CHECK(it->depth == doctest::Approx(0.02).epsilon(kTol));
      CHECK(it->depth == doctest::Approx(p.depth).epsilon(kTol));
      CHECK(near(it->normal, p.normal, kTol));
    }
  }

  TEST_CASE("convex hull and lying cylinder across a sharp ridge between its vertices") {
    auto hf = place(roof(), Vec3::Zero());
    std::vector<Vec3> pts;
    for (int k = 0; k < 8; ++k) pts.emplace_back((k & 1) ? 0.3 : -0.3, (k & 2) ? 0.3 : -0.3, (k & 4) ? 0.3 : -0.3);
    // Cube hull spanning y in [0.2, 0.8], bottom 0.01 below the ridge top.
    auto hull = place(std::make_shared<Convex>(pts), Vec3(0, 0.5, 1.29));
    auto c = collide(*hull, *hf);
    REQUIRE(c.size() == 2);
    for (const auto& p : c) {
      CHECK(p.depth == doctest::Approx(0.01).epsilon(kTol));
      CHECK(near(p.normal, Vec3(0, 0, 1), kTol));
      CHECK(std::abs(p.point.x()) < kTol);
      CHECK((std::abs(p.point.y() - 0.2) < kTol || std::abs(p.point.y() - 0.8) < kTol));
    }
    // The same hull turned 45 degrees about x: edge-edge crossing at (0, 0.5).
    const Real zc = 0.99 + 0.3 * std::sqrt(Real(2));
    auto tilted = place(std::make_shared<Convex>(pts), Vec3(0, 0.5, zc), Quat(Eigen::AngleAxis<Real>(M_PI / 4, Vec3::UnitX())));
    c = collide(*tilted, *hf);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.01).epsilon(kTol));
    CHECK(near(c[0].normal, Vec3(0, 0, 1), kTol));
    CHECK(near(c[0].point, Vec3(0, 0.5, 0.995), kTol));

    // Cylinder (radius 0.3, length 1) lying along x across the ridge, lowest line 0.01 below the ridge top.
    auto cyl = place(std::make_shared<Cylinder>(0.3, 1.0), Vec3(0, 0.5, 1.29),
                     Quat(Eigen::AngleAxis<Real>(-M_PI / 2, Vec3::UnitZ())));
    c = collide(*cyl, *hf);
    REQUIRE(c.size() == 1);
    CHECK(c[0].depth == doctest::Approx(0.01).epsilon(kTol));
    CHECK(near(c[0].normal, Vec3(0, 0, 1), kTol));
    CHECK(near(c[0].point, Vec3(0, 0.5, 0.995), kTol));
  }

  TEST_CASE("box on a sloped or flat field: no internal-edge normals, plane result on a slope") {
    // A slightly tipped box standing on one edge over a fine flat grid: every normal is the face normal.
    auto hf = place(flat(41, 4), Vec3::Zero());
    for (const Real ang : {0.05, 0.3, 0.7}) {
      for (const Vec3& xy : {Vec3(0.03, 0.04, 0), Vec3(0.1, 0.1, 0), Vec3(-0.27, 0.55, 0)}) {
        const Quat q = Quat(Eigen::AngleAxis<Real>(ang, Vec3(1, 0.3, 0).normalized())) *
                       Quat(Eigen::AngleAxis<Real>(0.2, Vec3::UnitZ()));
        auto box = place(std::make_shared<Box>(Vec3(0.4, 0.3, 0.2)), Vec3(xy.x(), xy.y(), 0), q);
        Real low = 0;
        for (int k = 0; k < 8; ++k) {
          const Vec3 v = box->getTransform().apply(Vec3((k & 1) ? 0.4 : -0.4, (k & 2) ? 0.3 : -0.3, (k & 4) ? 0.2 : -0.2));
          low = std::min(low, v.z());
        }
        box->setPosition(Vec3(xy.x(), xy.y(), -low - 0.01));
        auto c = collide(*box, *hf);
        CAPTURE(ang);
        CAPTURE(xy);
        REQUIRE(!c.empty());
        Real deepest = -1;
        for (const auto& p : c) {
          CHECK(near(p.normal, Vec3(0, 0, 1), kTol));
          deepest = std::max(deepest, p.depth);
        }
        CHECK(deepest == doctest::Approx(0.01).epsilon(kTol));
      }
    }
    // On a uniform slope the box equals the box on the slope's plane.
    auto slope = place(field(21, 4, [](Real x, Real y) { return 0.1 * x + 0.05 * y; }), Vec3::Zero());
    const Vec3 n = Vec3(-0.1, -0.05, 1).normalized();
    auto plane = place(std::make_shared<Plane>(n, 0), Vec3::Zero());
    const Quat q = Quat::FromTwoVectors(Vec3::UnitZ(), n) * Quat(Eigen::AngleAxis<Real>(0.4, Vec3::UnitZ()));
    auto box = place(std::make_shared<Box>(Vec3(0.35, 0.25, 0.2)), Vec3(0.12, -0.21, 0) + n * 0.19, q);
    box->setPosition(box->getTransform().p + Vec3(0.12, -0.21, 0.1 * 0.12 + 0.05 * -0.21) - Vec3(0.12, -0.21, 0));
    auto a = collide(*box, *slope);
    auto b = collide(*box, *plane);
    REQUIRE(a.size() == 4);
    REQUIRE(b.size() == 4);
    for (const auto& p : b) {
      const auto it = std::find_if(a.begin(), a.end(), [&](const ContactPoint& x) { return near(x.point, p.point, kTol); });
      REQUIRE(it != a.end());
      CHECK(it->depth == doctest::Approx(p.depth).epsilon(kTol));
      CHECK(near(it->normal, p.normal, kTol));
    }
  }

  TEST_CASE("cylinder lying on a uniform slope matches the plane's depth and normal") {
    auto slope = place(field(21, 4, [](Real x, Real y) { return 0.1 * x + 0.05 * y; }), Vec3::Zero());
    const Vec3 n = Vec3(-0.1, -0.05, 1).normalized();
    auto plane = place(std::make_shared<Plane>(n, 0), Vec3::Zero());
    // Axis (local y) horizontal-ish along (1, 1, 0.15), centre 0.3 - 0.02 above the slope along n.
    const Quat q = Quat::FromTwoVectors(Vec3::UnitY(), Vec3(1, 1, 0.15).normalized());
    const Vec3 base(0.11, -0.07, 0.1 * 0.11 + 0.05 * -0.07);
    auto cyl = place(std::make_shared<Cylinder>(0.3, 0.8), base + n * 0.28, q);
    auto a = collide(*cyl, *slope);
    auto b = collide(*cyl, *plane);
    REQUIRE(!a.empty());
    REQUIRE(!b.empty());
    Real da = -1, db = -1;
    for (const auto& p : a) {
      da = std::max(da, p.depth);
      CHECK(near(p.normal, n, kTol));
    }
    for (const auto& p : b) db = std::max(db, p.depth);
    CHECK(da == doctest::Approx(db).epsilon(kTol));
  }
}
