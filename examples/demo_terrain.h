// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Part of scree_demo: the vehicle of demo_vehicle.h (TwoBodyTireModel tires) on soft ground - a deformable
// Terrain (0.1 m cells, deformability 1, the default compression parameters fitted to a dry sand; docs/terrain.md)
// - driving forward, back and forward again over the same 2 m of ground. Prints, per pass, how much deeper the
// ruts got along the wheel tracks; compressed ground keeps its hardness, so the third pass adds least (measured
// 6.3, 6.3, 2.8 mm; the second pass is no shallower than the first here - fewer wheels cross the measured 2 m, the
// vehicle reverses inside it - see docs/terrain.md for why and for the clean driven-wheel test).
// The scene is bench/scenes/terrain_vehicle.h (read it to build your own: a HeightField, Terrain(geometry),
// getDataInterface().add(soil, 0, 0, deformability), and a soil-like contact Young's modulus).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "scenes/terrain_vehicle.h"

inline bool runTerrainDemo(double secondsPerPass) {
  using namespace scree;
  scenes::TerrainVehicleParams p;
  p.resolution = 121;  // 12 m x 12 m, 0.1 m cells
  p.size = 12.0;
  p.offsetX = 2.0;     // the field spans x in [-4, 8]; the vehicle starts at x = 0
  p.vehicle.speed = 2.0;
  scenes::TerrainVehicleScene s = scenes::buildTerrainVehicle(p);
  const HeightField& hf = *s.terrain->getHeightField();
  const Real cell = hf.getCellSizeX();
  // Mean and deepest rut along both wheel tracks (y = +-track/2) over x in [1, 3] m, which all four wheels cross
  // in every pass.
  auto rut = [&](Real& deepest) {
    Real sum = 0;
    int n = 0;
    deepest = 0;
    for (Real y : {0.5 * p.vehicle.track, -0.5 * p.vehicle.track})
      for (Real x = 1.0; x <= 3.0 + 1e-9; x += cell) {
        const Vec3 local = s.field->getTransform().applyInverse(Vec3(x, y, 0));
        const Real depth = p.thickness - hf.getHeightAt(local.x(), local.y());
        sum += depth;
        deepest = std::max(deepest, depth);
        ++n;
      }
    return sum / n;
  };
  const Real total0 = s.terrain->getVolumeLedger().total();
  std::printf("\nvehicle on soft ground: Terrain %zu x %zu (%.2f m cells), deformability %.1f, p0 %.0f kPa, M %.0f, "
              "D %.2f m\n",
              hf.getResolutionX(), hf.getResolutionY(), cell, p.deformability,
              s.terrain->getDataInterface().getYieldPressure() / 1e3,
              s.terrain->getDataInterface().getMaxCompressionMultiplier(),
              s.terrain->getDataInterface().getDepthForMaxCompression());
  std::printf("%5s %9s %10s %10s %11s %12s %10s\n", "pass", "dir", "x end[m]", "rut[mm]", "deeper[mm]",
              "deepest[mm]", "terrain ms");
  Real before = 0, deepest = 0;
  double terrainSeconds = 0;
  int steps = 0;
  for (int pass = 1; pass <= 3; ++pass) {
    const Real dir = pass % 2 ? 1.0 : -1.0;
    for (auto& axle : s.vehicle.axles) axle->getMotor1D().setSpeed(dir * p.vehicle.speed / p.vehicle.tireRadius);
    for (int i = 0; i < int(std::lround(secondsPerPass / p.vehicle.dt)); ++i) {
      s.step();
      terrainSeconds += s.terrain->getLastStepTime();
      ++steps;
    }
    const Real now = rut(deepest);
    std::printf("%5d %9s %10.2f %10.2f %11.2f %12.2f %10.4f\n", pass, dir > 0 ? "forward" : "back",
                s.vehicle.chassis->getPosition().x(), 1e3 * now, 1e3 * (now - before), 1e3 * deepest,
                1e3 * terrainSeconds / steps);
    before = now;
  }
  const TerrainVolumeLedger& l = s.terrain->getVolumeLedger();
  std::printf("soil ledger: height field %.4f m^3 + compressed %.4f m^3 = %.6f m^3 (at start %.6f)\n", l.heightField,
              l.compressed, l.total(), total0);
  return s.vehicle.sim->getLastStepReport().ok();
}
