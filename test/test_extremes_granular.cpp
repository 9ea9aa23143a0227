// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Long particle runs (label extremes: not run under the sanitizers): 5,000 particles poured into a box settle,
// and heaps poured on a plate steepen with rolling resistance.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include <scree/scree.h>

#include "scenes/particle_scenes.h"

using namespace scree;
using namespace scree::scenes;

TEST_SUITE("granular") {
  // One thread: results do not depend on the thread count (test_analytic_granular asserts bit-identical
  // states on 1 and 2 threads), and on a shared, oversubscribed machine OpenMP barriers waiting for a
  // descheduled partner thread dominate these long runs.
  struct OneThread {
    OneThread() { setNumThreads(1); }
    ~OneThread() { setNumThreads(0); }
  };

  TEST_CASE("5000 particles poured into a box settle with penetration below 2 % of the radius") {
    // spheres10k's box and jittered lattice with 5000 spheres (16 layers), dt 1/200, 20 iterations, 3 s.
    OneThread one;
    SphereLatticeParams p;
    p.count = 5000;
    p.jitter = true;
    p.dt = 1.0 / 200.0;
    ParticleScene s = buildParticleLattice(p);
    s.sim->getSolver().setNumIterations(20);
    const ParticleMetrics m0 = measureParticles(s);
    // Potential energy released if every particle fell by one radius: the scale for "at rest".
    const Real scale = m0.totalMass * 9.81 * p.radius;
    Real keMid = 0;
    const int steps = 600;
    for (int i = 0; i < steps; ++i) {
      s.step();
      if (i == steps / 2) keMid = measureParticles(s).kineticEnergy;
    }
    const ParticleMetrics m = measureParticles(s);
    std::printf("pour 5000: max penetration %.3g mm = %.3g %% of r (pair %.3g, floor %.3g, wall %.3g mm), "
                "KE %.3g J (at 1.5 s %.3g J), mean z %.3f m\n",
                m.maxPenetration * 1e3, 100 * m.maxPenetration / p.radius, m.maxPenPair * 1e3, m.maxPenFloor * 1e3,
                m.maxPenWall * 1e3, m.kineticEnergy, keMid, m.meanHeight);
    CHECK(m.finite);
    CHECK(m.count == 5000);
    CHECK(m.totalMass == doctest::Approx(m0.totalMass).epsilon(1e-12));
    CHECK(m.escaped == 0);
    // At rest: kinetic energy below 1e-4 of m g r (speeds of order 1 mm/s), and decayed since mid-run.
    CHECK(m.kineticEnergy < 1e-4 * scale);
    CHECK(m.kineticEnergy <= keMid);
    // The accuracy target at 20 iterations and dt 1/200.
    CHECK(m.maxPenetration < 0.02 * p.radius);
    // The heap is a packing, not a collapse: 16 lattice layers of spacing 0.11 end no lower than a dense
    // random packing (fraction <= 0.64) would put them: mean centre height >= 0.4 m.
    CHECK(m.meanHeight > 0.4);
  }

  TEST_CASE("a heap poured on a plate steepens with rolling resistance") {
    // Particles r = 1 cm, mu 0.5, poured from a 3x3 nozzle 0.3 m above the centre of a 0.8 x 0.8 m plate;
    // particles falling off the plate are destroyed. The angle of repose is the slope of the heap's surface
    // fitted between 20 % and 80 % of the heap's base radius.
    OneThread one;
    auto heapAngle = [](Real rolling) {
      const Real r = 0.01, dt = 1.0 / 200.0;
      Scene s;
      initScene(s, "heap", 0.5, dt, 0);
      s.material->setDensity(2500);
      s.contactMaterial->setRollingResistanceCoefficient(rolling);
      addStaticBox(s, Vec3(0.4, 0.4, 0.05), Vec3(0, 0, -0.05));
      s.sim->getSolver().setNumIterations(20);
      GranularBodySystem& ps = s.sim->getGranularBodySystem();
      ps.setMaterial(s.material);
      uint64_t rng = 11;
      const int emitSteps = 900, settleSteps = 300;
      for (int i = 0; i < emitSteps + settleSteps; ++i) {
        if (i < emitSteps && i % 6 == 0)
          for (int a = -1; a <= 1; ++a)
            for (int b = -1; b <= 1; ++b)
              ps.createParticle(Vec3(a * 2.2 * r + 0.002 * splitmixSymmetric(rng), b * 2.2 * r + 0.002 * splitmixSymmetric(rng),
                                     0.3),
                                r, Vec3(0, 0, -0.5));
        s.step();
        if (i % 50 == 0) {
          std::vector<size_t> gone;
          ps.forEachParticle([&](size_t id) {
            if (ps.getPosition(id).z() < -0.2) gone.push_back(id);
          });
          for (size_t id : gone) ps.destroyParticle(id);
        }
      }
      // Surface profile: highest particle top per radial bin of width 2r.
      std::vector<Real> top(64, 0.0);
      Real base = 0;
      ps.forEachParticle([&](size_t id) {
        const Vec3 x = ps.getPosition(id);
        if (x.z() < 0) return;
        const Real rho = std::hypot(x.x(), x.y());
        if (x.z() < 1.5 * r) base = std::max(base, rho);
        const size_t bin = size_t(rho / (2 * r));
        if (bin < top.size()) top[bin] = std::max(top[bin], x.z() + r);
      });
      Real sx = 0, sy = 0, sxx = 0, sxy = 0;
      int n = 0;
      for (size_t b = 0; b < top.size(); ++b) {
        const Real rho = (Real(b) + 0.5) * 2 * r;
        if (rho < 0.2 * base || rho > 0.8 * base || top[b] <= 0) continue;
        sx += rho;
        sy += top[b];
        sxx += rho * rho;
        sxy += rho * top[b];
        ++n;
      }
      if (n < 3) return 0.0;  // no heap left on the plate (everything rolled off): flat
      const Real slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
      const Real angle = std::atan(-slope) * 180 / std::numbers::pi;
      std::printf("heap: rolling resistance %.2f -> %zu particles, base radius %.3f m, angle of repose %.1f deg\n",
                  rolling, ps.numParticles(), base, angle);
      return angle;
    };
    const Real a0 = heapAngle(0.0), a1 = heapAngle(0.1), a2 = heapAngle(0.3);
    // Spheres with no rolling resistance roll off the plate (no heap: angle 0); resistance lets them lock
    // into a heap that steepens with the coefficient.
    CHECK(a0 < a1);
    CHECK(a1 < a2);
    CHECK(a1 > 5);
    // No heap of cohesionless spheres stands steeper than 45 deg.
    CHECK(a2 < 45);
  }
}
