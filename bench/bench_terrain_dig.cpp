// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Cost of digging (issue 16): the trench scene of bench/scenes/terrain_dig.h (kinematic 0.6 m wide bucket digs an
// 8 cm deep, 0.7 m long trench in 0.05 m cells, 15 mm particles, 6,700 live at the peak; lifts, dumps, 4 s of
// settling) at h = 1/60 s, 10 iterations, on 1 and 2 threads, and on 1 thread with the bucket of registered
// steel (steel = 1: SPLIT particle-bucket contacts, the manual's recommended set-up). Figures and where the time goes: docs/terrain.md,
// "Digging cost". Goal (issue 16): >= 60 steps/s (<= 16.7 ms/step) with >= 5,000 live
// particles on one core.
//
// One benchmark iteration is the whole scene (Iterations(1)); each step is timed with std::chrono around
// stepForward. Counters (ms are medians over the steps named):
//   ms_all        every step of the run
//   ms_dig        the steps of the lower and dig phases
//   ms_5k         the steps that start with >= 5,000 live particles; n_5k how many there were
//   cpu_5k        as ms_5k in process CPU time (all threads; on one thread: the time the step really ran,
//                 robust to other processes on the shared machine; on two threads the sum of both)
//   goal_ratio    ms_5k / 16.7 (below 1: the goal is met)
//   live_max      most live particles in any step; created, merged: the totals over the run
//   contacts_5k   particle contact points (units) per step, mean over the >= 5,000 steps
//   terrain_ms    the terrain's own work (Terrain::getLastStepTime: its contact, pre-collide and post-step
//                 listeners), median over the >= 5,000 steps
//   st_<stage>    Simulation::getTimings() per stage, mean over the >= 5,000 steps (ms); the stages add up to
//                 the step
//   drift         |ledger total - start| / start at the end (the soil is conserved)
// On a shared machine run the 2-thread case with OMP_WAIT_POLICY=passive (docs/terrain.md, "Digging cost": with
// the default spinning, each barrier waits for a parked thread and 2 threads take twice one thread's time).
// With the environment variable SCREE_DIG_HASH set, each run also prints to stderr a fingerprint (FNV-1a over
// the particles' positions and velocities every 10 steps) and the created / merged totals: two builds whose
// fingerprints match computed the same trench bit for bit (how the optimisations of docs/terrain.md, "Digging
// cost", were checked). Hashing costs time: leave it unset for timings.
// SCREE_DIG_SWEEP=scalar | avx2 picks the particle sweep's kernel (default: the widest the CPU has, AVX-512
// where present); the results are the same bit for bit, only the time differs (a kernel's gain depends on the
// CPU: docs/terrain.md, "Digging cost").
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "cpu_time.h"
#include "granular_stage.h"
#include "scenes/terrain_dig.h"

namespace {
using namespace scree;
using namespace scree::scenes;
using Clock = std::chrono::steady_clock;

using scree::bench::cpuMs;

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

void BM_terrain_dig(benchmark::State& state) {
  const int threads = int(state.range(0));
  setNumThreads(threads);
  if (const char* k = std::getenv("SCREE_DIG_SWEEP")) {
    const std::string kernel(k);
    scree::detail::GranularStage::setVectorSweepEnabled(kernel != "scalar");
    scree::detail::GranularStage::setAvx512SweepEnabled(kernel != "scalar" && kernel != "avx2");
  }
  for (auto _ : state) {
    state.PauseTiming();
    TerrainDigParams params;
    params.steelBucket = state.range(1) != 0;
    TerrainDigScene s = buildTerrainDig(params);
    const Real total0 = s.terrain->getVolumeLedger().total();
    state.ResumeTiming();
    std::vector<double> all, dig, big, bigCpu, terrainBig;
    StepTimings sum;
    size_t liveMax = 0, created = 0, merged = 0;
    double contacts = 0;
    const int n = s.totalSteps();
    const bool hashOn = std::getenv("SCREE_DIG_HASH") != nullptr;  // fingerprint (see the file comment)
    uint64_t hsh = 1469598103934665603ull;
    for (int i = 0; i < n; ++i) {
      const size_t live = s.sim->getGranularBodySystem().numParticles();
      const size_t phase = s.currentPhase();
      const auto t0 = Clock::now();
      const double c0 = cpuMs();
      s.step();
      const double cpu = cpuMs() - c0;
      const double ms = std::chrono::duration<double>(Clock::now() - t0).count() * 1e3;
      all.push_back(ms);
      if (hashOn && i % 10 == 0) {
        const auto& ps = s.sim->getGranularBodySystem();
        auto mix = [&](const void* p, size_t nbytes) {
          for (size_t q = 0; q < nbytes; ++q) hsh = (hsh ^ static_cast<const unsigned char*>(p)[q]) * 1099511628211ull;
        };
        mix(ps.positions().data(), ps.positions().size() * sizeof(Vec3));
        mix(ps.velocities().data(), ps.velocities().size() * sizeof(Vec3));
      }
      if (phase <= 1) dig.push_back(ms);
      liveMax = std::max(liveMax, s.sim->getGranularBodySystem().numParticles());
      created += s.terrain->getLastStepDigStats().particlesCreated;
      merged += s.terrain->getLastStepDigStats().particlesMerged;
      if (live >= 5000) {
        big.push_back(ms);
        bigCpu.push_back(cpu);
        terrainBig.push_back(s.terrain->getLastStepTime() * 1e3);
        contacts += double(s.sim->getStepStats().numParticleContacts);
        const StepTimings t = s.sim->getTimings();
        sum.preCollide += t.preCollide;
        sum.collideGeometries += t.collideGeometries + t.syncGeometries + t.resolveMaterials;
        sum.collideParticles += t.collideParticles;
        sum.contactEvents += t.contactEvents;
        sum.particleRows += t.particleRows + t.contactRows + t.constraintRows + t.applyForces;
        sum.solve += t.solve;
        sum.integrateMotion += t.integrateMotion + t.storeResults + t.projectPositions + t.checkFinite;
        sum.post += t.post + t.pre;
        sum.compactParticles += t.compactParticles;
      }
    }
    state.PauseTiming();
    if (hashOn) std::fprintf(stderr, "HASH threads=%d created=%zu merged=%zu hash=%016llx\n", threads, created, merged, (unsigned long long)hsh);
    const double nb = std::max<double>(1, double(big.size()));
    state.counters["ms_all"] = median(all);
    state.counters["ms_dig"] = median(dig);
    state.counters["ms_5k"] = median(big);
    state.counters["cpu_5k"] = median(bigCpu);
    state.counters["n_5k"] = double(big.size());
    state.counters["goal_ratio"] = median(big) / (1000.0 / 60);
    state.counters["live_max"] = double(liveMax);
    state.counters["contacts_5k"] = contacts / nb;
    state.counters["created"] = double(created);
    state.counters["merged"] = double(merged);
    state.counters["terrain_ms"] = median(terrainBig);
    state.counters["st_preCollide"] = sum.preCollide / nb;
    state.counters["st_collideGeom"] = sum.collideGeometries / nb;
    state.counters["st_collidePart"] = sum.collideParticles / nb;
    state.counters["st_events"] = sum.contactEvents / nb;
    state.counters["st_rows"] = sum.particleRows / nb;
    state.counters["st_solve"] = sum.solve / nb;
    state.counters["st_integrate"] = sum.integrateMotion / nb;
    state.counters["st_pre_post"] = sum.post / nb;
    state.counters["st_compact"] = sum.compactParticles / nb;
    state.counters["drift"] = std::abs(s.terrain->getVolumeLedger().total() - total0) / total0;
    state.ResumeTiming();
  }
  state.counters["threads"] = threads;
  setNumThreads(0);
}
// steel = 1: the bucket is steel registered as an external material (SPLIT particle-bucket contacts).
BENCHMARK(BM_terrain_dig)->Args({1, 0})->Args({2, 0})->Args({1, 1})->ArgNames({"threads", "steel"})->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
