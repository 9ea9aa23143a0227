// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// GranularFieldPostProcessor throughput: N particles (uniform random in a 1 m cube, radii 4–7 mm) into a 64^3
// voxel grid (voxel 15.6 mm >= the largest diameter). Args: {particles, threads, all}: all = 0 computes the
// manual's fields (mass, momentum, velocity), all = 1 adds solid volume fraction and kinetic stress. Counters: particles per second and the relative mass
// conservation error (mass field sum vs the particles' mass; all particles are inside the cube).
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <random>

#ifdef SCREE_WITH_OPENMP
#include <omp.h>
#endif

#include "scree/core/granular_body_system.h"
#include "scree/core/material.h"
#include "scree/model/granular_field_post_processor.h"

using namespace scree;

namespace {

void fillCloud(GranularBodySystem& gbs, int n) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<Real> u(-0.49, 0.49), rad(0.004, 0.007), vu(-1, 1);
  for (int i = 0; i < n; ++i) gbs.createParticle(Vec3(u(rng), u(rng), u(rng)), rad(rng), Vec3(vu(rng), vu(rng), vu(rng)));
}

void BM_Fields64(benchmark::State& state) {
  const int n = int(state.range(0));
  const int threads = int(state.range(1));
#ifdef SCREE_WITH_OPENMP
  const int before = omp_get_max_threads();
  omp_set_num_threads(threads);
#else
  if (threads > 1) {
    state.SkipWithError("built without OpenMP");
    return;
  }
#endif
  GranularBodySystem gbs;
  auto sand = std::make_shared<Material>("sand");
  sand->setDensity(2500);
  gbs.setMaterial(sand);
  fillCloud(gbs, n);
  GranularFieldPostProcessor gpp(gbs, {64, 64, 64}, Vec3(1, 1, 1));
  gpp.addField(GranularField::VELOCITY);  // + mass, momentum
  if (state.range(2) != 0) {
    gpp.addField(GranularField::KINETIC_STRESS);
    gpp.addField(GranularField::SOLID_VOLUME_FRACTION);
  }
  for (auto _ : state) {
    gpp.calculateFields();
    benchmark::DoNotOptimize(gpp.getField(GranularField::MASS)->getFieldData());
  }
  Real total = 0;
  const auto mass = gpp.getField(GranularField::MASS);
  for (size_t v = 0; v < mass->getDataSize(); ++v) total += mass->getFieldData()[v];
  state.counters["particles_per_s"] = benchmark::Counter(Real(n) * Real(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["mass_rel_err"] = std::abs(total - gbs.getTotalMass()) / gbs.getTotalMass();
#ifdef SCREE_WITH_OPENMP
  omp_set_num_threads(before);
#endif
}

}  // namespace

BENCHMARK(BM_Fields64)
    ->ArgNames({"particles", "threads", "all"})
    ->Args({25000, 1, 0})
    ->Args({50000, 1, 0})
    ->Args({100000, 1, 0})
    ->Args({200000, 1, 0})
    ->Args({100000, 2, 0})
    ->Args({200000, 2, 0})
    ->Args({100000, 1, 1})
    ->Args({100000, 2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK_MAIN();
