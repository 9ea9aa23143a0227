// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The four-wheeled vehicle of vehicle.h (TwoBodyTireModel tires) on a height-field ground instead of the plane:
// either a plain HeightField or a deformable Terrain on the same field (bench/bench_terrain.cpp, the demo's
// terrain scene). The ground is a soil material whose contact with the vehicle's material has a soil-like
// Young's modulus (the terrain yields at most the contact's elastic deflection per step, terrain.h), the same on
// both grounds so the only difference is the terrain's work.
#pragma once

#include "scenes/vehicle.h"

namespace scree::scenes {

struct TerrainVehicleParams {
  VehicleParams vehicle;
  size_t resolution = 257;       ///< vertices per side
  Real size = 25.6;              ///< m per side (cells of 0.1 m at 257)
  Real thickness = 0.5;          ///< m of soil under the surface at z = 0 (the ledger's volume)
  Real offsetX = 10.0;           ///< field centre x: the vehicle (at x = 0) starts near the -x end
  bool terrain = true;           ///< false: a plain HeightField with the same heights and material
  /// true: the field lies 100 m away and the vehicle stays on the plane of vehicle.h (the terrain is idle).
  bool untouched = false;
  Real deformability = 1.0;
  Real soilYoungsModulus = 1e6;  ///< N/m per contact point, vehicle-soil contact
};

struct TerrainVehicleScene {
  VehicleScene vehicle;
  GeometryRef field;
  TerrainRef terrain;  ///< null on a plain HeightField
  void step() { vehicle.step(); }
};

TerrainVehicleScene buildTerrainVehicle(const TerrainVehicleParams& p = {});

}  // namespace scree::scenes
