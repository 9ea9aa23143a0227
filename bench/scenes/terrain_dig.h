// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The trench scene (issue 16): a kinematic bucket digs a trench in a Terrain, lifts the soil, dumps it beside
// the trench and the heap merges back into the height field. Shared by bench/bench_terrain_dig.cpp, the demo's
// dig scene (examples/demo_dig.h) and examples/terrain_dig_trench.cpp.
//
// The bucket: a bottom plate (the blade, tagged as the shovel: forward to its front edge, up its thickness), a
// back plate and two side plates, of the soil material or registered steel (steelBucket), on one kinematic body driven phase by phase by
// velocities (lower into the ground, drag forward, lift while moving forward, turn the tip down, wait). Why
// kinematic: the scene measures the terrain and the particle solve, not an arm's control; the bucket moves the
// same in every run whatever the soil does, so runs are comparable step by step.
//
// Soil: bulk density 1600 kg/m^3 (a particle's mass is that times the soil volume it carries), friction 0.5 and
// rolling resistance 0.3 (the particles copy the soil's parameters; without rolling resistance a sphere the
// bucket set rolling rolls on forever, docs/terrain.md). The defaults size the dig so that it produces over
// 5,000 live particles (r = 15 mm, 9.5e-6 m^3 of soil each; a 0.6 x 0.6 x 0.45 m bucket lowered 8 cm into the
// ground and dragged 0.7 m: about 0.07 m^3 of soil, 7,700 particles made, 6,700 live at the peak). Why the bucket is so much larger
// than the soil: the particles overlap on their lattice but pile loosely, taking about 2.5 times the soil's volume
// (sphere volume 1.5 V at a packing fraction near 0.6), and a full bucket grows a column of new particles over its
// front that falls off. demoParams() is a lighter cut (larger particles, shorter trench).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <scree/scree.h>

namespace scree::scenes {

struct TerrainDigPhase {
  std::string name;
  Real seconds = 0;
  Vec3 velocity = Vec3::Zero();         ///< m/s, the bucket's linear velocity during the phase
  Vec3 angularVelocity = Vec3::Zero();  ///< rad/s
};

struct TerrainDigParams {
  Real dt = 1.0 / 60;
  int iterations = 10;
  // Field: sizeX x sizeY m, cells of `cell` m, soil `thickness` m thick, its surface at z = 0.
  Real sizeX = 4.0, sizeY = 2.0, cell = 0.05, thickness = 0.5;
  Real density = 1600;            ///< kg/m^3, bulk density of the soil
  Real friction = 0.5;
  Real rollingResistance = 0.3;
  Real particleRadius = 0.015;    ///< m, <= cell
  Real mergeVelocity = 0.1;       ///< m/s
  // Bucket (inner dimensions, m): blade length along x, width along y, wall height, plate thickness.
  Real bucketLength = 0.6, bucketWidth = 0.6, bucketHeight = 0.45, plate = 0.02;
  Real startX = -1.2;             ///< m, bucket (blade centre) x at the start
  Real startZ = 0.03;             ///< m, blade centre height at the start (above the surface)
  Real depth = 0.08;              ///< m, trench depth (the blade's centre plane goes this deep)
  Real trenchLength = 0.7;        ///< m, drag distance
  Real digSpeed = 0.4;            ///< m/s
  Real settleSeconds = 4.0;       ///< after the dump
  /// false: the bucket is of the soil material (the terrain logs its one FAQ warning: particles meet the bucket
  /// through the soil's parameters, fine here because this soil is stiff). true: the bucket is steel (E 2e11,
  /// the soil's friction) registered with addExternalMaterial, the manual's recommended set-up: particle-bucket
  /// contacts get E = max(steel, soil) and the SPLIT solve type, i.e. their normals go to the direct solver
  /// (measured cost in docs/terrain.md, "Digging cost").
  bool steelBucket = false;
  /// The lighter cut scree_demo runs: 25 mm particles (4.6 times the soil per particle), a 0.4 m trench, 1.5 s
  /// of settling: about 1,000 particles instead of 6,700, a few seconds of run time.
  static TerrainDigParams demoParams() {
    TerrainDigParams p;
    p.particleRadius = 0.025;
    p.trenchLength = 0.4;
    p.settleSeconds = 1.5;
    p.steelBucket = true;
    return p;
  }
};

struct TerrainDigScene {
  TerrainDigParams params;
  std::unique_ptr<Simulation> sim;
  MaterialRef soil;
  HeightFieldRef field;
  TerrainRef terrain;
  RigidBodyRef bucket;
  GeometryRef blade;  ///< the shovel
  std::vector<TerrainDigPhase> phases;
  int stepIndex = 0;  ///< steps taken

  /// Steps of phase k (its seconds / dt, rounded).
  int phaseSteps(size_t k) const;
  int totalSteps() const;
  /// Index of the phase the next step belongs to (phases.size() once all are done).
  size_t currentPhase() const;
  /// Sets the bucket's velocities for the current phase and steps once.
  void step();
};

TerrainDigScene buildTerrainDig(const TerrainDigParams& p = {});

}  // namespace scree::scenes
