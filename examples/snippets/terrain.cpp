// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The C++ fragments of docs/terrain.md, each between "// [doc]" and "// [/doc]", compiled in context.
// Compile-only (test_docs_snippets does not run it): the set-up reads a material map "map.png" that the page
// only names; the terrain examples (examples/terrain_*.cpp) and test_model_terrain* run the same calls.
// snippet: compile-only
#include <cmath>
#include <cstdio>
#include <scree/scree.h>
using namespace scree;

#pragma GCC diagnostic ignored "-Wunused-value"  // the read-out fragment names fields as a list

void setUp(Simulation& sim, const MaterialRef& soil, const MaterialRef& tire) {
  // [doc]
  auto hf = std::make_shared<HeightField>(257, 257, 25.6, 25.6);   // 0.1 m cells
  hf->setHeights(std::vector<Real>(257 * 257, 0.5));               // 0.5 m of soil ...
  auto terrain = std::make_shared<Terrain>(hf);
  terrain->getGeometry()->setPosition(Vec3(0, 0, -0.5));           // ... with its surface at z = 0
  terrain->getGeometry()->setMaterial(soil);
  sim.add(terrain);                                                 // geometry + two listeners
  auto& data = terrain->getDataInterface();                         // a reference (the manual's ->)
  data.add(soil, 0, /*particleAdhesion*/ 0, /*deformability*/ 1);  // index 0 = every vertex not mapped otherwise
  data.setMaterialMapping("map.png");                              // optional: several materials
  // Soil contacts need a soil-like stiffness (see "Contact stiffness" below):
  sim.getMaterialManager().getOrCreateContactMaterial(tire, soil)->setYoungsModulus(1e6);
  // [/doc]
}

void shovel(const std::shared_ptr<Terrain>& terrain, const GeometryRef& blade) {
  // [doc]
  blade->getPropertyContainer().addPropertyVec3(Terrain::ShovelUpProperty, Vec3(0, 0, 0.02));     // thickness
  blade->getPropertyContainer().addPropertyVec3(Terrain::ShovelForwardProperty, Vec3(0.2, 0, 0)); // origin -> tip
  terrain->getParticleAttributes().setParticleRadius(0.02);     // <= terrain->getMaximumParticleRadius()
  terrain->setMergeVelocity(0.1);                               // m/s, default 0.1
  terrain->setShovelMinimumDigAngleToHorizontalPlane(M_PI / 10);  // the default
  // per step: terrain->getLastStepDigStats(): particlesCreated, particlesMerged, particlesRemoved, volumeDug,
  // volumeMerged; terrain->getVolumeLedger() for where the soil is.
  // [/doc]
}

void readOuts(const std::shared_ptr<Terrain>& terrain, const GeometryRef& blade) {
  // [doc]
  const TerrainShovelStats s = terrain->getShovelStats(*blade);
  s.terrainContactForce;   // N, world: the solver's force on the shovel from its contacts with the terrain geometry
  s.particleContactForce;  // N, world: from its contacts with this terrain's particles (others are not counted)
  s.groundCuttingForce;    // N, world: the ground cutting row on a shovel that is also a deformer (else zero)
  s.diggingForce();        // the sum of the three
  s.fillVolume;            // m^3 of soil carried by the terrain particles in the shovel; s.fillParticles counts them
  // [/doc]
}

void particleMaterials(const std::shared_ptr<Terrain>& terrain, const MaterialRef& steel) {
  // [doc]
  terrain->getDataInterface().addExternalMaterial(steel);             // removeExternalMaterial, getExternalMaterials
  terrain->getParticleAttributes().setParticleYoungsModulusMultiplier(1e4);  // default 1
  terrain->getDataInterface().setParticleFrictionSolveType(FrictionModel::DIRECT);  // default ITERATIVE
  terrain->getDataInterface().setInverseFrictionMultiplier(0.5);       // default 1, DIRECT only
  // [/doc]
}

void avalanches(const std::shared_ptr<Terrain>& terrain, const MaterialRef& sand, Real x, Real y) {
  // [doc]
  terrain->setEnableDynamicHeightField(true);          // off by default; off disarms every vertex
  terrain->setAvalancheStepLifeTime(100);              // steps an arming lasts (default 100)
  terrain->setAvalancheDecayPercent(0.1);              // 0 ... 0.5 (default 0.1)
  terrain->setAvalancheVertexDistanceExtent(2);        // also the manual's setAvalanceVertexDistanceExtent
  terrain->setWetnessScale(0.3);                       // 0 (dry, default) ... 1
  terrain->getDataInterface().add(sand, 0, 0.0, 1.0, 34 * M_PI / 180);  // angle of repose; 0 = atan(friction)
  terrain->armAvalanche(x, y);                         // not in the manual: after your own edits
  terrain->avalancheAll();                             // an imported field, to repose now
  // per step: terrain->getLastStepAvalancheStats() (visited, moves, volumeMoved, volumeLost),
  //           terrain->getNumArmedVertices(), terrain->getLastStepAvalancheTime()
  // [/doc]
}

int main() {
  Simulation sim;
  auto soil = std::make_shared<Material>("soil");
  auto tire = std::make_shared<Material>("tire");
  setUp(sim, soil, tire);
  return 0;
}
