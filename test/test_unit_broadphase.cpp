// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Broadphase and Space: the uniform grid reports exactly the brute-force overlapping pairs (once each,
// sorted) with the work its cell size predicts, and the Space filters pairs by the documented rules and orders
// its contacts by geometry id.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <random>
#include <utility>

#include "scree/collide/geometry.h"
#include "scree/collide/shapes.h"
#include "scree/collide/space.h"
#include "scree/collide/uniform_grid.h"
#include "scree/core/rigid_body.h"
#include "radix_sort.h"  // collide/src

using namespace scree;
using scree::detail::UniformGrid;

namespace {

using PairList = std::vector<std::pair<uint32_t, uint32_t>>;

PairList bruteForce(const std::vector<Aabb>& boxes) {
  PairList out;
  auto empty = [](const Aabb& b) { return !(b.lo.array() <= b.hi.array()).all(); };
  for (uint32_t i = 0; i < boxes.size(); ++i)
    for (uint32_t j = i + 1; j < boxes.size(); ++j)
      if (!empty(boxes[i]) && !empty(boxes[j]) && boxes[i].overlaps(boxes[j])) out.emplace_back(i, j);
  return out;
}

Aabb boxAt(const Vec3& c, const Vec3& half) {
  Aabb b;
  b.lo = c - half;
  b.hi = c + half;
  return b;
}

enum class Sizes { UNIFORM, LOG_SPREAD, POINTS, MIXED };

std::vector<Aabb> randomBoxes(std::mt19937& rng, size_t n, Sizes sizes, Real world) {
  std::uniform_real_distribution<Real> pos(-world, world), unit(0, 1);
  std::vector<Aabb> boxes;
  for (size_t i = 0; i < n; ++i) {
    const Vec3 c(pos(rng), pos(rng), pos(rng));
    Vec3 half = Vec3::Zero();
    switch (sizes) {
      case Sizes::UNIFORM: half = Vec3::Constant(0.5); break;
      case Sizes::LOG_SPREAD:  // 1e-3 .. 10 m, independently per axis
        half = Vec3(std::pow(10.0, -3 + 4 * unit(rng)), std::pow(10.0, -3 + 4 * unit(rng)), std::pow(10.0, -3 + 4 * unit(rng)));
        break;
      case Sizes::POINTS: half = Vec3::Zero(); break;
      case Sizes::MIXED: half = unit(rng) < 0.9 ? Vec3::Constant(0.2 + 0.3 * unit(rng)) : Vec3::Constant(3 * unit(rng)); break;
    }
    boxes.push_back(boxAt(c, half));
  }
  return boxes;
}

}  // namespace

TEST_SUITE("collide") {

TEST_CASE("uniform grid reports exactly the brute-force pair set for several size distributions") {
  std::mt19937 rng(42);
  UniformGrid grid;
  PairList pairs;
  for (Sizes sizes : {Sizes::UNIFORM, Sizes::LOG_SPREAD, Sizes::POINTS, Sizes::MIXED})
    for (Real cell : {0.0, 0.05, 1.0, 7.0})
      for (size_t n : {0u, 1u, 2u, 20u, 50u, 700u}) {  // up to 32 boxes: the all-pairs path (kAllPairsMax)
        CAPTURE(int(sizes));
        CAPTURE(cell);
        CAPTURE(n);
        std::vector<Aabb> boxes = randomBoxes(rng, n, sizes, sizes == Sizes::POINTS ? 1.0 : 6.0);
        if (sizes == Sizes::POINTS && n > 2) {
          boxes[1] = boxes[0];  // coincident points overlap
          boxes[2].lo = boxes[2].hi = boxes[0].hi;
        }
        if (n >= 20) {
          // A ground plane (infinite in x and y, bounded above), a huge static box, a fully infinite box, and an
          // empty box that must never be reported.
          Aabb plane;
          plane.lo = Vec3(-1e300, -1e300, -1e300);
          plane.hi = Vec3(1e300, 1e300, -2.0);
          boxes.push_back(plane);
          boxes.push_back(boxAt(Vec3(3, 0, 0), Vec3(4, 4, 1)));
          Aabb all;
          all.lo = Vec3::Constant(-1e300);
          all.hi = Vec3::Constant(1e300);
          boxes.push_back(all);
          boxes.push_back(Aabb{});
          std::shuffle(boxes.begin(), boxes.end(), rng);
        }
        grid.setCellSize(cell);
        grid.findPairs(boxes, pairs);
        const PairList ref = bruteForce(boxes);
        CHECK(pairs.size() == ref.size());
        CHECK(pairs == ref);  // same pairs, same (i < j) sorted order, no duplicates
        if (boxes.size() <= UniformGrid::kAllPairsMax) CHECK(grid.getUsedCellSize() == 0);  // all pairs, no cells
        else CHECK(grid.getUsedCellSize() > 0);
        CHECK(grid.getNumCandidateTests() >= pairs.size());  // a pair is reported only after its AABB test
      }
}

TEST_CASE("the grid's radix sort of 64-bit keys gives std::sort's order for every key pattern") {
  // radixSortKeys (collide/src/radix_sort.h) skips the bytes all keys share and scatters the others; each
  // pattern below makes a different set of bytes vary: the grid's two key forms, keys differing only in their
  // top or bottom byte, duplicates, presorted and reversed runs, every size from the std::sort cut-over up.
  std::mt19937_64 rng(20261204);
  std::vector<uint64_t> tmp;
  int checked = 0;
  for (size_t n : {size_t(0), size_t(1), size_t(63), size_t(64), size_t(65), size_t(500), size_t(4097)}) {
    for (int pattern = 0; pattern < 7; ++pattern) {
      std::vector<uint64_t> keys(n);
      for (size_t i = 0; i < n; ++i) {
        const uint64_t r = rng();
        switch (pattern) {
          case 0: keys[i] = r; break;                                          // all bytes vary
          case 1: keys[i] = (r & 0xffffffffu) << 32 | uint64_t(i / 3); break;  // cell keys: hash << 32 | box
          case 2: keys[i] = (r % 211) << 32 | ((r >> 20) % 211); break;       // pair keys of 211 boxes
          case 3: keys[i] = (r & 0xff) << 56 | 0x0123456789abcdull; break;    // only the top byte varies
          case 4: keys[i] = 0xfedcba9876543200ull | (r & 0x3); break;         // only the bottom byte, duplicates
          case 5: keys[i] = uint64_t(i) * 0x10001ull; break;                  // presorted
          default: keys[i] = ~uint64_t(i) << 7; break;                        // reversed, low bits zero
        }
      }
      std::vector<uint64_t> expected = keys;
      std::sort(expected.begin(), expected.end());
      const size_t tmpSize = tmp.size();
      scree::detail::radixSortKeys(keys, tmp);
      CHECK_MESSAGE(keys == expected, "n = " << n << ", pattern " << pattern);
      CHECK(tmp.size() >= tmpSize);  // the scratch only grows: no per-step allocation once warm
      ++checked;
    }
  }
  CHECK(checked == 49);
}

TEST_CASE("uniform grid picks twice the median extent and is repeatable across calls") {
  std::mt19937 rng(1);
  std::vector<Aabb> boxes = randomBoxes(rng, 301, Sizes::UNIFORM, 10.0);
  UniformGrid grid;
  PairList a, b;
  grid.findPairs(boxes, a);
  CHECK(grid.getUsedCellSize() == doctest::Approx(2.0));  // every box is 1 m wide
  grid.findPairs(boxes, b);
  CHECK(a == b);
  // Only infinite boxes: no grid needed, still correct.
  std::vector<Aabb> inf(3);
  for (auto& x : inf) {
    x.lo = Vec3::Constant(-1e300);
    x.hi = Vec3::Constant(1e300);
  }
  grid.setCellSize(0);
  grid.findPairs(inf, a);
  CHECK(a == PairList{{0, 1}, {0, 2}, {1, 2}});
}

TEST_CASE("uniform grid at constant density: cell entries and candidate tests are the cell-size prediction") {
  // The pair count of an input is fixed by the input (any correct broadphase, an all-pairs loop included, returns
  // the same pairs), so it says nothing about cost. The grid's own work does. Boxes of width w = 1 m with centres
  // uniform in (-a, a)^3 and the automatic cell size c = 2 w: along one axis a box touches cell column k with
  // probability q_k = |(-a, a) ∩ [c k - w/2, c (k+1) + w/2)| / (2 a), so the expected number of (cell, box)
  // entries is n (sum_k q_k)^3 (1.5^3 = 3.375 per box away from the walls), and the expected number of box pairs
  // sharing a cell, which is what the grid tests, is C(n, 2) (sum_k q_k^2)^3: about 2.6 n at this density
  // (0.0625 boxes per m^3) for both sizes, where an all-pairs loop would test C(n, 2) = 2000 n and 4000 n.
  // Tolerances: entries are a sum of n independent per-box counts (sd 2.1 per box: 1 % of the mean at n = 4000),
  // bound 3 %; tests sum ~1e4 pair events, Poisson-like (sd ~1 %), bound 5 %. Hash collisions between distinct
  // cells would add tests; with ~2e4 occupied cells and a 32-bit hash they are expected ~0.05 times.
  const Real w = 1.0;
  std::mt19937 rng(9);
  UniformGrid grid;
  PairList pairs;
  using Size = std::pair<size_t, Real>;  // number of boxes, half-width of the region of centres
  for (const auto& [n, a] : {Size{4000, 20.0}, Size{8000, 20.0 * std::cbrt(2.0)}}) {
    CAPTURE(n);
    const std::vector<Aabb> boxes = randomBoxes(rng, n, Sizes::UNIFORM, a);
    grid.findPairs(boxes, pairs);
    const Real c = grid.getUsedCellSize();
    REQUIRE(c == doctest::Approx(2 * w));
    double s1 = 0, s2 = 0;
    for (long k = long(std::floor((-a - w / 2) / c)); Real(k) * c < a + w / 2; ++k) {
      const double lo = std::max(-a, Real(k) * c - w / 2), hi = std::min(a, Real(k + 1) * c + w / 2);
      if (hi <= lo) continue;
      const double q = (hi - lo) / (2 * a);
      s1 += q;
      s2 += q * q;
    }
    const double expectedEntries = double(n) * s1 * s1 * s1;
    const double expectedTests = 0.5 * double(n) * double(n - 1) * s2 * s2 * s2;
    const double entries = double(grid.getNumCellEntries()), tests = double(grid.getNumCandidateTests());
    MESSAGE("n " << n << ": cell entries " << entries << " (expected " << expectedEntries << "), candidate tests "
                 << tests << " (expected " << expectedTests << ", all pairs " << 0.5 * double(n) * double(n - 1)
                 << "), pairs found " << pairs.size());
    CHECK(entries == doctest::Approx(expectedEntries).epsilon(0.03));
    CHECK(tests == doctest::Approx(expectedTests).epsilon(0.05));
    CHECK(tests >= double(pairs.size()));  // every reported pair was tested
  }
}

TEST_CASE("space filters pairs: same body, groups, geometry and body pairs, collisions off, static-static") {
  auto sphere = [] { return std::make_shared<Geometry>(std::make_shared<Sphere>(0.5)); };
  auto b1 = std::make_shared<RigidBody>("b1");
  auto b2 = std::make_shared<RigidBody>("b2");
  auto g1 = sphere(), g1b = sphere(), g2 = sphere(), ground = sphere();
  b1->add(g1);
  b1->add(g1b);
  b2->add(g2);
  Space space;
  for (auto& g : {g1, g1b, g2, ground}) space.add(g);

  CHECK(space.canCollide(*g1, *g2));
  CHECK(space.canCollide(*g1, *ground));
  CHECK_FALSE(space.canCollide(*g1, *g1b));  // same body
  CHECK_FALSE(space.canCollide(*g1, *g1));

  SUBCASE("collisions switched off on one geometry") {
    g2->setEnableCollisions(false);
    CHECK_FALSE(space.canCollide(*g1, *g2));
    CHECK_FALSE(space.canCollide(*g2, *g1));
  }
  SUBCASE("disabled group pair, numeric and named") {
    g1->addGroup(3);
    g2->addGroup("wheels");
    CHECK(space.canCollide(*g1, *g2));
    space.setEnablePair(Geometry::groupId("wheels"), 3, false);
    CHECK_FALSE(space.getEnablePair(3, Geometry::groupId("wheels")));
    CHECK_FALSE(space.canCollide(*g1, *g2));
    CHECK(space.canCollide(*g1, *ground));
    space.setEnablePair(3, Geometry::groupId("wheels"), true);
    CHECK(space.canCollide(*g1, *g2));
    // A group with itself.
    g2->addGroup(3);
    space.setEnablePair(3, 3, false);
    CHECK_FALSE(space.canCollide(*g1, *g2));
    CHECK(g2->removeGroup(3));
    CHECK_FALSE(g2->removeGroup(3));
    CHECK(Geometry::groupId("wheels") >= (1u << 30));
    CHECK(Geometry::groupId("wheels") == Geometry::groupId("wheels"));
    CHECK(Geometry::groupId("wheels") != Geometry::groupId("tracks"));
  }
  SUBCASE("disabled geometry pair") {
    space.setEnableCollisions(g2.get(), g1.get(), false);
    CHECK_FALSE(space.canCollide(*g1, *g2));
    CHECK(space.canCollide(*g1b, *g2));
    space.setEnableCollisions(g1.get(), g2.get(), true);
    CHECK(space.canCollide(*g1, *g2));
  }
  SUBCASE("disabled body pair") {
    space.setEnableCollisions(b1.get(), b2.get(), false);
    CHECK_FALSE(space.canCollide(*g1, *g2));
    CHECK_FALSE(space.canCollide(*g2, *g1b));
    CHECK(space.canCollide(*g2, *ground));
  }
  SUBCASE("static and kinematic pairs") {
    b1->setMotionControl(RigidBody::STATIC);
    CHECK_FALSE(space.canCollide(*g1, *ground));  // static body vs world geometry
    CHECK(space.canCollide(*g1, *g2));            // static vs dynamic
    b2->setMotionControl(RigidBody::KINEMATICS);
    CHECK_FALSE(space.canCollide(*g1, *g2));      // static vs kinematic
    g2->setSensor(true);
    CHECK(space.canCollide(*g1, *g2));            // a kinematic sensor sweeping static geometry
    CHECK(space.canCollide(*g2, *ground));
    ground->setSensor(true);
    CHECK_FALSE(space.canCollide(*ground, *g1));  // static sensor vs static body: nothing can change
  }
}

TEST_CASE("space contacts are ordered by geometry id with geometry 0 the lower id") {
  // A row of touching spheres, added to the space in reverse order; body velocities and a sensor.
  Space space;
  std::vector<GeometryRef> geoms;
  std::vector<RigidBodyRef> bodies;
  for (int i = 0; i < 6; ++i) {
    auto g = std::make_shared<Geometry>(std::make_shared<Sphere>(0.5));
    auto b = std::make_shared<RigidBody>();
    b->add(g);
    b->setPosition(Vec3(0.95 * i, 0, 0));
    geoms.push_back(g);
    bodies.push_back(b);
  }
  for (int i = 5; i >= 0; --i) space.add(geoms[i]);
  space.add(geoms[0]);  // adding twice is a no-op
  CHECK(space.getGeometries().size() == 6);
  geoms[3]->setSensor(true);

  std::vector<GeometryContact> contacts;
  space.collide(1.0 / 60, contacts);
  REQUIRE(contacts.size() == 5);
  // Only neighbours overlap: centres 0.95 m apart, AABBs 1 m wide plus the 1e-3 m resting margin; next-but-one
  // neighbours are 1.9 m apart.
  CHECK(space.getNumBroadphasePairs() == 5);
  for (size_t k = 0; k < contacts.size(); ++k) {
    const GeometryContact& c = contacts[k];
    CHECK(c.geometry(0)->getId() < c.geometry(1)->getId());
    CHECK(c.geometry(0) == geoms[k].get());
    CHECK(c.geometry(1) == geoms[k + 1].get());
    CHECK(c.rigidBody(0) == bodies[k].get());
    CHECK(!c.points().empty());
    // Normal from geometry 1 towards geometry 0: -x here.
    CHECK(c.points()[0].normal.x() < 0);
    CHECK(c.isSensor() == (k == 2 || k == 3));
  }

  // Filtering applies inside collide().
  space.setEnableCollisions(bodies[0].get(), bodies[1].get(), false);
  space.collide(1.0 / 60, contacts);
  CHECK(contacts.size() == 4);
  CHECK(contacts.front().geometry(0) == geoms[1].get());

  // Remove a geometry.
  CHECK(space.remove(geoms[5]));
  CHECK_FALSE(space.remove(geoms[5]));
  space.collide(1.0 / 60, contacts);
  CHECK(contacts.size() == 3);
}

TEST_CASE("space grows AABBs by the speculative margin of fast bodies") {
  // Two spheres 1 m apart (gap 0.0 -> 1.0 between surfaces). At rest they are not paired; when one moves at
  // 120 m/s towards the other, h |v| = 2 m covers the gap within one 1/60 s step, so the broadphase pairs
  // them and the narrowphase sees a margin large enough to report a speculative point.
  Space space;
  auto ga = std::make_shared<Geometry>(std::make_shared<Sphere>(0.5));
  auto gb = std::make_shared<Geometry>(std::make_shared<Sphere>(0.5));
  auto a = std::make_shared<RigidBody>(), b = std::make_shared<RigidBody>();
  a->add(ga);
  b->add(gb);
  b->setPosition(Vec3(2, 0, 0));
  space.add(ga);
  space.add(gb);
  std::vector<GeometryContact> contacts;
  space.collide(1.0 / 60, contacts);
  CHECK(space.getNumBroadphasePairs() == 0);
  CHECK(contacts.empty());
  a->setVelocity(Vec3(120, 0, 0));
  space.collide(1.0 / 60, contacts);
  CHECK(space.getNumBroadphasePairs() == 1);
  REQUIRE(contacts.size() == 1);
  CHECK(contacts[0].points()[0].depth == doctest::Approx(-1.0).epsilon(1e-9));
  // Spinning counts too: w r with r the distance to the AABB's far corner.
  a->setVelocity(Vec3::Zero());
  a->setAngularVelocity(Vec3(0, 0, 200));
  space.collide(1.0 / 60, contacts);
  CHECK(space.getNumBroadphasePairs() == 1);
}

}  // TEST_SUITE

// ---- issue 18: persistent box-box manifolds (Space::setUsePersistentManifolds, space.cpp) ----------------------
// A box tilted on a larger box, in two spaces: `cached` (the default, manifolds reused) and `fresh` (every pair
// clipped). Within the reuse tolerance (|dp| <= 1e-4 r, |dtheta| <= 1e-4 rad of the pose at the clip, r the larger
// half diagonal) the cached contacts must lie within the error space.cpp derives -- a point off by at most
// 2e-4 r, the depth exact for the body-fixed points, so off from the fresh clip's by that times the faces'
// tilt plus the roundoff -- and keep the clip's feature ids; past the tolerance, after a change of extents or
// with the option off, the pair is clipped again and the contacts equal the fresh clip's bit for bit.
TEST_CASE("persistent box-box manifolds stay within their tolerance of a fresh clip and re-clip past it") {
  struct Pair {
    std::shared_ptr<Box> lowerShape = std::make_shared<Box>(Vec3(1.0, 0.8, 0.5));
    std::shared_ptr<Box> upperShape = std::make_shared<Box>(Vec3(0.4, 0.3, 0.25));
    GeometryRef lower = std::make_shared<Geometry>(lowerShape), upper = std::make_shared<Geometry>(upperShape);
    RigidBodyRef body = std::make_shared<RigidBody>();
    Space space;
    std::vector<GeometryContact> out;
    Pair() {
      body->add(upper);
      space.add(lower);
      space.add(upper);
    }
    void place(const Vec3& p, const Quat& q) {
      body->setPosition(p);
      body->setRotation(q);
    }
  };
  Pair cached, fresh;
  fresh.space.setUsePersistentManifolds(false);
  CHECK(cached.space.getUsePersistentManifolds());
  const Real r = std::max(Vec3(1.0, 0.8, 0.5).norm(), Vec3(0.4, 0.3, 0.25).norm());
  // Upper box resting 1 mm deep and tilted 0.002 rad about x: a face contact whose four points have different
  // depths (the tilt makes the depth sensitive to where the point lies).
  const Quat q0(Eigen::AngleAxis<Real>(0.002, Vec3(1, 0, 0)));
  const Vec3 p0(0.1, -0.05, 0.5 + 0.25 - 1e-3);
  auto both = [&](const Vec3& p, const Quat& q) {
    cached.place(p, q);
    fresh.place(p, q);
    cached.space.collide(1.0 / 60, cached.out);
    fresh.space.collide(1.0 / 60, fresh.out);
    REQUIRE(cached.out.size() == 1);
    REQUIRE(fresh.out.size() == 1);
  };
  auto same = [&] {
    const auto& a = cached.out[0].points();
    const auto& b = fresh.out[0].points();
    REQUIRE(a.size() == b.size());
    for (size_t k = 0; k < a.size(); ++k) {
      CHECK(a[k].point == b[k].point);
      CHECK(a[k].normal == b[k].normal);
      CHECK(a[k].depth == b[k].depth);
      CHECK(a[k].featureId == b[k].featureId);
    }
  };
  both(p0, q0);
  CHECK(cached.space.getNumReusedManifolds() == 0);
  REQUIRE(cached.out[0].points().size() >= 3);
  same();
  std::vector<Real> clipDepths;
  for (const ContactPoint& c : cached.out[0].points()) clipDepths.push_back(c.depth);

  // Within the tolerance: 0.6e-4 r of translation and 0.6e-4 rad of rotation from the clip's pose.
  const Vec3 dp = Vec3(0.6, -0.3, 0.2).normalized() * (0.6e-4 * r);
  const Quat q1 = Quat(Eigen::AngleAxis<Real>(0.6e-4, Vec3(0.3, 1, 0.2).normalized())) * q0;
  both(p0 + dp, q1);
  CHECK(cached.space.getNumReusedManifolds() == 1);
  {
    const auto& a = cached.out[0].points();
    const auto& b = fresh.out[0].points();
    REQUIRE(a.size() == b.size());
    const Real tilt = 0.002 + 0.6e-4;  // relative tilt of the two faces
    for (size_t k = 0; k < a.size(); ++k) {
      CAPTURE(k);
      CHECK(a[k].featureId == b[k].featureId);
      CHECK((a[k].point - b[k].point).norm() <= 2e-4 * r + 1e-12);
      CHECK(std::abs(a[k].depth - b[k].depth) <= 2e-4 * r * tilt + 1e-12);
      CHECK((a[k].normal - b[k].normal).norm() <= 1e-4 + 1e-12);
    }
    // The reuse is not a copy of the clip's answer: the depths moved with the bodies.
    Real moved = 0;
    for (size_t k = 0; k < a.size(); ++k) moved = std::max(moved, std::abs(a[k].depth - clipDepths[k]));
    CHECK(moved > 1e-6);  // dp has a normal component of about 1.4e-5 m
  }

  // Past the tolerance (1.2e-4 r from the clip's pose, though only 0.6e-4 r from the last step's): clipped again.
  both(p0 + 2 * dp, q0);
  CHECK(cached.space.getNumReusedManifolds() == 0);
  same();
  both(p0 + 2 * dp, q0);  // unchanged pose: reused, and then the points are exactly the clip's
  CHECK(cached.space.getNumReusedManifolds() == 1);
  {
    const auto& a = cached.out[0].points();
    const auto& b = fresh.out[0].points();
    for (size_t k = 0; k < a.size(); ++k) {
      CHECK((a[k].point - b[k].point).norm() <= 1e-12);
      CHECK(std::abs(a[k].depth - b[k].depth) <= 1e-12);
    }
  }

  // New extents at the same pose: clipped again.
  cached.upperShape->setHalfExtents(Vec3(0.4, 0.3, 0.2505));
  fresh.upperShape->setHalfExtents(Vec3(0.4, 0.3, 0.2505));
  both(p0 + 2 * dp, q0);
  CHECK(cached.space.getNumReusedManifolds() == 0);
  same();

  // Switched off: every step clips.
  cached.space.setUsePersistentManifolds(false);
  both(p0 + 2 * dp, q0);
  CHECK(cached.space.getNumReusedManifolds() == 0);
  same();
}

// The lookup of last step's manifold among many (Space::reuseManifold searches the sorted pair keys): a column of
// boxes resting face on face and a row beside it on a static slab, 13 box-box pairs. A lookup that misses some
// keys (an off-by-one in the search finds only the first or last) would re-clip those pairs silently: the
// contacts would still be right, so the count of reused manifolds is what is checked. With nothing moved, every
// pair is reused on the second collide, and its points are the first clip's bit for bit.
TEST_CASE("persistent box-box manifolds: every pair of a resting pile is found and reused") {
  Space space;
  std::vector<RigidBodyRef> bodies;
  std::vector<GeometryRef> geoms;
  auto addBox = [&](const Vec3& half, const Vec3& p, bool dynamic) {
    GeometryRef g = std::make_shared<Geometry>(std::make_shared<Box>(half));
    if (dynamic) {
      RigidBodyRef b = std::make_shared<RigidBody>();
      b->add(g);
      b->setPosition(p);
      bodies.push_back(b);
    } else {
      g->setPosition(p);
    }
    space.add(g);
    geoms.push_back(g);
  };
  addBox(Vec3(10, 10, 0.5), Vec3(0, 0, -0.5), false);  // the slab
  const Real h = 0.25, depth = 1e-3;                     // half size and overlap of each resting contact
  for (int i = 0; i < 7; ++i) addBox(Vec3(h, h, h), Vec3(0, 0, h + i * (2 * h - depth) - depth), true);  // column
  for (int i = 1; i <= 6; ++i) addBox(Vec3(h, h, h), Vec3(3 * i * h, 2, h - depth), true);              // row
  std::vector<GeometryContact> first, second;
  space.collide(1.0 / 60, first);
  CHECK(space.getNumReusedManifolds() == 0);
  REQUIRE(first.size() == 13);  // 6 contacts up the column, 7 boxes on the slab
  CHECK_FALSE(space.getBroadphase().lastCallReused());  // the first call bins
  space.collide(1.0 / 60, second);
  CHECK(space.getNumReusedManifolds() == 13);
  CHECK(space.getBroadphase().lastCallReused());  // nothing moved: the kept candidates (on by default)
  REQUIRE(second.size() == first.size());
  for (size_t c = 0; c < first.size(); ++c) {
    REQUIRE(second[c].points().size() == first[c].points().size());
    CHECK(second[c].points().size() == 4);
    for (size_t k = 0; k < first[c].points().size(); ++k) {
      CHECK((second[c].points()[k].point - first[c].points()[k].point).norm() < 1e-12);
      CHECK(std::abs(second[c].points()[k].depth - first[c].points()[k].depth) < 1e-12);
      CHECK(second[c].points()[k].featureId == first[c].points()[k].featureId);
    }
  }
}

namespace {
void shift(Aabb& box, const Vec3& d) {
  box.lo += d;
  box.hi += d;
}

/// Both grids' pairs for `boxes`, required equal element for element; returns whether `kept` reused.
bool samePairs(UniformGrid& kept, UniformGrid& fresh, const std::vector<Aabb>& boxes) {
  PairList a, b;
  kept.findPairs(boxes, a);
  fresh.findPairs(boxes, b);
  REQUIRE(a == b);
  CHECK_FALSE(fresh.lastCallReused());
  return kept.lastCallReused();
}
}  // namespace

TEST_CASE("broadphase reuse returns the fresh grid's pairs in the same order while boxes move, jump and vanish") {
  // A grid that keeps its candidates (UniformGrid::setReuseRatio) against one that bins every call, over a run
  // of calls in which most boxes drift by micrometres (reuse), some jump by metres (the next call bins afresh),
  // one box is empty now and then and the number of boxes changes: the pairs must be identical, element for
  // element, on every call. Both sizes: the cells (300 boxes and two unbounded ones) and all pairs (20).
  for (const size_t n : {size_t(300), size_t(20)}) {
    CAPTURE(n);
    std::mt19937 rng(1234 + uint32_t(n));
    std::uniform_real_distribution<Real> unit(0, 1), jitter(-2e-6, 2e-6), jump(-3, 3);
    std::vector<Aabb> boxes = randomBoxes(rng, n, Sizes::MIXED, n > 100 ? 6.0 : 2.0);
    if (n > 100) {
      Aabb plane;  // unbounded, as Space gives a plane
      plane.lo = Vec3(-1e300, -1e300, -1e300);
      plane.hi = Vec3(1e300, 1e300, -5.0);
      boxes.push_back(plane);
      Aabb slab = boxAt(Vec3(0, 0, 0), Vec3(50, 50, 0.2));  // oversize
      boxes.push_back(slab);
    }
    UniformGrid kept(0.05), fresh;
    int reused = 0, binned = 0;
    PairList a, b;
    for (int call = 0; call < 400; ++call) {
      CAPTURE(call);
      const Real r = unit(rng);
      if (r < 0.05) {  // a jump: leaves its enlarged box
        const size_t i = size_t(unit(rng) * Real(boxes.size() - 1));
        shift(boxes[i], Vec3(jump(rng), jump(rng), jump(rng)));
      } else if (r < 0.07) {  // one box empty for this call: inverted on one axis only, so that enlarging it
        // would give a box that is not empty (and the grid must not keep candidates found with it)
        const size_t i = size_t(unit(rng) * Real(boxes.size() - 1));
        const Aabb saved = boxes[i];
        boxes[i].hi.x() = boxes[i].lo.x() - 1e-3;
        kept.findPairs(boxes, a);
        fresh.findPairs(boxes, b);
        CHECK_FALSE(kept.lastCallReused());
        REQUIRE(a == b);
        kept.findPairs(boxes, a);  // still empty: binned again
        CHECK_FALSE(kept.lastCallReused());
        REQUIRE(a == b);
        boxes[i] = saved;
      } else if (r < 0.08) {  // a box added or removed
        if (unit(rng) < 0.5) boxes.push_back(boxAt(Vec3(jump(rng), jump(rng), jump(rng)), Vec3::Constant(0.3)));
        else boxes.pop_back();
      }
      for (Aabb& box : boxes)  // everything drifts (the unbounded box stays)
        if (std::abs(box.lo.x()) <= 1e299) shift(box, Vec3(jitter(rng), jitter(rng), jitter(rng)));
      (samePairs(kept, fresh, boxes) ? reused : binned) += 1;
    }
    // Both paths ran: most calls reuse, the jumps and resizes bin afresh.
    CHECK(reused > 250);
    CHECK(binned > 10);
    fresh.findPairs(boxes, b);
    REQUIRE(b.size() > n / 20);  // the pairs are not trivially empty
  }
}

TEST_CASE("broadphase reuse backs off while every call moves the boxes and resumes when they rest") {
  // Boxes that jump on every call leave their enlarged boxes each time: the grid then bins plainly for 1, 2, 4 ...
  // 64 calls between tries (the pairs are the same either way), and once the boxes rest it reuses again within
  // the longest back-off.
  std::mt19937 rng(77);
  std::uniform_real_distribution<Real> jump(-2, 2);
  std::vector<Aabb> boxes = randomBoxes(rng, 200, Sizes::UNIFORM, 5.0);
  UniformGrid kept(0.05), fresh;
  PairList a, b;
  int reused = 0;
  for (int call = 0; call < 150; ++call) {
    for (Aabb& box : boxes) shift(box, Vec3(jump(rng), jump(rng), jump(rng)));
    reused += samePairs(kept, fresh, boxes);
  }
  CHECK(reused == 0);
  int firstReuse = -1;
  for (int call = 0; call < 70 && firstReuse < 0; ++call) {
    kept.findPairs(boxes, a);
    fresh.findPairs(boxes, b);
    REQUIRE(a == b);
    if (kept.lastCallReused()) firstReuse = call;
  }
  CHECK(firstReuse >= 0);
  CHECK(firstReuse <= 66);  // at most 64 plain calls, one binning, then the first reuse
}

TEST_CASE("broadphase reuse ratio: bad values are rejected and leave the ratio unchanged; Space's default") {
  UniformGrid grid(0.05);
  for (const Real bad : {-0.1, std::nan(""), std::numeric_limits<Real>::infinity()}) {
    CHECK_THROWS_AS(grid.setReuseRatio(bad), std::invalid_argument);
    CHECK(grid.getReuseRatio() == 0.05);
  }
  Space space;
  CHECK(space.getBroadphaseReuseRatio() == Space::kDefaultBroadphaseReuseRatio);
  CHECK_THROWS_AS(space.setBroadphaseReuseRatio(-1), std::invalid_argument);
  CHECK(space.getBroadphaseReuseRatio() == Space::kDefaultBroadphaseReuseRatio);
  // Off: the same boxes bin on every call.
  grid.setReuseRatio(0);
  const std::vector<Aabb> boxes = {boxAt(Vec3::Zero(), Vec3::Constant(1)), boxAt(Vec3(1, 0, 0), Vec3::Constant(1))};
  PairList pairs;
  for (int k = 0; k < 3; ++k) {
    grid.findPairs(boxes, pairs);
    CHECK_FALSE(grid.lastCallReused());
    CHECK(pairs == PairList{{0, 1}});
  }
}
