// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Part of scree_demo: a dozer blade (issue 17). The scene of bench/scenes/terrain_dozer.h on a small field (65 x 65
// vertices, 6.4 m): a 2 m blade (a DynamicHeightFieldDeformer geometry) cuts 10 cm into the soil and pushes it at
// 0.5 m/s for 3 s; the soil it overlaps is moved ahead of it into a berm, whose moved vertices avalanche toward
// the angle of repose (docs/terrain.md "Deformers", "Avalanches and the angle of repose"); then it is lifted clear
// and rests 2 s while the berm keeps slumping. Prints per phase (the push in three parts) the berm height ahead of the blade, its
// steepest slope against the angle of repose, the soil volume the blade has swept (width x depth x travel), the volume moved between
// vertices so far (each step re-pushes the berm, so it exceeds the swept volume many times), the armed vertices and the soil-volume
// ledger total, which stays constant (pushing and avalanching only move soil between vertices).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "scenes/terrain_dozer.h"

inline bool runDozerDemo() {
  using namespace scree;
  scenes::TerrainDozerParams p;
  p.n = 65;
  scenes::TerrainDozerScene s = scenes::buildTerrainDozer(p);
  Terrain& terrain = *s.terrain;
  const Real total0 = terrain.getVolumeLedger().total();
  const Real repose = terrain.computeAngleOfRepose(p.n / 2, p.n / 2);
  std::printf("\ndozer: %.0f m blade, %.0f cm deep at %.1f m/s on %zu x %zu vertices (%.2f m cells); angle of repose "
              "%.1f deg; soil ledger total %.6f m^3\n",
              p.bladeWidth, 100 * p.depth, p.speed, p.n, p.n, p.cell, repose * 180 / M_PI, total0);
  std::printf("%-8s %7s %9s %10s %10s %11s %7s %12s %9s\n", "phase", "x[m]", "berm[cm]", "slope[deg]", "swept[m3]", "moved[m3]",
              "armed", "total[m3]", "ms/step");
  // The push in three parts, then the rest in two.
  const int pushSteps = s.phaseSteps(0), restSteps = s.phaseSteps(1);
  const int marks[5] = {pushSteps / 3, 2 * pushSteps / 3, pushSteps, pushSteps + restSteps / 2, s.totalSteps()};
  const char* names[5] = {"push 1/3", "push 2/3", "push 3/3", "rest 1/2", "rest 2/2"};
  Real pushed = 0, worstDrift = 0;
  double seconds = 0;
  bool ok = true;
  for (int k = 0; k < 5; ++k) {
    while (s.stepIndex < marks[k]) {
      s.step();
      pushed += terrain.getLastStepDeformStats().volumePushed;
      seconds += s.sim->getStepStats().total;
      worstDrift = std::max(worstDrift, std::abs(terrain.getVolumeLedger().total() - total0) / total0);
      ok = ok && s.sim->getLastStepReport().ok();
    }
    std::printf("%-8s %7.2f %9.1f %10.1f %10.4f %11.4f %7zu %12.6f %9.2f\n", names[k], s.blade->getPosition().x(),
                100 * s.bermHeight(), s.bermSlope() * 180 / M_PI,
                p.bladeWidth * p.depth * (s.blade->getPosition().x() - p.startX), pushed, terrain.getNumArmedVertices(),
                terrain.getVolumeLedger().total(), 1e3 * seconds / std::max(1, s.stepIndex));
  }
  std::printf("soil ledger total %.6f m^3 (worst drift %.1e relative)\n", terrain.getVolumeLedger().total(),
              worstDrift);
  return ok && pushed > 0 && worstDrift <= 1e-9;
}
