// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Plate-load (bevameter) scene on a Terrain: an n x n terrain (cells s) entirely under a bed of n x n pistons,
// one small sphere above each vertex, guided vertically by a Prismatic to the world and weighing p s^2, so every
// vertex carries the pressure p (no plate edge, no statically indeterminate load sharing between the points of
// one rigid plate). Used by docs/terrain.md's plate-sinkage study (examples/terrain_plate_study.cpp); the tests
// build the same bed in test_model_terrain_sinkage.cpp.
#pragma once

#include "scenes/scenes.h"

namespace scree::scenes {

struct TerrainPlateParams {
  size_t n = 11;                ///< vertices per side
  Real cell = 0.05;             ///< m
  Real pressure = 20e3;         ///< Pa
  Real deformability = 1.0;
  Real yieldPressure = TerrainDataInterface::defaultYieldPressure;
  Real maxMultiplier = TerrainDataInterface::defaultMaxCompressionMultiplier;
  Real depthForMax = TerrainDataInterface::defaultDepthForMaxCompression;
  Real youngsModulus = 1e5;     ///< N/m per contact point (the soil's elastic stiffness under one piston)
  Real dt = 1.0 / 60;
};

struct TerrainPlateScene : Scene {
  TerrainRef terrain;
  Real thickness = 0.5;
  /// Mean plastic sinkage of the inner (n-2) x (n-2) vertices, m (the outer ring's pistons touch the edge).
  Real meanInnerSinkage() const;
};

TerrainPlateScene buildTerrainPlate(const TerrainPlateParams& p = {});

}  // namespace scree::scenes
