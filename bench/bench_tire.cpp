// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Cost of the TwoBodyTireModel (issue 6): one step of the four-wheeled vehicle (bench/scenes/vehicle.h)
// driving at 2 m/s over flat ground and a bump, with tire models (rim + tire per wheel) and with rigid wheels
// (tire hinged to the chassis, no rim, no tire model). Same time step (1/400 s) and PGS iterations (20).
//
// Timing: one iteration = one stepForward(); the scene is rebuilt (timer paused) every 4 s of simulated time
// so the timed steps cover the drive over the bump. Counters: ms_per_step (std::chrono over stepForward only),
// rows (solver rows in the last step), and for the tire variant sag_rel_err, the static sag of a settled
// vehicle against (chassis + rims) g / 4k (an accuracy figure for the same scene).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <memory>

#include "scenes/vehicle.h"

namespace {
using namespace scree;
using namespace scree::scenes;

VehicleParams params(bool rigid) {
  VehicleParams p;
  p.speed = 2.0;
  p.bump = true;
  p.rigidWheels = rigid;
  return p;
}

void BM_vehicle(benchmark::State& state) {
  using Clock = std::chrono::steady_clock;
  const bool rigid = state.range(0) != 0;
  const VehicleParams p = params(rigid);
  const int runSteps = int(4.0 / p.dt);
  auto scene = std::make_unique<VehicleScene>(buildVehicle(p));
  int steps = 0;
  double seconds = 0;
  for (auto _ : state) {
    if (steps == runSteps) {
      state.PauseTiming();
      scene = std::make_unique<VehicleScene>(buildVehicle(p));
      steps = 0;
      state.ResumeTiming();
    }
    const auto t0 = Clock::now();
    scene->step();
    seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    ++steps;
  }
  state.counters["ms_per_step"] = benchmark::Counter(seconds * 1e3, benchmark::Counter::kAvgIterations);
  state.counters["rows"] = double(scene->sim->getSolver().getStats().numRows);
  state.counters["finite"] = scenes::allFinite(*scene->sim) ? 1.0 : 0.0;
  if (!rigid) {
    VehicleParams sp;  // parked: motors hold
    VehicleScene parked = buildVehicle(sp);
    for (int i = 0; i < int(2.0 / sp.dt); ++i) parked.step();
    const Real expect = (sp.chassisMass + 4 * sp.rimMass) * SceneConstants::gravity / 4 / 3.5e5;
    Real worst = 0;
    for (const auto& m : parked.tireModels)
      worst = std::max(worst, std::abs(m->getRadialDeflection() - expect) / expect);
    state.counters["sag_rel_err"] = worst;
  }
  state.SetLabel(rigid ? "rigid wheels" : "tire models");
}
BENCHMARK(BM_vehicle)->Arg(0)->Arg(1)->ArgName("rigid")->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
