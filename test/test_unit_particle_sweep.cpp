// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The four-wide particle sweep (solver/src/granular_stage.cpp, "Four-wide sweep"; docs/terrain.md, "Digging
// cost", sixth round): centred particle units are solved four at a time in AVX2 lanes, each slab's units in
// dependency-level order. The claim is that this is the scalar sweep bit for bit (units of one level share no
// particle, units that share one keep their order, and every lane does the scalar code's IEEE operations in the
// same order). These tests run the same scenes with the four-wide sweep switched off and on and compare the
// particle states' hashes; they fail on any lost or reordered update, any contracted multiply-add or any
// std::max / branch whose blend differs from the scalar code in a single bit (a sign of zero included). The
// second test does the same for the eight-wide (AVX-512) kernel where the CPU has it.
#include <doctest/doctest.h>

#include <cstdint>

#include <scree/scree.h>

#include "granular_stage.h"
#include "scenes/particle_scenes.h"
#include "scenes/terrain_dig.h"

using namespace scree;
using detail::GranularStage;

namespace {
/// Restores the default (four-wide where the CPU has AVX2, eight-wide where it has AVX-512) at the end of a test.
/// wide = false keeps the four-wide kernel on an AVX-512 CPU.
struct SweepSwitch {
  explicit SweepSwitch(bool on, bool wide = true) {
    GranularStage::setVectorSweepEnabled(on);
    GranularStage::setAvx512SweepEnabled(wide);
  }
  ~SweepSwitch() {
    GranularStage::setVectorSweepEnabled(true);
    GranularStage::setAvx512SweepEnabled(true);
  }
};

/// A jittered lattice of 2,500 particles falling into a pile (friction, no rolling resistance), 60 steps.
uint64_t latticeHash(bool vector, int threads, bool wide = true) {
  SweepSwitch sw(vector, wide);
  setNumThreads(threads);
  scenes::SphereLatticeParams p;
  p.count = 2500;
  p.jitter = true;
  scenes::ParticleScene s = scenes::buildParticleLattice(p);
  for (int i = 0; i < 60; ++i) s.step();
  CHECK(s.sim->getStepStats().numParticleContacts > 4000);  // several slabs: the parallel path
  setNumThreads(0);
  return scenes::hashParticleState(s.particles());
}

/// The trench of bench/bench_terrain_dig.cpp (friction 0.5, rolling resistance 0.3, particles created by the
/// cut every step, the kinematic bucket's serial units): its first 150 steps (lower and dig).
uint64_t trenchHash(bool vector, bool wide = true) {
  SweepSwitch sw(vector, wide);
  setNumThreads(1);
  scenes::TerrainDigScene s = scenes::buildTerrainDig(scenes::TerrainDigParams{});
  for (int i = 0; i < 150; ++i) s.step();
  CHECK(s.sim->getGranularBodySystem().numParticles() > 1000);
  setNumThreads(0);
  return scenes::hashParticleState(s.sim->getGranularBodySystem());
}
}  // namespace

TEST_SUITE("unit") {
  TEST_CASE("the four-wide particle sweep is bit-identical to the scalar sweep") {
    if (!GranularStage::vectorSweepAvailable()) {
      MESSAGE("this CPU has no AVX2: only the scalar sweep exists, nothing to compare");
      return;
    }
    const uint64_t scalar = latticeHash(false, 1);
    const uint64_t packed0 = GranularStage::packedUnitsTotal();
    const uint64_t vector1 = latticeHash(true, 1, false);  // four-wide kernel only
    const uint64_t packed1 = GranularStage::packedUnitsTotal();
    const uint64_t vector2 = latticeHash(true, 2);
    CHECK(packed1 - packed0 > 100000);  // the four-wide path really ran (about 4,000 units a step in packets)
    CHECK(scalar == vector1);
    CHECK(scalar == vector2);

    const uint64_t trenchScalar = trenchHash(false);
    const uint64_t packed2 = GranularStage::packedUnitsTotal();
    const uint64_t trenchVector = trenchHash(true, false);
    CHECK(GranularStage::packedUnitsTotal() - packed2 > 100000);
    CHECK(trenchScalar == trenchVector);
  }

  // The eight-wide kernel (solver/src/granular_stage.cpp, "Eight-wide sweep"): pairs of packets in the lanes
  // of AVX-512 registers, claimed bit-identical to the four-wide and the scalar sweep (the same IEEE operations
  // per lane; the file is compiled with -ffp-contract=off, since AVX-512 brings FMA: with contraction allowed
  // GCC fuses the kernel's multiply-adds and these comparisons fail).
  TEST_CASE("the eight-wide particle sweep is bit-identical to the scalar sweep") {
    if (!GranularStage::avx512SweepAvailable()) {
      MESSAGE("this CPU has no AVX-512: the eight-wide kernel does not run, nothing to compare");
      return;
    }
    const uint64_t scalar = latticeHash(false, 1);
    const uint64_t wide0 = GranularStage::wideUnitsTotal();
    const uint64_t wide1 = latticeHash(true, 1);
    const uint64_t wideRan = GranularStage::wideUnitsTotal() - wide0;
    const uint64_t wide2 = latticeHash(true, 2);
    CHECK(wideRan > 100000);  // the eight-wide kernel really ran (some 40 sweeps' worth of its units a step)
    CHECK(scalar == wide1);
    CHECK(scalar == wide2);

    const uint64_t trenchScalar = trenchHash(false);
    const uint64_t wide3 = GranularStage::wideUnitsTotal();
    const uint64_t trenchWide = trenchHash(true);
    CHECK(GranularStage::wideUnitsTotal() - wide3 > 100000);
    CHECK(trenchScalar == trenchWide);
  }
}
