// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Google Benchmark fixture base for the reference scenes (bench/scenes, docs/scenes.md).
//
// Timing: one benchmark iteration = one Simulation::stepForward(). Every timed step belongs to a run of the
// defined scene: when a run reaches the scene's defined step count the scene is rebuilt from scratch with the
// timer paused. The reported time (real time, ms) is therefore the mean cost of a step over the scene's
// trajectory; `ms_per_step` repeats it from a std::chrono sum over the stepForward() calls alone.
//
// Accuracy: after the timed loop one complete, untimed run of the freshly built scene (its defined number of
// steps) gives the scene's metrics, reported as counters along with `contacts` (contact points in the last
// step of that run), `finite`, and `run_ms_per_step` (the mean step cost over that whole untimed run).
#pragma once

#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <memory>

#include "scenes/scenes.h"

namespace scree::bench {

template <class S>
class SceneFixture : public benchmark::Fixture {
 public:
  void SetUp(const benchmark::State&) override { scene_ = std::make_unique<S>(build()); }
  void TearDown(const benchmark::State&) override { scene_.reset(); }

 protected:
  virtual S build() = 0;
  /// Runs a fresh scene through its defined steps and sets the metric counters.
  virtual void measure(benchmark::State& state, S& fresh) = 0;

  void run(benchmark::State& state) {
    using Clock = std::chrono::steady_clock;
    double stepSeconds = 0;
    int stepsInRun = 0;
    for (auto _ : state) {
      if (stepsInRun == scene_->numSteps) {
        state.PauseTiming();
        scene_.reset();
        scene_ = std::make_unique<S>(build());
        stepsInRun = 0;
        state.ResumeTiming();
      }
      const auto t0 = Clock::now();
      scene_->step();
      stepSeconds += std::chrono::duration<double>(Clock::now() - t0).count();
      ++stepsInRun;
    }
    state.counters["ms_per_step"] = benchmark::Counter(stepSeconds * 1e3, benchmark::Counter::kAvgIterations);
    scene_.reset();

    S fresh = build();
    const auto r0 = Clock::now();
    measure(state, fresh);
    // Mean step cost over the whole defined run (includes the metric evaluation, which is small): for
    // fixtures with few timed iterations (spheres10k_jitter) this covers the full trajectory.
    state.counters["run_ms_per_step"] =
        std::chrono::duration<double>(Clock::now() - r0).count() * 1e3 / double(fresh.numSteps);
    state.counters["contacts"] = double(fresh.numContactPoints());
    state.counters["finite"] = scenes::allFinite(*fresh.sim) ? 1.0 : 0.0;
    state.SetLabel(fresh.name);
  }

  static double flag(bool b) { return b ? 1.0 : 0.0; }

  std::unique_ptr<S> scene_;
};

}  // namespace scree::bench
