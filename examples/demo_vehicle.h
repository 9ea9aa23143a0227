// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Part of scree_demo: a four-wheeled vehicle on TwoBodyTireModel tires (issue 6) driving at 2 m/s over flat
// ground and an 8 cm bump. Chassis box, hinge-motor axles, rims and tires as built by bench/scenes/vehicle.cpp
// (read it to build your own: a rim body per wheel hinged to the chassis with a Motor1D, a Cylinder tire body
// joined to the rim by TwoBodyTireModel(tire, tireRadius, rim, rimRadius)). Runs in its own Simulation at
// h = 1/400 s (the PGS wheel chains stay tight; 1/60 runs too, less accurately) and prints the tire deformations.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "scenes/vehicle.h"

inline bool runVehicleDemo(double seconds) {
  using namespace scree;
  scenes::VehicleParams p;
  p.speed = 2.0;
  p.bump = true;
  scenes::VehicleScene s = scenes::buildVehicle(p);
  std::printf("\nvehicle on TwoBodyTireModel tires (radial k %.3g N/m, torsional k %.3g N m/rad), bump %.0f cm at "
              "x = %.1f m\n",
              s.tireModels[0]->getStiffness(TwoBodyTireModel::RADIAL),
              s.tireModels[0]->getStiffness(TwoBodyTireModel::TORSIONAL), 100 * p.bumpHeight, p.bumpX);
  std::printf("%5s %7s %7s %27s %9s %9s %9s\n", "t[s]", "x[m]", "v[m/s]", "radial FL FR RL RR [mm]", "lat[mm]",
              "tors[mrad]", "Fr FL[N]");
  Real peak[4] = {0, 0, 0, 0};
  const int printEvery = int(std::lround(0.25 / p.dt));
  for (int i = 1; i <= int(std::lround(seconds / p.dt)); ++i) {
    s.step();
    for (int k = 0; k < 4; ++k) peak[k] = std::max(peak[k], s.tireModels[k]->getRadialDeflection());
    if (i % printEvery) continue;
    const auto& fl = s.tireModels[0];
    std::printf("%5.2f %7.3f %7.3f %6.2f %6.2f %6.2f %6.2f %9.3f %9.3f %9.1f\n", s.sim->getTimeStamp(),
                s.chassis->getPosition().x(), s.chassis->getVelocity().x(), 1e3 * peak[0], 1e3 * peak[1],
                1e3 * peak[2], 1e3 * peak[3], 1e3 * fl->getLateralOffset(), 1e3 * fl->getTorsionAngle(),
                fl->getForce(TwoBodyTireModel::RADIAL));
    std::fill(peak, peak + 4, 0.0);
  }
  const Real sag = (p.chassisMass + 4 * p.rimMass) * 9.81 / 4 / s.tireModels[0]->getStiffness(TwoBodyTireModel::RADIAL);
  std::printf("(radial columns: peak over each 0.25 s; static sag (chassis + rims) g / 4k = %.2f mm)\n", 1e3 * sag);
  return s.sim->getLastStepReport().ok();
}
