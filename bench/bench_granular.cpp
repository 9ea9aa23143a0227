// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Particle benchmarks (GranularBodySystem):
//   spheres10k_jitter as particles (docs/scenes.md: 10,000 spheres r 0.05, dt 1/100, 10 iterations, 300 steps),
//     on 1 and 2 threads: median and mean ms/step over the whole run, and the scene's metrics at the end
//     (max penetration in mm and in % of the radius, kinetic energy, escaped spheres);
//   the same lattice with 100k spheres in a larger box (perRow 57, inner half width 3.145 m), first 60 steps
//     (the fall and first impacts; the full 300 steps take minutes on this machine);
//   a scaling series N = 1e3 ... 2e5 (lattices with perRow = sqrt(N/31)), 20 steps after 20 warm-up steps,
//     reporting ms/step, microseconds per particle and per contact;
//   a 512-particle glued lump in the DIRECT particle mode against the same lump solved iteratively.
// One benchmark iteration is one complete run (Iterations(1)); timing is per step with std::chrono, and the
// median is what to compare (the machine is shared).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "scenes/particle_scenes.h"

namespace {
using namespace scree;
using namespace scree::scenes;
using Clock = std::chrono::steady_clock;

struct RunTimes {
  double median = 0, mean = 0;
  size_t contacts = 0;
};
RunTimes timeSteps(ParticleScene& s, int warmup, int steps) {
  for (int i = 0; i < warmup; ++i) s.step();
  std::vector<double> ms;
  ms.reserve(size_t(steps));
  size_t contacts = 0;
  for (int i = 0; i < steps; ++i) {
    const auto t0 = Clock::now();
    s.step();
    ms.push_back(std::chrono::duration<double>(Clock::now() - t0).count() * 1e3);
    contacts += s.sim->getStepStats().numParticleContacts;
  }
  RunTimes r;
  for (double x : ms) r.mean += x;
  r.mean /= double(ms.size());
  std::nth_element(ms.begin(), ms.begin() + long(ms.size() / 2), ms.end());
  r.median = ms[ms.size() / 2];
  r.contacts = contacts / size_t(steps);
  return r;
}

void reportMetrics(benchmark::State& state, const ParticleScene& s) {
  const ParticleMetrics m = measureParticles(s);
  state.counters["max_pen_mm"] = m.maxPenetration * 1e3;
  state.counters["max_pen_pct_r"] = 100 * m.maxPenetration / s.params.radius;
  state.counters["pen_pair_mm"] = m.maxPenPair * 1e3;
  state.counters["pen_floor_mm"] = m.maxPenFloor * 1e3;
  state.counters["pen_wall_mm"] = m.maxPenWall * 1e3;
  state.counters["kinetic_J"] = m.kineticEnergy;
  state.counters["escaped"] = double(m.escaped);
  state.counters["mean_z"] = m.meanHeight;
}

// spheres10k_jitter, full defined run, arg = threads.
void BM_Spheres10kJitter(benchmark::State& state) {
  const int threads = int(state.range(0));
  setNumThreads(threads);
  for (auto _ : state) {
    state.PauseTiming();
    ParticleScene s = buildParticles10kJitter();
    state.ResumeTiming();
    const RunTimes t = timeSteps(s, 0, s.numSteps);
    state.PauseTiming();
    state.counters["median_ms_per_step"] = t.median;
    state.counters["mean_ms_per_step"] = t.mean;
    state.counters["contacts"] = double(t.contacts);
    reportMetrics(state, s);
    state.ResumeTiming();
  }
  state.counters["threads"] = threads;
  setNumThreads(0);
}
BENCHMARK(BM_Spheres10kJitter)->Arg(1)->Arg(2)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// 100k spheres in a larger box, first 60 steps, arg = threads.
void BM_Spheres100kJitter(benchmark::State& state) {
  const int threads = int(state.range(0));
  setNumThreads(threads);
  for (auto _ : state) {
    state.PauseTiming();
    SphereLatticeParams p;
    p.count = 100000;
    p.perRow = 57;
    p.jitter = true;
    ParticleScene s = buildParticleLattice(p);
    state.ResumeTiming();
    const RunTimes t = timeSteps(s, 0, 60);
    state.PauseTiming();
    state.counters["median_ms_per_step"] = t.median;
    state.counters["mean_ms_per_step"] = t.mean;
    state.counters["contacts"] = double(t.contacts);
    reportMetrics(state, s);
    state.ResumeTiming();
  }
  state.counters["threads"] = threads;
  setNumThreads(0);
}
BENCHMARK(BM_Spheres100kJitter)->Arg(2)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// Scaling: N particles, 20 warm-up steps then 20 timed steps; args = N, threads.
void BM_ParticleScaling(benchmark::State& state) {
  const size_t n = size_t(state.range(0));
  const int threads = int(state.range(1));
  setNumThreads(threads);
  for (auto _ : state) {
    state.PauseTiming();
    SphereLatticeParams p;
    p.count = n;
    p.perRow = std::max(2, int(std::lround(std::sqrt(double(n) / 31.0))));
    p.jitter = true;
    ParticleScene s = buildParticleLattice(p);
    state.ResumeTiming();
    const RunTimes t = timeSteps(s, 20, 20);
    state.PauseTiming();
    state.counters["median_ms_per_step"] = t.median;
    state.counters["us_per_particle"] = t.median * 1e3 / double(n);
    state.counters["contacts"] = double(t.contacts);
    state.counters["us_per_contact"] = t.contacts ? t.median * 1e3 / double(t.contacts) : 0.0;
    state.ResumeTiming();
  }
  state.counters["threads"] = threads;
  setNumThreads(0);
}
BENCHMARK(BM_ParticleScaling)
    ->Args({1000, 2})
    ->Args({10000, 2})
    ->Args({50000, 2})
    ->Args({100000, 2})
    ->Args({200000, 2})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The manual's DIRECT particle mode: a glued lump of 8 x 8 x 8 = 512 touching particles (r 0.05, simple cubic,
// 1344 particle pairs) with infinite friction and adhesion, adhesive overlap 0, restitution 0, dropped 5 cm onto
// the ground at dt 1/60; 20 warm-up steps (fall and landing), then 40 timed steps at rest. arg 0: DIRECT (the
// pairs are one equality system solved by one factorisation per step; the ground contacts are unilateral),
// arg 1: ITERATIVE (the particle stage's Gauss-Seidel, default 16 sweeps), arg 2: DIRECT with infinite
// particle-ground friction as well (only the 64 ground normals are bounded). Counters: median ms/step; the worst
// relative displacement | |x_i - x_j| - 2r | over the lump's neighbour pairs, over the whole run (landing
// included) and at the end (at rest the compliance gives 7 m g / E = 36 N / 2e8 N/m = 1.8e-7 m in the bottom
// layer); direct rows, factorisations, pivots and ms spent in numeric factorisations per step (means over the
// timed steps); direct solves that fell back to PGS over the whole run.
void BM_GluedLumpDirect(benchmark::State& state) {
  const bool iterative = state.range(0) == 1, stickyGround = state.range(0) == 2;
  for (auto _ : state) {
    state.PauseTiming();
    Simulation sim;
    const Real dt = 1.0 / 60.0, r = 0.05, d = 2 * r;
    sim.setTimeStep(dt);
    sim.setUniformGravity(Vec3(0, 0, -9.81));
    auto glue = std::make_shared<Material>("glue");
    auto ground = std::make_shared<Material>("ground");
    const auto type = iterative ? FrictionModel::ITERATIVE : FrictionModel::DIRECT;
    auto cm = sim.getMaterialManager().getOrCreateContactMaterial(glue, glue);
    cm->setFrictionCoefficient(std::numeric_limits<Real>::infinity());
    cm->setAdhesion(std::numeric_limits<Real>::infinity(), 0.0);
    cm->setRestitution(0.0);
    cm->setSolveType(type);
    auto cg = sim.getMaterialManager().getOrCreateContactMaterial(glue, ground);
    cg->setRestitution(0.0);
    cg->setSolveType(type);
    if (stickyGround) cg->setFrictionCoefficient(std::numeric_limits<Real>::infinity());
    auto floor = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(5, 5, 0.5)));
    floor->setMaterial(ground);
    auto floorBody = std::make_shared<RigidBody>();
    floorBody->setMotionControl(RigidBody::STATIC);
    floorBody->add(floor);
    floorBody->setPosition(Vec3(0, 0, -0.5));
    sim.add(floorBody);
    auto& ps = sim.getGranularBodySystem();
    ps.setMaterial(glue);
    const int k = 8;
    std::vector<size_t> ids;
    for (int z = 0; z < k; ++z)
      for (int y = 0; y < k; ++y)
        for (int x = 0; x < k; ++x) ids.push_back(ps.createParticle(Vec3(x * d, y * d, r + 0.05 + z * d), r));
    auto at = [&](int x, int y, int z) { return ps.getPosition(ids[size_t((z * k + y) * k + x)]); };
    auto spread = [&] {
      Real worst = 0;
      for (int z = 0; z < k; ++z)
        for (int y = 0; y < k; ++y)
          for (int x = 0; x < k; ++x) {
            if (x + 1 < k) worst = std::max(worst, std::abs((at(x + 1, y, z) - at(x, y, z)).norm() - d));
            if (y + 1 < k) worst = std::max(worst, std::abs((at(x, y + 1, z) - at(x, y, z)).norm() - d));
            if (z + 1 < k) worst = std::max(worst, std::abs((at(x, y, z + 1) - at(x, y, z)).norm() - d));
          }
      return worst;
    };
    Real worstRun = 0;
    int fallbacks = 0;
    for (int i = 0; i < 20; ++i) {
      sim.stepForward();
      worstRun = std::max(worstRun, spread());
      fallbacks += sim.getSolver().getStats().directFallback ? 1 : 0;
    }
    state.ResumeTiming();
    std::vector<double> ms;
    double rows = 0, facts = 0, pivots = 0, factorMs = 0;
    const int steps = 40;
    for (int i = 0; i < steps; ++i) {
      const auto t0 = Clock::now();
      sim.stepForward();
      ms.push_back(std::chrono::duration<double>(Clock::now() - t0).count() * 1e3);
      state.PauseTiming();
      const SolverStats& st = sim.getSolver().getStats();
      rows += double(st.numDirectRows);
      facts += double(st.numFactorisations);
      pivots += double(st.numPivots);
      factorMs += st.factorisationTime * 1e3;
      fallbacks += st.directFallback ? 1 : 0;
      worstRun = std::max(worstRun, spread());
      state.ResumeTiming();
    }
    state.PauseTiming();
    std::nth_element(ms.begin(), ms.begin() + long(ms.size() / 2), ms.end());
    state.counters["median_ms_per_step"] = ms[ms.size() / 2];
    state.counters["worst_rel_disp_m"] = worstRun;
    state.counters["rest_rel_disp_m"] = spread();
    state.counters["fallbacks"] = fallbacks;
    state.counters["direct_rows"] = rows / steps;
    state.counters["factorisations"] = facts / steps;
    state.counters["pivots"] = pivots / steps;
    state.counters["factor_ms_per_step"] = factorMs / steps;
    state.counters["contacts"] = double(sim.getStepStats().numParticleContacts);
    state.ResumeTiming();
  }
}
BENCHMARK(BM_GluedLumpDirect)->Arg(0)->Arg(1)->Arg(2)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
