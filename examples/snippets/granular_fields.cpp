// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Granular fields on a voxel grid (docs/granular-fields.md); examples/granular_fields.cpp is a longer example.
#include <cstdio>
#include <scree/scree.h>
using namespace scree;

int main() {
  Simulation sim;
  for (int i = 0; i < 100; ++i)  // a row of falling particles
    sim.getGranularBodySystem().createParticle(Vec3(-1.9 + 0.038 * i, 0.06, 1), 0.015);
  for (int i = 0; i < 30; ++i) sim.stepForward();

  // [doc]
  GranularFieldPostProcessor gpp(sim.getGranularBodySystem(), {32, 32, 16}, Vec3(4, 4, 2));  // voxels, side lengths
  gpp.addField(std::make_shared<GranularVelocityField>());   // adds mass and momentum too
  gpp.calculateFields();
  const Real* v = gpp.getField(GranularField::VELOCITY)->getFieldData();  // [(i + nx*(j + ny*k))*3 + c]
  gpp.writeVti("fields.vti");                                 // ParaView; writeCsvSlice("z8.csv", 2, 8) for a slice
  // [/doc]

  // The grid is centred on the origin (12.5 cm voxels). After 30 steps of free fall the row is at
  // z = 1 - g h^2 30 * 31 / 2 = -0.267 m, so voxel (16, 16, 5) holds grains near x = y = 0.06 m.
  const size_t vox = gpp.voxelIndex(16, 16, 5);
  std::printf("v_z in voxel (16, 16, 5): %.3f m/s (free fall for 0.5 s: -4.903)\n", v[3 * vox + 2]);
}
