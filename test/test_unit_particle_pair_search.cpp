// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The particle pair search's two-speed grid (collide/include/scree/collide/particle_collider.h, "Two-speed
// grid") against a brute-force search over all pairs, step after step, on a moving cloud like the trench's:
// a block carried at a common velocity (the bucket's soil), particles at rest (the ground's heap), and fast ones
// (flung and falling), with particles created, destroyed and reordered between steps.
//
// The rule (the header's): a pair is a contact when its gap is below min(h |v_a - v_b| + margin, reach), with
// reach = min(2 h max|v| + margin, one largest diameter). The brute force evaluates the same floating-point
// expressions as the collider's exact test, so the lists must agree exactly, pair for pair and in (a, b) order:
// one missed pair (for example one the fast particles should find, or a slow pair beyond the small grid's cell)
// fails the step's comparison.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <scree/scree.h>
#include "scree/collide/particle_collider.h"
#include "particle_pairs_brute.h"

using namespace scree;

namespace {
// Deterministic generator (splitmix64).
struct Rng {
  uint64_t s;
  uint64_t next() {
    uint64_t z = (s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  Real uniform() { return Real(next() >> 11) * 0x1.0p-53; }
  Vec3 inBox(Real a) { return Vec3(a * uniform(), a * uniform(), a * uniform()); }
  Vec3 direction() { return Vec3(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5); }
};

using Pairs = test::ParticlePairs;
using test::bruteForce;
using test::pairsOf;
}  // namespace

TEST_SUITE("granular") {
  TEST_CASE("the two-speed pair search equals a brute-force search on a moving cloud with creation and removal") {
    // Radii 4-6 mm. A 0.12 m block of 1,200 particles moving at (0.4, 0, 0) m/s with up to 0.017 m/s of scatter
    // (the carried soil: the median velocity is theirs, most of them are slow against it), 600 at rest beside it
    // touching its side (fast against the median: h |v - u| = 6.7 mm, above a quarter radius), 150 fast ones
    // at 0.5-3 m/s in random directions through both; each kind meets each kind.
    // Run twice (doctest subcases): with the four-wide candidate filter (header, "Candidate filter") where the
    // CPU has AVX2, and with the scalar test alone; both must equal the brute force in every step.
    bool filter = true;
    SUBCASE("four-wide candidate filter on") { filter = true; }
    SUBCASE("candidate filter off (scalar test only)") { filter = false; }
    detail::ParticleCollider::setPairFilterEnabled(filter);
    const bool expectFilter = filter && detail::ParticleCollider::pairFilterAvailable();
    MESSAGE((expectFilter ? std::string("candidate filter on") : std::string("candidate filter off")));
    size_t stepsFiltered = 0;
    const Real h = 1.0 / 60;
    GranularBodySystem ps;
    Rng rng{2026};
    const Vec3 carried(0.4, 0, 0);
    auto addCarried = [&](const Vec3& p) {
      ps.createParticle(p, 0.004 + 0.002 * rng.uniform(), carried + 0.02 * rng.direction());
    };
    auto addResting = [&](const Vec3& p) { ps.createParticle(p, 0.004 + 0.002 * rng.uniform()); };
    auto addFast = [&](const Vec3& p) {
      ps.createParticle(p, 0.004 + 0.002 * rng.uniform(), (1 + 5 * rng.uniform()) * rng.direction());
    };
    for (int k = 0; k < 1200; ++k) addCarried(rng.inBox(0.12));
    for (int k = 0; k < 600; ++k) addResting(Vec3(0.12, 0, 0) + Vec3(0.06, 0.12, 0.12).cwiseProduct(rng.inBox(1)));
    for (int k = 0; k < 150; ++k) addFast(Vec3(0.18, 0.12, 0.12).cwiseProduct(rng.inBox(1)));

    detail::ParticleCollider collider;
    size_t pairsChecked = 0, stepsWithBoth = 0, fastMin = SIZE_MAX;
    bool hashedChecked = false;
    for (int step = 0; step < 40; ++step) {
      // Between steps, as the trench does: particles are created (at the block's front) and destroyed
      // (merged), and every 10 steps the dense order is permuted.
      for (int k = 0; k < 15; ++k) {
        const Vec3 p = Vec3(0.12 + 0.4 * h * step, 0, 0) + Vec3(0.02, 0.12, 0.12).cwiseProduct(rng.inBox(1));
        if (k % 5 == 0) addFast(p);
        else addCarried(p);
      }
      const auto ids = ps.getParticleIds();
      for (int k = 0; k < 8; ++k) ps.destroyParticle(ids[size_t(rng.next() % ids.size())]);
      if (step % 10 == 5) {
        std::vector<uint32_t> order(ps.size());
        for (size_t k = 0; k < order.size(); ++k) order[k] = uint32_t(order.size() - 1 - k);
        ps.reorder(order);
      }
      // Step 30: one particle 1e6 m away, so the live cells' box is too large for the dense grid and the hashed
      // grid is searched (also by the fast particles).
      size_t farId = 0;
      if (step == 30) farId = ps.createParticle(Vec3(1e6, 0, 0), 0.005, Vec3(1, 0, 0));

      collider.collide(ps, {}, h);
      const Pairs found = pairsOf(collider);
      const Pairs expected = bruteForce(ps, h, collider.getContactMargin());
      INFO("step " << step << ": " << collider.getNumFastParticles() << " fast of " << ps.numParticles());
      REQUIRE(found == expected);
      if (collider.usedPairFilter()) ++stepsFiltered;
      pairsChecked += expected.size();
      const size_t fast = collider.getNumFastParticles();
      fastMin = std::min(fastMin, fast);
      if (fast > 0 && fast < ps.numParticles() / 2) ++stepsWithBoth;
      if (farId) {
        hashedChecked = true;
        ps.destroyParticle(farId);
      }

      // Move: x += h v, gravity on the fast ones' velocities only (the block and the heap keep their speeds, so
      // the split stays), so the neighbourhoods change from step to step.
      auto& x = ps.positions();
      auto& v = ps.velocities();
      for (size_t i = 0; i < ps.size(); ++i) {
        x[i] += h * v[i];
        if (v[i].norm() > 0.6) v[i].z() -= 9.81 * h;
      }
    }
    // The comparison meant something: many pairs, and both searches ran in every step (slow particles through
    // the half stencil, fast ones through their own wider search).
    CHECK(pairsChecked > 40 * 2000);
    CHECK(stepsWithBoth == 40);
    CHECK(fastMin > 100);
    CHECK(hashedChecked);
    // The filter runs on the dense grid only: in the first 7 steps here (then the flung particles' box grows past
    // the dense grid's size limit and the hashed grid takes over), never when off.
    if (expectFilter) CHECK(stepsFiltered >= 5);
    else CHECK(stepsFiltered == 0);
    detail::ParticleCollider::setPairFilterEnabled(true);
  }
}
