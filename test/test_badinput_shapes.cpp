// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Bad input at the shape/geometry API boundary: every constructor and setter rejects NaN, infinities,
// negative and zero sizes with std::invalid_argument naming the parameter and the value, and a rejected
// setter leaves the object unchanged.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

#include "scree/collide/geometry.h"
#include "scree/collide/shapes.h"
#include "scree/collide/space.h"
#include "scree/collide/uniform_grid.h"
#include "scree/core/errors.h"
#include "scree/core/rigid_body.h"

#include "test_badinput.h"

using namespace scree;
using namespace scree::test;
using scree::detail::UniformGrid;

namespace {

const Real kBadScalars[] = {kNaN, kInf, -kInf, -1.0, 0.0};


/// How errors.h prints a scalar (inf, -inf, nan, -1, 0).
std::string fmt(Real v) { return detail::formatValue(v); }

}  // namespace

TEST_SUITE("collide") {

TEST_CASE("sphere rejects non-positive or non-finite radii and stays unchanged") {
  for (Real v : kBadScalars) {
    CAPTURE(v);
    expectInvalid([&] { Sphere s(v); }, {"radius", fmt(v)});
    Sphere s(0.5);
    expectInvalid([&] { s.setRadius(v); }, {"Sphere::setRadius", "radius", fmt(v)});
    CHECK(s.getRadius() == 0.5);
    CHECK(s.getModificationCount() == 0);
  }
}

TEST_CASE("box rejects bad half extents per component and stays unchanged") {
  for (Real v : kBadScalars)
    for (int k = 0; k < 3; ++k) {
      Vec3 he(1, 2, 3);
      he[k] = v;
      CAPTURE(he.transpose());
      expectInvalid([&] { Box b(he); }, {"halfExtents", fmt(v)});
      Box b(Vec3(1, 1, 1));
      expectInvalid([&] { b.setHalfExtents(he); }, {"Box::setHalfExtents", "halfExtents", fmt(v)});
      CHECK(b.getHalfExtents() == Vec3(1, 1, 1));
    }
}

TEST_CASE("capsule and cylinder reject bad radius and height and stay unchanged") {
  for (Real v : kBadScalars) {
    CAPTURE(v);
    expectInvalid([&] { Capsule c(v, 1); }, {"radius", fmt(v)});
    expectInvalid([&] { Capsule c(1, v); }, {"height", fmt(v)});
    expectInvalid([&] { Cylinder c(v, 1); }, {"radius", fmt(v)});
    expectInvalid([&] { Cylinder c(1, v); }, {"height", fmt(v)});
    Capsule cap(0.5, 2);
    expectInvalid([&] { cap.setRadius(v); }, {"Capsule::setRadius", "radius", fmt(v)});
    expectInvalid([&] { cap.setHeight(v); }, {"Capsule::setHeight", "height", fmt(v)});
    CHECK(cap.getRadius() == 0.5);
    CHECK(cap.getHeight() == 2);
    Cylinder cyl(0.5, 2);
    expectInvalid([&] { cyl.setRadius(v); }, {"Cylinder::setRadius", "radius", fmt(v)});
    expectInvalid([&] { cyl.setHeight(v); }, {"Cylinder::setHeight", "height", fmt(v)});
    CHECK(cyl.getRadius() == 0.5);
    CHECK(cyl.getHeight() == 2);
  }
}

TEST_CASE("plane rejects a zero or non-finite normal and a non-finite distance") {
  expectInvalid([] { Plane p(Vec3::Zero(), 0); }, {"normal"});
  expectInvalid([] { Plane p(Vec3(kNaN, 0, 1), 0); }, {"normal", "nan"});
  expectInvalid([] { Plane p(Vec3(0, kInf, 1), 0); }, {"normal", "inf"});
  for (Real v : {kNaN, kInf, -kInf}) expectInvalid([&] { Plane p(Vec3::UnitZ(), v); }, {"distance", fmt(v)});
  Plane ok(Vec3::UnitZ(), -1e6);  // any finite distance is fine
  CHECK(ok.getDistance() == -1e6);
}

TEST_CASE("convex rejects too few, non-finite, coincident, collinear and coplanar points") {
  expectInvalid([] { Convex c(std::vector<Vec3>{Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY()}); }, {"points", "3"});
  expectInvalid([] { Convex c(std::vector<Vec3>{}); }, {"points", "0"});
  std::vector<Vec3> tet = {Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
  for (Real v : {kNaN, kInf}) {
    auto bad = tet;
    bad[2].y() = v;
    expectInvalid([&] { Convex c(bad); }, {"points[2]", fmt(v)});
  }
  expectInvalid([] { Convex c(std::vector<Vec3>(6, Vec3(1, 2, 3))); }, {"degenerate"});
  expectInvalid([] { Convex c(std::vector<Vec3>{Vec3::Zero(), Vec3(1, 1, 1), Vec3(2, 2, 2), Vec3(3, 3, 3)}); },
                {"degenerate"});
  std::vector<Vec3> flat;
  for (int i = 0; i < 20; ++i) flat.emplace_back(std::cos(i * 0.3), std::sin(i * 0.3), 1e-16 * (i % 2));
  expectInvalid([&] { Convex c(flat); }, {"degenerate"});
}

TEST_CASE("height field validates resolution, size, heights and indices") {
  expectInvalid([] { HeightField h(1, 4, 1, 1); }, {"resolutionX", "1"});
  expectInvalid([] { HeightField h(4, 0, 1, 1); }, {"resolutionY", "0"});
  for (Real v : kBadScalars) {
    expectInvalid([&] { HeightField h(4, 4, v, 1); }, {"sizeX", fmt(v)});
    expectInvalid([&] { HeightField h(4, 4, 1, v); }, {"sizeY", fmt(v)});
  }
  HeightField hf(3, 3, 2, 2);
  hf.setHeight(1, 1, 0.5);
  const auto before = hf.getHeights();
  expectInvalid([&] { hf.setHeights(std::vector<Real>(8, 0.0)); }, {"heights.size()", "8", "9"});
  std::vector<Real> withNan(9, 0.0);
  withNan[4] = kNaN;
  expectInvalid([&] { hf.setHeights(withNan); }, {"heights[4]", "nan"});
  expectInvalid([&] { hf.setHeight(3, 0, 1.0); }, {"HeightField::setHeight", "i", "3"});
  expectInvalid([&] { hf.setHeight(0, 7, 1.0); }, {"j", "7"});
  for (Real v : {kNaN, kInf, -kInf}) expectInvalid([&] { hf.setHeight(0, 0, v); }, {"height", fmt(v)});
  CHECK(hf.getHeights() == before);
  CHECK(hf.getMaxHeight() == 0.5);
  hf.setHeight(0, 0, -3.0);  // negative heights are valid
  CHECK(hf.getMinHeight() == -3.0);
}

TEST_CASE("line rejects non-finite or coincident endpoints and stays unchanged") {
  expectInvalid([] { Line l(Vec3(kNaN, 0, 0), Vec3::UnitX()); }, {"p1", "nan"});
  expectInvalid([] { Line l(Vec3::Zero(), Vec3(0, kInf, 0)); }, {"p2", "inf"});
  expectInvalid([] { Line l(Vec3::UnitX(), Vec3::UnitX()); }, {"p2"});
  Line l(Vec3::Zero(), Vec3::UnitZ());
  expectInvalid([&] { l.set(Vec3::Zero(), Vec3(kNaN, 0, 0)); }, {"Line::set", "p2", "nan"});
  CHECK(l.getSecondPoint() == Vec3::UnitZ());
}

TEST_CASE("geometry rejects a null shape, non-finite positions and bad rotations") {
  expectInvalid([] { Geometry g(nullptr); }, {"shape", "null"});
  Geometry g(std::make_shared<Sphere>(1));
  g.setLocalPosition(Vec3(1, 2, 3));
  for (Real v : {kNaN, kInf}) {
    expectInvalid([&] { g.setLocalPosition(Vec3(v, 0, 0)); }, {"Geometry::setLocalPosition", "position", fmt(v)});
    expectInvalid([&] { g.setPosition(Vec3(0, 0, v)); }, {"Geometry::setPosition", "position", fmt(v)});
    expectInvalid([&] { g.setLocalRotation(Quat(v, 0, 0, 0)); }, {"rotation", fmt(v)});
  }
  expectInvalid([&] { g.setLocalRotation(Quat(0, 0, 0, 0)); }, {"Geometry::setLocalRotation", "rotation"});
  expectInvalid([&] { g.setRotation(Quat(0, 0, 0, 0)); }, {"Geometry::setRotation", "rotation"});
  CHECK(g.getLocalTransform().p == Vec3(1, 2, 3));
  CHECK(g.getLocalTransform().q.coeffs() == Quat::Identity().coeffs());
  // A non-unit quaternion is normalised.
  g.setLocalRotation(Quat(2, 0, 0, 0));
  CHECK(g.getLocalTransform().q.norm() == doctest::Approx(1));
  expectInvalid([] { Geometry::groupId(""); }, {"name"});
}

TEST_CASE("body add rejects null and already attached geometries; body unchanged") {
  auto body = std::make_shared<RigidBody>();
  auto g = std::make_shared<Geometry>(std::make_shared<Sphere>(0.1));
  body->add(g);
  const Real m = body->getMass();
  expectInvalid([&] { body->add(nullptr); }, {"geometry", "null"});
  expectInvalid([&] { body->add(g); }, {"already attached"});
  CHECK(body->getGeometries().size() == 1);
  CHECK(body->getMass() == m);
}

TEST_CASE("space and grid settings reject bad values") {
  Space s;
  for (Real v : {kNaN, kInf, -1.0}) expectInvalid([&] { s.setContactMargin(v); }, {"margin", fmt(v)});
  CHECK(s.getContactMargin() == 1e-3);
  expectInvalid([&] { s.add(nullptr); }, {"geometry", "null"});
  UniformGrid grid;
  for (Real v : {kNaN, kInf, -1.0}) expectInvalid([&] { grid.setCellSize(v); }, {"size", fmt(v)});
  for (Real v : {kNaN, kInf, 0.5}) expectInvalid([&] { grid.setOversizeFactor(v); }, {"factor", fmt(v)});
  CHECK(grid.getCellSize() == 0);
}

}  // TEST_SUITE
