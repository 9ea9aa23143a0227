// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Cost of terrain avalanches (issue 17; terrain.h "Dynamic height field: avalanches and the angle of repose").
//
// BM_avalanche_local/n: an n x n terrain (0.1 m cells, 0.5 m of soil, friction 0.5: repose atan(0.5)) with the
// dynamic height field on and the default avalanche settings (decay 0.1, life time 100 steps, extent 2); a
// local disturbance the size of a blade's berm - a ridge 2 m long, 0.3 m wide and 0.3 m high (21 x 3 vertices)
// at the centre, armed along its middle row - avalanches for its life time. One iteration = one stepForward() of the simulation (nothing else in it); the disturbance is rebuilt
// (timer paused, heights reset and booked) every life time. Counters: avalanche_ms (the terrain's avalanche
// pass per step, Terrain::getLastStepAvalancheTime), ms_per_step (stepForward), armed (armed vertices per step);
// these are wall-clock; the CPU column is the step's thread CPU time (steadier on a loaded machine). The claim:
// the cost follows the touched area, not the grid - the same at n = 257 and n = 513.
//
// BM_avalanche_all/n: avalancheAll() on an n x n field of random heights (uniform in [0.5, 1.5) m at 0.1 m cells:
// neighbours up to 20 x the repose difference apart), timed per call (the field is rebuilt with the timer
// paused). Counters: passes, moves (pair moves) per call.
#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>
#include <random>
#include <vector>

#include "scree/scree.h"
#include "scenes/scenes.h"

namespace {
using namespace scree;

struct AvalancheScene : scenes::Scene {
  TerrainRef terrain;
  explicit AvalancheScene(size_t n) {
    scenes::initScene(*this, "avalanche", 0.5, 1.0 / 60.0, 0);
    auto hf = std::make_shared<HeightField>(n, n, 0.1 * Real(n - 1), 0.1 * Real(n - 1));
    hf->setHeights(std::vector<Real>(n * n, 0.5));
    terrain = std::make_shared<Terrain>(hf);
    terrain->getGeometry()->setMaterial(material);
    sim->add(terrain);
  }
};

void BM_avalanche_local(benchmark::State& state) {
  using Clock = std::chrono::steady_clock;
  const size_t n = size_t(state.range(0)), c = n / 2;
  AvalancheScene scene(n);
  Terrain& t = *scene.terrain;
  HeightField& hf = *t.getHeightField();
  t.setEnableDynamicHeightField(true);
  const int life = t.getAvalancheStepLifeTime();
  const std::vector<Real> flat(n * n, 0.5);
  auto disturb = [&] {
    hf.setHeights(flat);
    for (size_t j = c - 1; j <= c + 1; ++j)
      for (size_t i = c - 10; i <= c + 10; ++i) hf.setHeight(i, j, 0.8);
    (void)t.getVolumeLedger();  // books the edit (a full-grid sum, once) outside the timed steps
    for (size_t i = c - 10; i <= c + 10; ++i) t.armAvalanche(i, c);
  };
  disturb();
  int steps = 0;
  double seconds = 0, avalancheSeconds = 0, armed = 0;
  for (auto _ : state) {
    if (steps == life) {
      state.PauseTiming();
      disturb();
      steps = 0;
      state.ResumeTiming();
    }
    armed += double(t.getNumArmedVertices());
    const auto t0 = Clock::now();
    scene.sim->stepForward();
    seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    avalancheSeconds += t.getLastStepAvalancheTime();
    ++steps;
  }
  state.counters["ms_per_step"] = benchmark::Counter(seconds * 1e3, benchmark::Counter::kAvgIterations);
  state.counters["avalanche_ms"] = benchmark::Counter(avalancheSeconds * 1e3, benchmark::Counter::kAvgIterations);
  state.counters["armed"] = benchmark::Counter(armed, benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_avalanche_local)->Arg(257)->Arg(513)->ArgName("n")->Unit(benchmark::kMicrosecond)->UseRealTime();

void BM_avalanche_all(benchmark::State& state) {
  const size_t n = size_t(state.range(0));
  AvalancheScene scene(n);
  Terrain& t = *scene.terrain;
  std::mt19937 rng(17);
  std::uniform_real_distribution<Real> u(0.5, 1.5);
  std::vector<Real> rough(n * n);
  for (Real& h : rough) h = u(rng);
  double passes = 0, moves = 0;
  for (auto _ : state) {
    state.PauseTiming();
    t.getHeightField()->setHeights(rough);
    (void)t.getVolumeLedger();
    state.ResumeTiming();
    const TerrainAvalancheStats s = t.avalancheAll();
    passes += double(s.passes);
    moves += double(s.moves);
  }
  state.counters["passes"] = benchmark::Counter(passes, benchmark::Counter::kAvgIterations);
  state.counters["moves"] = benchmark::Counter(moves, benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_avalanche_all)->Arg(257)->Arg(513)->ArgName("n")->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
