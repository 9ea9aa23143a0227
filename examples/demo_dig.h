// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Part of scree_demo: digging (issue 16). The trench scene of bench/scenes/terrain_dig.h in its lighter demo form
// (TerrainDigParams::demoParams: 25 mm particles, a 0.4 m trench): a kinematic bucket - blade (the shovel), back
// plate and sides - is lowered 8 cm into a Terrain, dragged forward (the cut soil becomes particles in the
// bucket), lifted, turned tip down to dump, and the heap merges back into the height field. Prints per phase the
// particles created and merged, the live ones, the soil-volume ledger (height field, pending, particles and the
// total, which stays constant), and the bucket's read-outs (Terrain::getShovelStats): the digging force (terrain
// plus particle contact forces on the shovel; mean horizontal component and peak magnitude over the phase) and
// the fill at the phase's end.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "scenes/terrain_dig.h"

inline bool runDigDemo() {
  using namespace scree;
  scenes::TerrainDigScene s = scenes::buildTerrainDig(scenes::TerrainDigParams::demoParams());
  Terrain& terrain = *s.terrain;
  const Real total0 = terrain.getVolumeLedger().total();
  std::printf("\ndigging: bucket %.1f x %.1f x %.2f m digs %.0f cm deep, %.1f m long; particles r %.0f mm carry %.3g "
              "m^3 each; soil ledger total %.6f m^3\n",
              s.params.bucketLength, s.params.bucketWidth, s.params.bucketHeight, 100 * s.params.depth,
              s.params.trenchLength, 1e3 * terrain.getParticleAttributes().getParticleRadius(),
              terrain.getParticleVolume(), total0);
  std::printf("%-7s %7s %7s %6s %11s %9s %10s %11s %10s %10s %8s %9s\n", "phase", "created", "merged", "live",
              "heightF[m3]", "pend[m3]", "parts[m3]", "total[m3]", "Fx mean[N]", "|F| max[N]", "fill[L]",
              "fill[n]");
  double seconds = 0;
  int steps = 0;
  for (size_t k = 0; k < s.phases.size(); ++k) {
    size_t created = 0, merged = 0;
    Real fx = 0, fmax = 0;
    const int n = s.phaseSteps(k);
    for (int i = 0; i < n; ++i) {
      s.step();
      created += terrain.getLastStepDigStats().particlesCreated;
      merged += terrain.getLastStepDigStats().particlesMerged;
      const Vec3 f = terrain.getShovelStats(*s.blade).diggingForce();
      fx += f.x();
      fmax = std::max(fmax, f.norm());
      seconds += s.sim->getStepStats().total;
      ++steps;
    }
    const TerrainVolumeLedger& l = terrain.getVolumeLedger();
    const TerrainShovelStats st = terrain.getShovelStats(*s.blade);
    std::printf("%-7s %7zu %7zu %6zu %11.5f %9.6f %10.6f %11.6f %10.1f %10.1f %8.1f %9zu\n", s.phases[k].name.c_str(),
                created, merged, s.sim->getGranularBodySystem().numParticles(), l.heightField, l.pending,
                l.particles, l.total(), fx / std::max(1, n), fmax, 1e3 * st.fillVolume, st.fillParticles);
  }
  const TerrainVolumeLedger& l = terrain.getVolumeLedger();
  std::printf("soil ledger total %.6f m^3 (drift %.1e relative); %d steps, %.2f ms/step\n", l.total(),
              (l.total() - total0) / total0, steps, 1e3 * seconds / std::max(1, steps));
  return s.sim->getLastStepReport().ok() && std::abs(l.total() - total0) <= 1e-9 * total0;
}
