// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// One fixture per reference scene of docs/scenes.md. See scene_fixture.h for the timing pattern (one iteration =
// one step, scenes rebuilt untimed at the end of each defined run) and the metric counters (one untimed
// complete run after the timed loop).
#include <cmath>

#include "overhead_fixtures.h"
#include "scene_fixture.h"

namespace scree::bench {
using namespace scree::scenes;

// ---- pyramid20 ----------------------------------------------------------------------------------------------
class Pyramid20 : public SceneFixture<PyramidScene> {
 protected:
  PyramidScene build() override { return buildPyramid20(); }
  void measure(benchmark::State& state, PyramidScene& s) override {
    const PyramidMetrics m = runPyramid(s);
    state.counters["drift_cm"] = m.maxDisplacement * 100;  // largest displacement of any box
    state.counters["top_dz_cm"] = m.topDz * 100;
    state.counters["stands"] = flag(m.stands);
  }
};
BENCHMARK_DEFINE_F(Pyramid20, pyramid20)(benchmark::State& state) { run(state); }
BENCHMARK_REGISTER_F(Pyramid20, pyramid20)->Unit(benchmark::kMillisecond)->UseRealTime();

// ---- tower10 ------------------------------------------------------------------------------------------------
class Tower10 : public SceneFixture<TowerScene> {
 protected:
  TowerScene build() override { return buildTower10(); }
  void measure(benchmark::State& state, TowerScene& s) override {
    const TowerMetrics m = runTower(s);
    state.counters["top_dxy_cm"] = m.topHorizontal * 100;
    state.counters["top_dz_cm"] = m.topVertical * 100;
    state.counters["drift_cm"] = m.maxDisplacement * 100;
  }
};
BENCHMARK_DEFINE_F(Tower10, tower10)(benchmark::State& state) { run(state); }
BENCHMARK_REGISTER_F(Tower10, tower10)->Unit(benchmark::kMillisecond)->UseRealTime();

// ---- mass_ratio ---------------------------------------------------------------------------------------------
class MassRatio : public SceneFixture<MassRatioScene> {
 protected:
  MassRatioScene build() override { return buildMassRatio(); }
  void measure(benchmark::State& state, MassRatioScene& s) override {
    const MassRatioMetrics m = runMassRatio(s);
    state.counters["heavy_err_mm"] = m.heavyError * 1e3;
    state.counters["heavy_err_worst_mm"] = m.heavyErrorWorst * 1e3;
    state.counters["overlap_mm"] = m.overlap * 1e3;  // NaN once squeezed out
    state.counters["overlap_worst_mm"] = m.overlapWorst * 1e3;
    state.counters["squeezed"] = flag(m.squeezed);
  }
};
BENCHMARK_DEFINE_F(MassRatio, mass_ratio)(benchmark::State& state) { run(state); }
BENCHMARK_REGISTER_F(MassRatio, mass_ratio)->Unit(benchmark::kMillisecond)->UseRealTime();

// ---- chain20 ------------------------------------------------------------------------------------------------
class Chain20 : public SceneFixture<Chain20Scene> {
 protected:
  Chain20Scene build() override { return buildChain20(); }
  void measure(benchmark::State& state, Chain20Scene& s) override {
    const ChainMetrics m = runChain20(s);
    state.counters["sep_max_m"] = m.maxSeparation;
    state.counters["sep_mean_m"] = m.meanSeparation;
    state.counters["sep_final_m"] = m.finalSeparation;
    state.counters["t_above_10cm_s"] = m.firstAbove10cm;
  }
};
BENCHMARK_DEFINE_F(Chain20, chain20)(benchmark::State& state) { run(state); }
BENCHMARK_REGISTER_F(Chain20, chain20)->Unit(benchmark::kMillisecond)->UseRealTime();

// ---- slide --------------------------------------------------------------------------------------------------
class Slide : public SceneFixture<SlideScene> {
 protected:
  SlideScene build() override { return buildSlide(); }
  void measure(benchmark::State& state, SlideScene& s) override {
    const SlideMetrics m = runSlide(s);
    state.counters["dist_m"] = m.distance;
    state.counters["dist_err_pct"] = m.distanceErr * 100;  // vs 4.2474 m
    state.counters["stop_s"] = m.stopTime;
    state.counters["time_err_pct"] = m.timeErr * 100;      // vs 1.699 s
  }
};
BENCHMARK_DEFINE_F(Slide, slide)(benchmark::State& state) { run(state); }
BENCHMARK_REGISTER_F(Slide, slide)->Unit(benchmark::kMillisecond)->UseRealTime();

// ---- incline ------------------------------------------------------------------------------------------------
template <int MuTenths>
class Incline : public SceneFixture<InclineScene> {
 protected:
  InclineScene build() override { return buildIncline(MuTenths / 10.0); }
  void measure(benchmark::State& state, InclineScene& s) override {
    const InclineMetrics m = runIncline(s);
    state.counters["disp_m"] = m.displacement;
    if (m.analytic > 0)
      state.counters["disp_err_pct"] = m.error * 100;  // vs 1.3143 m
    else
      state.counters["disp_mm"] = m.displacement * 1e3;  // analytic 0 (sticks)
  }
};
using InclineMu05 = Incline<5>;
using InclineMu06 = Incline<6>;
BENCHMARK_DEFINE_F(InclineMu05, incline_mu05)(benchmark::State& state) { run(state); }
BENCHMARK_REGISTER_F(InclineMu05, incline_mu05)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_DEFINE_F(InclineMu06, incline_mu06)(benchmark::State& state) { run(state); }
BENCHMARK_REGISTER_F(InclineMu06, incline_mu06)->Unit(benchmark::kMillisecond)->UseRealTime();

// ---- spheres10k_jitter --------------------------------------------------------------------------------------
class Spheres10kJitter : public SceneFixture<SpheresScene> {
 protected:
  SpheresScene build() override { return buildSpheres10kJitter(); }
  void measure(benchmark::State& state, SpheresScene& s) override {
    const SpheresMetrics m = runSpheres(s);
    state.counters["ke_J"] = m.kineticEnergy;
    state.counters["max_pen_cm"] = m.maxPenetration * 100;
    state.counters["mean_h_m"] = m.meanHeight;
    state.counters["max_h_m"] = m.maxHeight;
    state.counters["escaped"] = double(m.escaped);
  }
};
// 20 timed steps (of the first run's 300) keep a default run to minutes; the metric run adds 300 steps.
BENCHMARK_DEFINE_F(Spheres10kJitter, spheres10k_jitter)(benchmark::State& state) { run(state); }
BENCHMARK_REGISTER_F(Spheres10kJitter, spheres10k_jitter)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(20);

}  // namespace scree::bench

BENCHMARK_MAIN();
