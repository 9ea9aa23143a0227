// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// GranularBodySystem container: stable ids across create/destroy/reorder, exact conservation of count and mass,
// custom buffers following their particles, deferred destroys during iteration, and bad input.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <stdexcept>
#include <utility>
#include <vector>

#include <scree/scree.h>
#include "scree/collide/particle_collider.h"
#include "particle_pairs_brute.h"

using namespace scree;
using scree::test::bruteForce;
using scree::test::pairsOf;

namespace {
// Deterministic generator for the create/destroy cycles (splitmix64).
struct SplitMix {
  uint64_t s;
  uint64_t next() {
    uint64_t z = (s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
};
}  // namespace

// Pair search: ParticleCollider (collide/include/scree/collide/particle_collider.h) against a brute-force
// search over all pairs with the header's rule: a pair is a contact when its gap is below
// min(h |v_a - v_b| + margin, one largest diameter). Both grids are checked: the dense grid (the live cells' box
// is small) and the hashed grid it falls back to when a particle is flung far away. The brute force evaluates
// the same floating-point expressions (squared distances of x_a - x_b, sums of radii and margin, commutative in
// floating point), so the lists must agree exactly, pair for pair and in (a, b) order.
namespace {
Real uniform(SplitMix& g) { return Real(g.next() >> 11) * 0x1.0p-53; }

}  // namespace

TEST_SUITE("granular") {
  TEST_CASE("particle mass is density times sphere volume") {
    GranularBodySystem g;
    auto m = std::make_shared<Material>("sand");
    m->setDensity(2500);
    g.setMaterial(m);
    const size_t id = g.createParticle(Vec3(1, 2, 3), 0.05, Vec3(0, 0, -1));
    // 2500 * 4/3 pi 0.05^3 = 1.30899694 kg (docs/scenes.md spheres10k quotes 1.309 kg); only round-off differs.
    CHECK(g.getMass(id) == doctest::Approx(2500 * 4.0 / 3.0 * std::numbers::pi * 0.125e-3).epsilon(1e-14));
    CHECK(g.getPosition(id) == Vec3(1, 2, 3));
    CHECK(g.getVelocity(id) == Vec3(0, 0, -1));
    CHECK(g.getRadius(id) == 0.05);
    CHECK(g.getParticleMaterial(id) == m);
    CHECK(id != 0);
  }

  TEST_CASE("ids stay valid and point at the same particle through create, destroy and reorder cycles") {
    GranularBodySystem g;
    g.addCustomBufferReal("tag");
    std::map<size_t, Real> expectTag;     // id -> tag value (unique per particle)
    std::vector<size_t> dead;             // destroyed ids must stay invalid even when the slot is reused
    SplitMix rng{42};
    Real nextTag = 1;
    for (int round = 0; round < 50; ++round) {
      const int nCreate = int(rng.next() % 40);
      for (int k = 0; k < nCreate; ++k) {
        const Real r = 0.01 + 0.001 * Real(rng.next() % 10);
        const size_t id = g.createParticle(Vec3(nextTag, 0, 0), r);
        g.setCustomReal("tag", id, nextTag);
        expectTag[id] = nextTag;
        nextTag += 1;
      }
      const int nDestroy = int(rng.next() % 30);
      for (int k = 0; k < nDestroy && !expectTag.empty(); ++k) {
        auto it = expectTag.begin();
        std::advance(it, long(rng.next() % expectTag.size()));
        g.destroyParticle(it->first);
        dead.push_back(it->first);
        expectTag.erase(it);
      }
      if (round % 7 == 3 && g.size() > 1) {  // reverse the dense order
        std::vector<uint32_t> order(g.size());
        for (size_t k = 0; k < order.size(); ++k) order[k] = uint32_t(order.size() - 1 - k);
        g.reorder(order);
      }
      REQUIRE(g.numParticles() == expectTag.size());
      for (const auto& [id, tag] : expectTag) {
        REQUIRE(g.isValid(id));
        CHECK(g.getCustomReal("tag", id) == tag);
        CHECK(g.getPosition(id).x() == tag);  // position followed the particle through swaps and reorders
      }
    }
    for (size_t id : dead) CHECK_FALSE(g.isValid(id));
  }

  TEST_CASE("particle count and total mass are conserved exactly through create/destroy cycles") {
    GranularBodySystem g;
    auto heavy = std::make_shared<Material>("heavy");
    heavy->setDensity(7800);
    std::vector<size_t> ids;
    for (int i = 0; i < 2000; ++i) {
      if (i % 3 == 0) g.setMaterial(heavy);
      else g.setMaterial(std::make_shared<Material>("light"));
      ids.push_back(g.createParticle(Vec3::Zero(), 0.01 + 0.0001 * Real(i % 50)));
    }
    auto sortedMasses = [&] {
      std::vector<Real> m;
      g.forEachParticle([&](size_t id) { m.push_back(g.getMass(id)); });
      std::sort(m.begin(), m.end());
      return m;
    };
    auto sortedSum = [](const std::vector<Real>& m) {
      Real s = 0;
      for (Real x : m) s += x;
      return s;
    };
    const std::vector<Real> massesBefore = sortedMasses();
    const size_t nBefore = g.numParticles();
    // Destroy every other particle, then recreate the same ones (same radius and material).
    std::vector<std::pair<Real, MaterialRef>> removed;
    for (size_t k = 0; k < ids.size(); k += 2) {
      removed.push_back({g.getRadius(ids[k]), g.getParticleMaterial(ids[k])});
      g.destroyParticle(ids[k]);
    }
    CHECK(g.numParticles() == nBefore - removed.size());
    for (auto& [r, m] : removed) {
      g.setMaterial(m);
      g.createParticle(Vec3::Zero(), r);
    }
    CHECK(g.numParticles() == nBefore);
    // Exact: the multiset of particle masses is bit-identical, hence so is its sum in a fixed (sorted) order.
    const std::vector<Real> massesAfter = sortedMasses();
    CHECK(massesAfter == massesBefore);
    CHECK(sortedSum(massesAfter) == sortedSum(massesBefore));
    // getTotalMass sums in dense order, which changed: equal to within n rounding errors (2000 * 2^-53 rel.).
    CHECK(g.getTotalMass() == doctest::Approx(sortedSum(massesBefore)).epsilon(1e-12));
    // Integer-valued check with no round-off at all: count per material.
    size_t heavyCount = 0;
    g.forEachParticle([&](size_t id) { heavyCount += g.getParticleMaterial(id) == heavy; });
    CHECK(heavyCount == 667);
  }

  TEST_CASE("destroying inside forEachParticle is deferred and safe") {
    GranularBodySystem g;
    g.addCustomBufferReal("x");
    for (int i = 0; i < 100; ++i) g.setCustomReal("x", g.createParticle(Vec3(i, 0, 0), 0.1), i);
    int visited = 0;
    g.forEachParticle([&](size_t id) {
      ++visited;
      const Real x = g.getPosition(id).x();
      if (int(x) % 2 == 0) g.destroyParticle(id);
      if (x == 10) g.createParticle(Vec3(1000, 0, 0), 0.1);  // created during the loop: not visited
    });
    CHECK(visited == 100);
    CHECK(g.numParticles() == 51);
    CHECK(g.size() == 51);  // compacted after the loop
    g.forEachParticle([&](size_t id) {
      const Real x = g.getPosition(id).x();
      CHECK((x == 1000 || int(x) % 2 == 1));
      if (x != 1000) CHECK(g.getCustomReal("x", id) == x);
    });
  }

  TEST_CASE("bad input throws, names the parameter and leaves the system unchanged") {
    GranularBodySystem g;
    const size_t id = g.createParticle(Vec3(0, 0, 1), 0.1);
    auto throwsNaming = [](auto&& f, const char* text) {
      try {
        f();
      } catch (const std::invalid_argument& e) {
        return std::string(e.what()).find(text) != std::string::npos;
      }
      return false;
    };
    CHECK(throwsNaming([&] { g.createParticle(Vec3(NAN, 0, 0), 0.1); }, "position"));
    CHECK(throwsNaming([&] { g.createParticle(Vec3::Zero(), -0.1); }, "radius = -0.1"));
    CHECK(throwsNaming([&] { g.createParticle(Vec3::Zero(), 0.1, Vec3(INFINITY, 0, 0)); }, "velocity"));
    CHECK(throwsNaming([&] { g.setVelocity(id, Vec3(NAN, 0, 0)); }, "velocity"));
    CHECK(throwsNaming([&] { g.setMaterial(nullptr); }, "material"));
    CHECK(throwsNaming([&] { g.getPosition(id + 1); }, "id"));
    CHECK(throwsNaming([&] { g.setCustomReal("nope", id, 1); }, "nope"));
    CHECK(throwsNaming([&] { g.setRadius(id, 0); }, "radius = 0"));
    CHECK(g.numParticles() == 1);
    CHECK(g.getPosition(id) == Vec3(0, 0, 1));
    CHECK(g.getVelocity(id) == Vec3::Zero());
    CHECK(g.getRadius(id) == 0.1);
    g.destroyParticle(id);
    CHECK(throwsNaming([&] { g.destroyParticle(id); }, "id"));
    CHECK(g.numParticles() == 0);
  }

  TEST_CASE("the simulation owns one particle system") {
    Simulation sim;
    GranularBodySystem& g = sim.getGranularBodySystem();
    const size_t id = g.createParticle(Vec3(0, 0, 1), 0.1);
    CHECK(sim.getGranularBodySystem().numParticles() == 1);
    CHECK(sim.getGranularBodySystem().isValid(id));
  }

  TEST_CASE("the particle pair search finds exactly the brute-force pairs, on the dense and the hashed grid") {
    // 3,000 particles of radii 4-6 mm in a 0.25 m cube (packed densely enough for some 4 contacts each), speeds
    // up to 1 m/s (so some pairs need the speed margin and the reach is capped at one diameter), 50 destroyed.
    GranularBodySystem ps;
    SplitMix rng{12345};
    std::vector<size_t> ids;
    for (int k = 0; k < 3000; ++k) {
      const Vec3 p(0.25 * uniform(rng), 0.25 * uniform(rng), 0.25 * uniform(rng));
      const Vec3 vel = (k % 7 == 0 ? 1.0 : 0.1) * Vec3(uniform(rng) - 0.5, uniform(rng) - 0.5, uniform(rng) - 0.5);
      ids.push_back(ps.createParticle(p, 0.004 + 0.002 * uniform(rng), vel));
    }
    for (int k = 0; k < 50; ++k) ps.destroyParticle(ids[size_t(k * 37)]);
    const Real h = 1.0 / 60;
    detail::ParticleCollider collider;
    collider.collide(ps, {}, h);
    const auto dense = pairsOf(collider);
    const auto expected = bruteForce(ps, h, collider.getContactMargin());
    CHECK(expected.size() > 3000);  // a dense enough cloud for the test to mean something
    CHECK(dense == expected);

    // A particle 1e6 m away: the live cells' box is far beyond 8 cells per particle, so the hashed grid is used.
    ps.createParticle(Vec3(1e6, 0, 0), 0.005);
    collider.collide(ps, {}, h);
    const auto hashed = pairsOf(collider);
    CHECK(hashed == bruteForce(ps, h, collider.getContactMargin()));
    CHECK(hashed == dense);  // the far particle has no partner and the others' pairs are unchanged
  }
}
