// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The dozer scene (issue 17): a 2 m blade pushes soil across a Terrain with the dynamic height field on
// (docs/terrain.md "Deformers", "Avalanches and the angle of repose"): the soil the blade overlaps is moved ahead
// of it into a berm, and the berm's moved vertices avalanche toward their angle of repose. Shared by
// bench/bench_terrain_dynamic.cpp and the demo's dozer scene (examples/demo_dozer.h).
//
// The field: n x n vertices at `cell` m (n = 257 and 513 in the bench: 25.6 m and 51.2 m square), `thickness` m of
// soil, surface at z = 0, one soil material (friction mu of the scene material, contact E `youngsModulus`).
// The blade: a box 0.1 m thick along x, `bladeWidth` m across (y), 0.4 m tall, a dynamic body of 1000 kg whose
// geometry carries the bool property DynamicHeightFieldDeformer (useContactDepth false). It is driven as in
// test/test_model_terrain_deform.cpp: before every step its position height, y and rotation are reset and its
// velocity set to the phase's velocity, so it follows the same path in every run whatever the soil does (the
// soil's push on it only shows up as a velocity loss within a step). Why not a kinematic body: the deformer's
// horizontal contact points act on a dynamic body, as they would on a real machine, and the bench then also
// pays for them in the solve.
//
// Phases: "push" (the blade's bottom `depth` m below the surface, moving +x at `speed`; the soil's resistance
// slows it within each step, so it covers less than speed x time), then "rest" (the blade still and lifted
// `restLift` m clear of the surface: nothing is pushed, the armed berm keeps avalanching for the avalanche life
// time). Why lifted: a blade left in the soil sags under gravity within each step (g dt = 0.16 m/s, above the
// 0.05 m/s cut-off velocity) and would keep pushing.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <scree/scree.h>

#include "scenes/scenes.h"

namespace scree::scenes {

struct TerrainDozerParams {
  size_t n = 257;            ///< vertices per side
  Real cell = 0.1;           ///< m
  Real thickness = 0.5;      ///< m of soil
  Real mu = 0.5;             ///< soil friction (repose atan(mu) for loose dry soil)
  Real youngsModulus = 1e3;  ///< N/m, contact material E (as the deform test)
  Real dt = 1.0 / 60;
  bool dynamicHeightField = true;  ///< off: the same blade path on a static-height terrain (the bench's baseline)
  Real bladeWidth = 2.0, bladeThickness = 0.1, bladeHeight = 0.4;  ///< m
  Real depth = 0.1;          ///< m, blade bottom below the surface
  Real speed = 0.5;          ///< m/s
  Real startX = -1.5;        ///< m, blade centre x at the start (field centred on the origin)
  Real pushSeconds = 3.0;
  Real restSeconds = 2.0;
  Real restLift = 0.5;       ///< m, blade bottom above the initial surface while resting
};

struct TerrainDozerPhase {
  std::string name;
  Real seconds = 0;
  Real speed = 0;  ///< m/s along +x
  bool lifted = false;  ///< blade held clear of the soil
};

struct TerrainDozerScene : Scene {
  TerrainDozerParams params;
  HeightFieldRef field;
  TerrainRef terrain;
  RigidBodyRef blade;
  std::vector<TerrainDozerPhase> phases;
  int stepIndex = 0;

  int phaseSteps(size_t k) const;
  int totalSteps() const;
  /// Index of the phase the next step belongs to (phases.size() once all are done; the blade then rests).
  size_t currentPhase() const;
  /// Resets the blade to its path with the current phase's velocity and steps once.
  void step();
  /// Berm height, m above the initial surface: over the rows across the blade (|y| < 0.4 of its width), the
  /// highest soil within 1.5 m ahead of its front face, averaged over the rows.
  Real bermHeight() const;
  /// Steepest slope (rad) between 8-neighbour vertices within 1.5 m ahead of the blade across its width.
  Real bermSlope() const;
};

TerrainDozerScene buildTerrainDozer(const TerrainDozerParams& p = {});

}  // namespace scree::scenes
