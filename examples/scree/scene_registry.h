// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The scenes `scree list` shows and `scree run` runs. Each entry wraps a builder that already exists (the
// reference scenes of docs/scenes.md in bench/scenes/, the terrain scenes in bench/scenes/terrain_*.h, the
// suction pick-and-place and the granular pile of examples/demo_*.h): no scene is defined here, only how to
// drive it and what to print at the end.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <scree/scree.h>

namespace scree::cli {

struct BuildOptions {
  double dt = 0;  ///< s; 0 keeps the scene's own time step (the builders that drive phases get it as a parameter)
};

/// A built scene, ready to step.
struct SceneRun {
  Simulation* sim = nullptr;
  std::vector<const Terrain*> terrains;  ///< for the recording (their height fields)
  /// One step, with the scene's own per-step work (a driven bucket or blade, per-step metric observers).
  std::function<void()> step;
  /// Prints the scene's metrics to stdout, one "  name: value" line each.
  std::function<void()> printMetrics;
  std::shared_ptr<void> owner;  ///< keeps the scene alive
};

struct SceneEntry {
  std::string name;
  std::string description;  ///< one line
  double defaultTime = 0;   ///< s, the scene's defined duration
  std::function<SceneRun(const BuildOptions&)> build;
};

/// Every scene, in the order `scree list` prints them.
const std::vector<SceneEntry>& sceneRegistry();
/// The entry named `name`, or nullptr.
const SceneEntry* findScene(const std::string& name);

}  // namespace scree::cli
