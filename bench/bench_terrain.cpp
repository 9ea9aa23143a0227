// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Cost of the Terrain (issue 15): the four-wheeled vehicle on TwoBodyTireModel tires (bench/scenes/vehicle.h)
// driving at 2 m/s over a 257 x 257 field (0.1 m cells), once on a deformable Terrain and once on a plain
// HeightField with the same heights, materials and contact stiffness; and idle: the vehicle on its plane while a
// 257 x 257 terrain (or plain field) lies untouched 100 m away. Time step 1/400 s, 20 PGS iterations (vehicle.h).
//
// Timing: one iteration = one stepForward(); the scene is rebuilt (timer paused) every 4 s of simulated time, so
// the timed steps cover the drive from the start (4 wheels on the ground throughout). Counters: ms_per_step
// (std::chrono over stepForward only), terrain_ms (the terrain's own listeners per step, Terrain::
// getLastStepTime), loaded (vertices loaded per step), rut_mm (the deepest vertex at the end, mm).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <memory>

#include "scenes/terrain_vehicle.h"

namespace {
using namespace scree;
using namespace scree::scenes;

void BM_terrain_vehicle(benchmark::State& state) {
  using Clock = std::chrono::steady_clock;
  TerrainVehicleParams p;
  p.vehicle.speed = 2.0;
  p.terrain = state.range(0) != 0;
  p.untouched = state.range(1) != 0;
  const int runSteps = int(4.0 / p.vehicle.dt);
  auto scene = std::make_unique<TerrainVehicleScene>(buildTerrainVehicle(p));
  int steps = 0;
  double seconds = 0, terrainSeconds = 0, loaded = 0;
  for (auto _ : state) {
    if (steps == runSteps) {
      state.PauseTiming();
      scene = std::make_unique<TerrainVehicleScene>(buildTerrainVehicle(p));
      steps = 0;
      state.ResumeTiming();
    }
    const auto t0 = Clock::now();
    scene->step();
    seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    if (scene->terrain) {
      terrainSeconds += scene->terrain->getLastStepTime();
      loaded += double(scene->terrain->getNumLoadedVertices());
    }
    ++steps;
  }
  state.counters["ms_per_step"] = benchmark::Counter(seconds * 1e3, benchmark::Counter::kAvgIterations);
  state.counters["terrain_ms"] = benchmark::Counter(terrainSeconds * 1e3, benchmark::Counter::kAvgIterations);
  state.counters["loaded"] = benchmark::Counter(loaded, benchmark::Counter::kAvgIterations);
  const auto& h = std::static_pointer_cast<HeightField>(scene->field->getShape())->getHeights();
  state.counters["rut_mm"] = 1e3 * (p.thickness - *std::min_element(h.begin(), h.end()));
  state.counters["finite"] = scenes::allFinite(*scene->vehicle.sim) ? 1.0 : 0.0;
  state.SetLabel(std::string(p.terrain ? "terrain" : "plain height field") + (p.untouched ? ", untouched" : ", driving"));
}
BENCHMARK(BM_terrain_vehicle)
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({0, 1})
    ->Args({1, 1})
    ->ArgNames({"terrain", "untouched"})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
