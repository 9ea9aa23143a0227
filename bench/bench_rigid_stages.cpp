// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Per-stage step timings (Simulation::getTimings) of the rigid reference scenes pyramid20 and tower10
// (docs/scenes.md), on 1 and 2 threads (issue 18: where a small rigid scene's step goes, and the two-thread
// speed-up of the coloured sweeps, docs/solver-internals.md "Sweep cost" and "Coloured sweeps").
//
// The pyramid20 benchmarks' argument is the thread count (scree::setNumThreads). Issue 18's 2-thread check on an
// idle machine: --benchmark_filter='pyramid20_(partitioned_)?stages|team|omp' (docs/solver-internals.md
// "Partitioned sweeps", second round; BM_team_* and BM_omp_fork_join measure the synchronisation itself).
//
// One benchmark iteration is one complete run of the scene's defined steps (scene built with the timer paused).
// Counters:
//   median_ms   median wall time of one step over the run (ms)
//   cpu_ms      process CPU time per step (all threads), mean over the run (ms)
//   st_<stage>  Simulation::getTimings() per stage, mean over the run (ms); collide = syncGeometries +
//               collideGeometries + resolveMaterials; rows = contactRows + constraintRows
//   drift_cm    pyramid20: largest box displacement at the end (cm); tower10: top box's horizontal offset
//   allocs      heap allocations (global operator new) per step after the first 60 steps (storage has grown by
//               then; issue 18 asks for none in a rigid step)
//   fingerprint low 32 bits of an FNV-1a hash of every body's final position and velocity (the same on 1 and 2
//               threads: the sweeps' results do not depend on the thread count); also in the label, fp=<all digits>
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <new>
#include <string>
#include <thread>
#include <vector>

#include "cpu_time.h"
#include "scree/core/parallel.h"
#include "scenes/scenes.h"

// Counts every heap allocation of the process (this benchmark binary only; the replacement operator new pairs
// with the replacement operator delete below, which GCC cannot see).
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
static std::atomic<long> gAllocations{0};
void* operator new(std::size_t n) {
  gAllocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {
using namespace scree;
using namespace scree::scenes;
using Clock = std::chrono::steady_clock;

using scree::bench::cpuMs;

uint64_t fingerprint(const Simulation& sim) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&](const Vec3& v) {
    const auto* p = reinterpret_cast<const unsigned char*>(v.data());
    for (size_t q = 0; q < sizeof(Real) * 3; ++q) h = (h ^ p[q]) * 1099511628211ull;
  };
  for (const RigidBodyRef& b : sim.getRigidBodies()) {
    mix(b->getPosition());
    mix(b->getVelocity());
  }
  return h;
}

template <class S, class Build, class Drift>
void runStages(benchmark::State& state, Build build, Drift drift, int threadCount = 0) {
  const int threads = threadCount > 0 ? threadCount : int(state.range(0));
  setNumThreads(threads);
  std::vector<double> wall;
  StepTimings sum;
  double cpu = 0, driftCm = 0, sweepThreads = 0, rowThreads = 0;
  long steps = 0, allocSteps = 0, allocs = 0;
  uint64_t fp = 0;
  for (auto _ : state) {
    state.PauseTiming();
    S s = build();
    state.ResumeTiming();
    for (int i = 0; i < s.numSteps; ++i) {
      const long a0 = gAllocations.load(std::memory_order_relaxed);
      const double c0 = cpuMs();
      const auto t0 = Clock::now();
      s.step();
      wall.push_back(std::chrono::duration<double>(Clock::now() - t0).count() * 1e3);
      cpu += cpuMs() - c0;
      if (i >= 60) {
        allocs += gAllocations.load(std::memory_order_relaxed) - a0;
        ++allocSteps;
      }
      sum += s.sim->getTimings();
      sweepThreads += s.sim->getSolver().getStats().numSweepThreads;
      rowThreads += s.sim->getSolver().getStats().numRowBuildThreads;
      ++steps;
    }
    driftCm = drift(s) * 100;
    fp = fingerprint(*s.sim);
  }
  setNumThreads(1);
  std::nth_element(wall.begin(), wall.begin() + long(wall.size() / 2), wall.end());
  const double n = double(std::max(1L, steps));
  state.counters["median_ms"] = wall[wall.size() / 2];
  state.counters["cpu_ms"] = cpu / n;
  state.counters["st_collide"] = (sum.syncGeometries + sum.collideGeometries + sum.resolveMaterials) / n;
  state.counters["st_rows"] = (sum.contactRows + sum.constraintRows) / n;
  state.counters["st_solve"] = sum.solve / n;
  state.counters["st_integrate"] = sum.integrateMotion / n;
  state.counters["st_store"] = sum.storeResults / n;
  state.counters["st_other"] = (sum.total - sum.syncGeometries - sum.collideGeometries - sum.resolveMaterials -
                                sum.contactRows - sum.constraintRows - sum.solve - sum.integrateMotion -
                                sum.storeResults) / n;
  state.counters["st_total"] = sum.total / n;
  state.counters["drift_cm"] = driftCm;
  state.counters["allocs"] = double(allocs) / double(std::max(1L, allocSteps));
  state.counters["fingerprint"] = double(fp & 0xffffffffu);
  // The console prints counters with 5 significant digits; the label carries every digit, so that bit claims can
  // be read from the console as well as from the JSON output.
  state.SetLabel("fp=" + std::to_string(fp & 0xffffffffu));
  // The mean thread counts of the sweeps and of the contact row build over the steps (SolverStats): with the
  // adaptive count, the share of steps that ran on two threads is (count - 1).
  state.counters["sweep_threads"] = sweepThreads / n;
  state.counters["row_threads"] = rowThreads / n;
}

/// runStages on one thread, for benchmarks whose argument is not the thread count.
template <class S, class Build, class Drift>
void runStagesOneThread(benchmark::State& state, Build build, Drift drift) {
  runStages<S>(state, build, drift, 1);
}

void BM_pyramid20_stages(benchmark::State& state) {
  runStages<PyramidScene>(state, [] { return buildPyramid20(); },
                          [](const PyramidScene& s) { return measurePyramid(s).maxDisplacement; });
}
BENCHMARK(BM_pyramid20_stages)->Arg(1)->Arg(2)->Iterations(1)->Repetitions(3)->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The same with graph-coloured sweeps (Solver::setUseColouredSweeps): the 1- and 2-thread fingerprints agree.
void BM_pyramid20_coloured_stages(benchmark::State& state) {
  runStages<PyramidScene>(state,
                          [] {
                            PyramidScene s = buildPyramid20();
                            s.sim->getSolver().setUseColouredSweeps(true);
                            return s;
                          },
                          [](const PyramidScene& s) { return measurePyramid(s).maxDisplacement; });
}
BENCHMARK(BM_pyramid20_coloured_stages)->Arg(1)->Arg(2)->Iterations(1)->Repetitions(3)
    ->Unit(benchmark::kMillisecond)->UseRealTime();

// Issue 18 (sweep scheduling): partitioned sweeps and the parallel shock pass (Solver::setUsePartitionedSweeps);
// the 1- and 2-thread fingerprints agree.
void BM_pyramid20_partitioned_stages(benchmark::State& state) {
  runStages<PyramidScene>(state,
                          [] {
                            PyramidScene s = buildPyramid20();
                            s.sim->getSolver().setUsePartitionedSweeps(true);
                            return s;
                          },
                          [](const PyramidScene& s) { return measurePyramid(s).maxDisplacement; });
}
BENCHMARK(BM_pyramid20_partitioned_stages)->Arg(1)->Arg(2)->Iterations(1)->Repetitions(3)
    ->Unit(benchmark::kMillisecond)->UseRealTime();

// The same with the thread count fixed (Solver::setUseAdaptiveSweepThreads(false)): what two threads cost on this
// host, which the default (by measurement, solver/src/sweep_threads.h) avoids when it is more than one thread's.
void BM_pyramid20_partitioned_fixed_stages(benchmark::State& state) {
  runStages<PyramidScene>(state,
                          [] {
                            PyramidScene s = buildPyramid20();
                            s.sim->getSolver().setUsePartitionedSweeps(true);
                            s.sim->getSolver().setUseAdaptiveSweepThreads(false);
                            return s;
                          },
                          [](const PyramidScene& s) { return measurePyramid(s).maxDisplacement; });
}
BENCHMARK(BM_pyramid20_partitioned_fixed_stages)->Arg(2)->Iterations(1)->Repetitions(3)
    ->Unit(benchmark::kMillisecond)->UseRealTime();

// How the partitioned step's two-thread gain grows with the scene: pyramids of 20, 30 and 40 rows (210, 465 and
// 820 boxes), Args = (rows, threads), the thread count fixed. The parallel part (region sweeps, shock pass) grows
// with the contacts like the serial part (row build, prepare, records, store), so this measures how much of the
// serial part's cost is per step rather than per contact (docs/solver-internals.md "The team's waits spin by
// time").
void BM_pyramid_partitioned_scaling(benchmark::State& state) {
  const int rows = int(state.range(0));
  runStages<PyramidScene>(
      state,
      [rows] {
        PyramidScene s = buildPyramid(rows);
        s.sim->getSolver().setUsePartitionedSweeps(true);
        s.sim->getSolver().setUseAdaptiveSweepThreads(false);
        return s;
      },
      [](const PyramidScene& s) { return measurePyramid(s).maxDisplacement; }, int(state.range(1)));
}
BENCHMARK(BM_pyramid_partitioned_scaling)
    ->Args({20, 1})->Args({20, 2})->Args({30, 1})->Args({30, 2})->Args({40, 1})->Args({40, 2})
    ->Iterations(1)->Repetitions(3)->Unit(benchmark::kMillisecond)->UseRealTime();

// The ceiling of a two-thread step on this host: two independent pyramids of `rows` rows, each in its own
// Simulation (one thread each, default settings), Args = (rows, threads). On one thread the program thread steps
// both; on two, a second std::thread steps the second pyramid at the same time, with one spin handshake per step.
// Nothing is shared between the two, so this is what a step whose every stage kept its region's data on its own
// thread (no boundary, no barrier) could gain at most. rows 14 gives 2 x 105 boxes, pyramid20's 210; 21 and 28
// match pyramid30 and pyramid40 (2 x 231, 2 x 406). median_ms is the wall time of one step of both pyramids
// (docs/solver-internals.md "The ceiling of two threads"). A third argument of 1 makes the two threads swap
// pyramids every step (the program thread steps pyramid a on even steps and b on odd ones): the same work with
// every pyramid's data moving between the cores each step, which is what a stage moved alone to the second thread
// pays.
void BM_independent_pyramids(benchmark::State& state) {
  const int rows = int(state.range(0));
  const bool two = state.range(1) == 2;
  const bool swap = state.range(2) == 1;
  setNumThreads(1);
  std::vector<double> wall;
  double driftCm = 0;
  for (auto _ : state) {
    state.PauseTiming();
    PyramidScene a = buildPyramid(rows), b = buildPyramid(rows);
    std::atomic<int> go{0}, done{0};
    std::thread worker;
    if (two)
      worker = std::thread([&] {
        for (int i = 1; i <= b.numSteps; ++i) {
          while (go.load(std::memory_order_acquire) < i) {
          }
          (swap && i % 2 == 0 ? a : b).step();
          done.store(i, std::memory_order_release);
        }
      });
    state.ResumeTiming();
    for (int i = 1; i <= a.numSteps; ++i) {
      const auto t0 = Clock::now();
      if (two) go.store(i, std::memory_order_release);
      (two && swap && i % 2 == 0 ? b : a).step();
      if (two) {
        while (done.load(std::memory_order_acquire) < i) {
        }
      } else {
        b.step();
      }
      wall.push_back(std::chrono::duration<double>(Clock::now() - t0).count() * 1e3);
    }
    state.PauseTiming();
    if (worker.joinable()) worker.join();
    driftCm = std::max(measurePyramid(a).maxDisplacement, measurePyramid(b).maxDisplacement) * 100;
    state.ResumeTiming();
  }
  std::nth_element(wall.begin(), wall.begin() + long(wall.size() / 2), wall.end());
  state.counters["median_ms"] = wall[wall.size() / 2];
  state.counters["drift_cm"] = driftCm;
}
BENCHMARK(BM_independent_pyramids)
    ->Args({14, 1, 0})->Args({14, 2, 0})->Args({14, 2, 1})->Args({21, 1, 0})->Args({21, 2, 0})->Args({21, 2, 1})
    ->Args({28, 1, 0})->Args({28, 2, 0})->Args({28, 2, 1})
    ->Iterations(1)->Repetitions(3)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_tower10_stages(benchmark::State& state) {
  runStages<TowerScene>(state, [] { return buildTower10(); },
                        [](const TowerScene& s) { return measureTower(s).topHorizontal; });
}
BENCHMARK(BM_tower10_stages)->Arg(1)->Arg(2)->Iterations(5)->Repetitions(3)->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// ---- issue 18 (friction anchors, Solver::setUseFrictionAnchors; docs/solver-internals.md "Friction anchors") ----
// pyramid20 with anchors, with the shock pass (Arg 1) and without it (Arg 0), one thread; compare with
// BM_pyramid20_stages/1 and BM_pyramid20_noshock_stages.
PyramidScene buildPyramid20With(bool anchors, bool shock) {
  PyramidScene s = buildPyramid20();
  s.sim->getSolver().setUseFrictionAnchors(anchors);
  s.sim->getSolver().setUseShockPropagation(shock);
  return s;
}
void BM_pyramid20_anchor_stages(benchmark::State& state) {
  const bool shock = state.range(0) != 0;
  runStagesOneThread<PyramidScene>(state, [shock] { return buildPyramid20With(true, shock); },
                                   [](const PyramidScene& s) { return measurePyramid(s).maxDisplacement; });
}
BENCHMARK(BM_pyramid20_anchor_stages)->Arg(1)->Arg(0)->Iterations(1)->Repetitions(3)
    ->Unit(benchmark::kMillisecond)->UseRealTime();
void BM_pyramid20_noshock_stages(benchmark::State& state) {
  runStagesOneThread<PyramidScene>(state, [] { return buildPyramid20With(false, false); },
                                   [](const PyramidScene& s) { return measurePyramid(s).maxDisplacement; });
}
BENCHMARK(BM_pyramid20_noshock_stages)->Iterations(1)->Repetitions(3)->Unit(benchmark::kMillisecond)
    ->UseRealTime();
// ---- issue 18 (coarse correction, Solver::setUseCoarseCorrection; docs/solver-internals.md "Coarse
// correction"): pyramid20 without the shock pass, anchors on, with the correction after the 2nd and 4th sweep.
// Compare with BM_pyramid20_anchor_stages/0 (the same without it) and BM_pyramid20_stages/1 (the default).
void BM_pyramid20_coarse_stages(benchmark::State& state) {
  runStagesOneThread<PyramidScene>(
      state,
      [] {
        PyramidScene s = buildPyramid20With(true, false);
        s.sim->getSolver().setUseCoarseCorrection(true);
        return s;
      },
      [](const PyramidScene& s) { return measurePyramid(s).maxDisplacement; });
}
BENCHMARK(BM_pyramid20_coarse_stages)->Iterations(1)->Repetitions(3)->Unit(benchmark::kMillisecond)
    ->UseRealTime();
// The same with the partitioned sweeps, Arg = threads (fixed): the correction is serial between the sweep calls,
// and the 1- and 2-thread fingerprints agree.
void BM_pyramid20_coarse_partitioned_stages(benchmark::State& state) {
  runStages<PyramidScene>(
      state,
      [] {
        PyramidScene s = buildPyramid20With(true, false);
        s.sim->getSolver().setUseCoarseCorrection(true);
        s.sim->getSolver().setUsePartitionedSweeps(true);
        s.sim->getSolver().setUseAdaptiveSweepThreads(false);
        return s;
      },
      [](const PyramidScene& s) { return measurePyramid(s).maxDisplacement; });
}
BENCHMARK(BM_pyramid20_coarse_partitioned_stages)->Arg(1)->Arg(2)->Iterations(1)->Repetitions(3)
    ->Unit(benchmark::kMillisecond)->UseRealTime();

// ---- issue 18 (sweep scheduling): the persistent team's costs (scree/core/parallel.h; docs/solver-internals.md
// "Persistent team"). Arg = threads. BM_team_fork_join: one runTeam with an empty job (what a partitioned stage
// pays to start and join); BM_omp_fork_join: the same with an empty `#pragma omp parallel` (what it paid before);
// BM_team_barrier: one TeamBarrier::wait of every thread (what a partitioned sweep pays), 1000 per iteration,
// time per barrier. On a loaded machine these measure the load (a descheduled partner costs a time slice).
void BM_team_fork_join(benchmark::State& state) {
  const int n = int(state.range(0));
  int sink = 0;
  for (auto _ : state) {
    detail::runTeam(n, [&](int t, int) {
      if (t == 0) ++sink;
    });
  }
  benchmark::DoNotOptimize(sink);
}
BENCHMARK(BM_team_fork_join)->Arg(1)->Arg(2)->Repetitions(3)->Unit(benchmark::kMicrosecond)->UseRealTime();

#ifdef SCREE_WITH_OPENMP
void BM_omp_fork_join(benchmark::State& state) {
  const int n = int(state.range(0));
  int sink = 0;
  for (auto _ : state) {
#pragma omp parallel num_threads(n)
    {
#pragma omp master
      ++sink;
    }
  }
  benchmark::DoNotOptimize(sink);
}
BENCHMARK(BM_omp_fork_join)->Arg(1)->Arg(2)->Repetitions(3)->Unit(benchmark::kMicrosecond)->UseRealTime();
#endif

void BM_team_barrier(benchmark::State& state) {
  const int n = int(state.range(0));
  constexpr int kBarriers = 1000;
  for (auto _ : state) {
    detail::TeamBarrier barrier(n);
    detail::runTeam(n, [&](int, int nt) {
      if (nt > 1)
        for (int k = 0; k < kBarriers; ++k) barrier.wait();
    });
  }
  state.counters["s_per_barrier"] =
      benchmark::Counter(double(state.iterations()) * kBarriers, benchmark::Counter::kIsRate |
                                                                     benchmark::Counter::kInvert);
}
BENCHMARK(BM_team_barrier)->Arg(2)->Repetitions(3)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
