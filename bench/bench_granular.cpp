// Particle benchmarks (GranularBodySystem):
//   spheres10k_jitter as particles (SCENES.md: 10,000 spheres r 0.05, dt 1/100, 10 iterations, 300 steps),
//     on 1 and 2 threads: median and mean ms/step over the whole run, and the scene's metrics at the end
//     (max penetration in mm and in % of the radius, kinetic energy, escaped spheres);
//   the same lattice with 100k spheres in a larger box (perRow 57, inner half width 3.145 m), first 60 steps
//     (the fall and first impacts; the full 300 steps take minutes on this machine);
//   a scaling series N = 1e3 ... 2e5 (lattices with perRow = sqrt(N/31)), 20 steps after 20 warm-up steps,
//     reporting ms/step, microseconds per particle and per contact.
// One benchmark iteration is one complete run (Iterations(1)); timing is per step with std::chrono, and the
// median is what to compare (the machine is shared).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
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

}  // namespace

BENCHMARK_MAIN();
