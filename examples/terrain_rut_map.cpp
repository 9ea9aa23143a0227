// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Writes the ruts a vehicle leaves on soft ground as a depth map, to look at them rather than read a number:
// the vehicle of the demo (tire models) drives 4 s forward over a deformable Terrain (0.1 m cells,
// deformability 1), then the depth of every vertex below the original surface is written as "x y depth_mm"
// rows (gnuplot's pm3d format, a blank line between rows of x). docs/terrain/rut_map.gp turns it into
// docs/terrain/rut_map.png.
//
//   build/examples/terrain_rut_map [out.dat] [seconds]
#include <cstdio>
#include <cstdlib>
#include <string>

#include "scenes/terrain_vehicle.h"

int main(int argc, char** argv) {
  using namespace scree;
  const std::string out = argc > 1 ? argv[1] : "rut_map.dat";
  const double seconds = argc > 2 ? std::atof(argv[2]) : 4.0;
  scenes::TerrainVehicleParams p;
  p.resolution = 121;  // 12 m x 12 m, 0.1 m cells
  p.size = 12.0;
  p.offsetX = 2.0;
  p.vehicle.speed = 2.0;
  scenes::TerrainVehicleScene s = scenes::buildTerrainVehicle(p);
  for (auto& axle : s.vehicle.axles) axle->getMotor1D().setSpeed(p.vehicle.speed / p.vehicle.tireRadius);
  const Real total0 = s.terrain->getVolumeLedger().total();
  const int steps = int(seconds / p.vehicle.dt + 0.5);
  for (int i = 0; i < steps; ++i) s.step();

  const HeightField& hf = *s.terrain->getHeightField();
  std::FILE* f = std::fopen(out.c_str(), "w");
  if (!f) {
    std::fprintf(stderr, "terrain_rut_map: cannot write %s\n", out.c_str());
    return 1;
  }
  Real deepest = 0;
  for (size_t i = 0; i < hf.getResolutionX(); ++i) {
    for (size_t j = 0; j < hf.getResolutionY(); ++j) {
      const Vec3 w = s.field->getTransform().apply(hf.getVertex(i, j));
      const Real depth = p.thickness - hf.getHeight(i, j);
      deepest = std::max(deepest, depth);
      std::fprintf(f, "%.3f %.3f %.4f\n", w.x(), w.y(), 1e3 * depth);
    }
    std::fprintf(f, "\n");
  }
  std::fclose(f);
  const TerrainVolumeLedger& l = s.terrain->getVolumeLedger();
  std::printf("after %.1f s: vehicle at x = %.2f m, deepest rut %.1f mm; ledger %.6f m^3 (start %.6f), %.6f m^3 "
              "pressed into compression; wrote %s\n",
              seconds, s.vehicle.chassis->getPosition().x(), 1e3 * deepest, l.total(), total0, l.compressed,
              out.c_str());
  return 0;
}
