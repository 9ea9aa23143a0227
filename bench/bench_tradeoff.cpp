// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The speed-accuracy trade (issue 4): every reference scene of the sweep is run for a fixed simulated time under
// solve type x iterations x time step, recording the median wall time of a step and the error that matters for
// the scene. scripts/speed_accuracy.py runs this with --benchmark_format=json and turns the output into
// docs/speed-accuracy.md (tables, Pareto fronts, recommendation) and one PNG per scene (gnuplot).
//
// Scenes (docs/scenes.md builders) and their error:
//   chain20     released from horizontal, 5 s: largest joint separation over all joints and steps, m
//   tower10     3 s: largest displacement of any box from its start, m (drift)
//   pyramid20   3 s: largest displacement of any box, m
//   mass_ratio  1000 kg on 1 kg, 3 s: worst vertical overlap of the two boxes (penetration), m; squeezed out = 1e3
//   pile1000    1000 spheres (r 0.05, 10 x 10 per layer, 10 layers) dropped into a box, 2 s: largest
//               penetration at the end, m
// Solve types: ITERATIVE (PGS) and, for contact scenes, SPLIT (normals direct, friction PGS) at 5..200
// iterations; DIRECT once (iterations do not matter to it). Joints follow the same type in chain20.
// Counters: ms_per_step (median over the run's steps), ms_per_sim_s (mean step time / dt: the cost of one
// simulated second), error, finite, dt, iterations, type (0 DIRECT, 1 ITERATIVE, 3 SPLIT).
// SCREE_TRADEOFF_TIME_SCALE (default 1) scales every scene's simulated time, e.g. 0.2 for a smoke run.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "scenes/scenes.h"

namespace {
using namespace scree;
using namespace scree::scenes;
using Clock = std::chrono::steady_clock;

struct Run {
  std::vector<double> stepSeconds;
  double error = 0;
  bool finite = true;
};

double timeScale() {
  const char* s = std::getenv("SCREE_TRADEOFF_TIME_SCALE");
  const double v = s ? std::atof(s) : 1.0;
  return v > 0 ? v : 1.0;
}

template <class S>
void configure(S& s, FrictionModel::SolveType type, int iterations, Real dt, Real seconds) {
  s.sim->setTimeStep(dt);
  s.sim->getSolver().setNumIterations(iterations);
  if (s.contactMaterial) s.contactMaterial->setSolveType(type);
  for (const auto& c : s.sim->getConstraints()) c->setSolveType(type);
  s.dt = dt;
  s.numSteps = std::max(1, int(std::lround(seconds * timeScale() / dt)));
}

// Steps s through numSteps, timing each step; `observe` runs untimed after each step.
template <class S>
Run stepAll(S& s, const std::function<void()>& observe) {
  Run r;
  r.stepSeconds.reserve(size_t(s.numSteps));
  for (int i = 0; i < s.numSteps; ++i) {
    const auto t0 = Clock::now();
    s.step();
    r.stepSeconds.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
    if (observe) observe();
  }
  r.finite = allFinite(*s.sim);
  return r;
}

Run runScene(const std::string& scene, FrictionModel::SolveType type, int iterations, Real dt) {
  if (scene == "chain20") {
    Chain20Scene s = buildChain20();
    configure(s, type, iterations, dt, 5.0);
    ChainObserver obs(s);
    Run r = stepAll(s, [&] { obs.observe(); });
    r.error = obs.result().maxSeparation;
    return r;
  }
  if (scene == "tower10") {
    TowerScene s = buildTower10();
    configure(s, type, iterations, dt, 3.0);
    Run r = stepAll(s, {});
    r.error = measureTower(s).maxDisplacement;
    return r;
  }
  if (scene == "pyramid20") {
    PyramidScene s = buildPyramid20();
    configure(s, type, iterations, dt, 3.0);
    Run r = stepAll(s, {});
    r.error = measurePyramid(s).maxDisplacement;
    return r;
  }
  if (scene == "mass_ratio") {
    MassRatioScene s = buildMassRatio();
    configure(s, type, iterations, dt, 3.0);
    MassRatioObserver obs(s);
    Run r = stepAll(s, [&] { obs.observe(); });
    const MassRatioMetrics m = obs.result();
    r.error = m.squeezed ? 1e3 : m.overlapWorst;
    return r;
  }
  // pile1000
  SphereLatticeParams p;
  p.count = 1000;
  p.perRow = 10;
  p.jitter = true;
  SpheresScene s = buildSphereLattice(p);
  configure(s, type, iterations, dt, 2.0);
  Run r = stepAll(s, {});
  r.error = measureSpheres(s).maxPenetration;
  return r;
}

void sweep(benchmark::State& state, std::string scene, FrictionModel::SolveType type, int iterations, Real dt) {
  Run r;
  for (auto _ : state) r = runScene(scene, type, iterations, dt);
  std::vector<double> t = r.stepSeconds;
  double mean = 0;
  for (double x : t) mean += x;
  mean /= double(std::max<size_t>(t.size(), 1));
  std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
  state.counters["ms_per_step"] = t.empty() ? 0 : t[t.size() / 2] * 1e3;
  state.counters["ms_per_sim_s"] = mean * 1e3 / dt;
  state.counters["error"] = std::isfinite(r.error) ? r.error : 1e300;
  state.counters["finite"] = r.finite ? 1 : 0;
  state.counters["dt"] = dt;
  state.counters["iterations"] = iterations;
  state.counters["type"] = int(type);
}

int registerAll() {
  const char* scenes[] = {"chain20", "tower10", "pyramid20", "mass_ratio", "pile1000"};
  const int iterations[] = {5, 10, 20, 50, 100, 200};
  const int rates[] = {30, 60, 120, 240};
  for (const char* scene : scenes) {
    const bool joints = std::string(scene) == "chain20";
    for (int rate : rates) {
      const Real dt = 1.0 / rate;
      auto add = [&](FrictionModel::SolveType type, const char* tname, int it) {
        const std::string name = std::string(scene) + "/" + tname + "/it:" + std::to_string(it) +
                                 "/dt:1_" + std::to_string(rate);
        benchmark::RegisterBenchmark(name.c_str(), sweep, std::string(scene), type, it, dt)
            ->Iterations(1)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
      };
      for (int it : iterations) add(FrictionModel::ITERATIVE, "PGS", it);
      if (!joints)
        for (int it : iterations) add(FrictionModel::SPLIT, "SPLIT", it);
      add(FrictionModel::DIRECT, "DIRECT", 10);
    }
  }
  return 0;
}
const int registered = registerAll();
}  // namespace

BENCHMARK_MAIN();
