// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Cost of the dynamic height field with a deformer (issue 17; terrain.h "Dynamic height field: deformers" and
// "... avalanches and the angle of repose"; the scene: bench/scenes/terrain_dozer.h).
//
// BM_dozer/n/dhf: the dozer scene on an n x n field (0.1 m cells) - a 2 m blade, 10 cm deep, pushing soil at
// 0.5 m/s - with the dynamic height field on (dhf = 1: deformer contacts rebuilt, soil pushed into a berm,
// avalanches) or off (dhf = 0: the same blade path on static heights, the baseline). One iteration = one step
// of the scene (blade reset + stepForward). The scene is rebuilt (timer paused) every 240 steps (2 m pushed:
// the berm grows through the run, so every repetition averages the same mix). Counters, wall-clock per step:
// terrain_ms (the terrain's own stages, Terrain::getLastStepTime: pre-collide, contact listener - where the
// deformer contacts are rebuilt - and post step, where deformation and avalanches run), avalanche_ms (its
// avalanche pass, Terrain::getLastStepAvalancheTime; the deformation itself is not timed apart), step_ms
// (stepForward), armed (armed vertices), pushed (vertices pushed per step), points (contact points: the deformer
// contact adds a vertical and a horizontal point per original point), and the step's stages from
// Simulation::getStepStats: collide_ms (collision and materials), solve_ms (rows and the velocity solve), post_ms
// (POST_STEP listeners). The CPU column is the thread CPU
// time of the whole iteration. The goals: terrain_ms < 1 ms at n = 257 on one core; n = 513 within 1.5x
// of n = 257 (the cost follows the blade's footprint and the armed berm, not the grid).
#include <benchmark/benchmark.h>

#include <chrono>

#include "scenes/terrain_dozer.h"

namespace {
using namespace scree;

constexpr int kStepsPerBuild = 240;

void BM_dozer(benchmark::State& state) {
  using Clock = std::chrono::steady_clock;
  scenes::TerrainDozerParams p;
  p.n = size_t(state.range(0));
  p.dynamicHeightField = state.range(1) != 0;
  p.pushSeconds = kStepsPerBuild * p.dt + 1.0;  // never reaches the rest phase
  scenes::TerrainDozerScene s = scenes::buildTerrainDozer(p);
  double stepSeconds = 0, terrainSeconds = 0, avalancheSeconds = 0, armed = 0, pushed = 0, points = 0;
  double collideSeconds = 0, solveSeconds = 0, postSeconds = 0;
  for (auto _ : state) {
    if (s.stepIndex == kStepsPerBuild) {
      state.PauseTiming();
      s = scenes::buildTerrainDozer(p);
      state.ResumeTiming();
    }
    const auto t0 = Clock::now();
    s.step();
    stepSeconds += std::chrono::duration<double>(Clock::now() - t0).count();
    terrainSeconds += s.terrain->getLastStepTime();
    avalancheSeconds += s.terrain->getLastStepAvalancheTime();
    armed += double(s.terrain->getNumArmedVertices());
    pushed += double(s.terrain->getLastStepDeformStats().verticesPushed);
    points += double(s.numContactPoints());
    const StepStats& st = s.sim->getStepStats();
    collideSeconds += st.collide;
    solveSeconds += st.rows + st.solve;
    postSeconds += st.post;
  }
  using C = benchmark::Counter;
  state.counters["step_ms"] = C(stepSeconds * 1e3, C::kAvgIterations);
  state.counters["terrain_ms"] = C(terrainSeconds * 1e3, C::kAvgIterations);
  state.counters["avalanche_ms"] = C(avalancheSeconds * 1e3, C::kAvgIterations);
  state.counters["armed"] = C(armed, C::kAvgIterations);
  state.counters["pushed"] = C(pushed, C::kAvgIterations);
  state.counters["points"] = C(points, C::kAvgIterations);
  state.counters["collide_ms"] = C(collideSeconds * 1e3, C::kAvgIterations);
  state.counters["solve_ms"] = C(solveSeconds * 1e3, C::kAvgIterations);
  state.counters["post_ms"] = C(postSeconds * 1e3, C::kAvgIterations);
}
BENCHMARK(BM_dozer)
    ->ArgsProduct({{257, 513}, {0, 1}})
    ->ArgNames({"n", "dhf"})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime()
    ->MinTime(2.0);

}  // namespace

BENCHMARK_MAIN();
