// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The two overhead fixtures, shared by bench_overhead (run in CI) and bench_scenes.
#pragma once

#include "scene_fixture.h"

namespace scree::bench {

class OverheadEmpty : public SceneFixture<scenes::OverheadScene> {
 protected:
  scenes::OverheadScene build() override { return scenes::buildOverheadEmpty(); }
  void measure(benchmark::State& state, scenes::OverheadScene& s) override {
    (void)state;
    scenes::runOverhead(s);  // nothing to measure beyond `finite` and `contacts`
  }
};

class OverheadOneBox : public SceneFixture<scenes::OverheadScene> {
 protected:
  scenes::OverheadScene build() override { return scenes::buildOverheadOneBox(); }
  void measure(benchmark::State& state, scenes::OverheadScene& s) override {
    const scenes::OverheadMetrics m = scenes::runOverhead(s);
    state.counters["box_dz_mm"] = m.boxDz * 1e3;  // resting box sinks by ~compliance only
  }
};

BENCHMARK_DEFINE_F(OverheadEmpty, overhead_empty)(benchmark::State& state) { run(state); }
BENCHMARK_REGISTER_F(OverheadEmpty, overhead_empty)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_DEFINE_F(OverheadOneBox, overhead_one_box)(benchmark::State& state) { run(state); }
BENCHMARK_REGISTER_F(OverheadOneBox, overhead_one_box)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace scree::bench
