// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scenes/terrain_dig.h"

#include <cmath>

namespace scree::scenes {

int TerrainDigScene::phaseSteps(size_t k) const { return int(std::lround(phases[k].seconds / params.dt)); }

int TerrainDigScene::totalSteps() const {
  int n = 0;
  for (size_t k = 0; k < phases.size(); ++k) n += phaseSteps(k);
  return n;
}

size_t TerrainDigScene::currentPhase() const {
  int n = stepIndex;
  for (size_t k = 0; k < phases.size(); ++k) {
    if (n < phaseSteps(k)) return k;
    n -= phaseSteps(k);
  }
  return phases.size();
}

void TerrainDigScene::step() {
  const size_t k = currentPhase();
  if (k < phases.size()) {
    bucket->setVelocity(phases[k].velocity);
    bucket->setAngularVelocity(phases[k].angularVelocity);
  } else {
    bucket->setVelocity(Vec3::Zero());
    bucket->setAngularVelocity(Vec3::Zero());
  }
  sim->stepForward();
  ++stepIndex;
}

TerrainDigScene buildTerrainDig(const TerrainDigParams& p) {
  TerrainDigScene s;
  s.params = p;
  s.sim = std::make_unique<Simulation>();
  Simulation& sim = *s.sim;
  sim.setTimeStep(p.dt);
  sim.setUniformGravity(Vec3(0, 0, -9.81));
  sim.getSolver().setNumIterations(p.iterations);
  s.soil = std::make_shared<Material>("soil");
  s.soil->setDensity(p.density);
  s.soil->setFrictionCoefficient(p.friction);
  s.soil->setRestitution(0);
  s.soil->setRollingResistanceCoefficient(p.rollingResistance);

  const size_t nx = size_t(std::lround(p.sizeX / p.cell)) + 1, ny = size_t(std::lround(p.sizeY / p.cell)) + 1;
  s.field = std::make_shared<HeightField>(nx, ny, p.sizeX, p.sizeY);
  s.field->setHeights(std::vector<Real>(nx * ny, p.thickness));
  s.terrain = std::make_shared<Terrain>(s.field);
  s.terrain->getGeometry()->setMaterial(s.soil);
  s.terrain->getGeometry()->setPosition(Vec3(0, 0, -p.thickness));
  sim.add(s.terrain);
  s.terrain->getDataInterface().add(s.soil, 0, /*particleAdhesion*/ 0, /*deformability*/ 0);
  s.terrain->getParticleAttributes().setParticleRadius(p.particleRadius);
  s.terrain->setMergeVelocity(p.mergeVelocity);

  // The bucket, in its body frame: blade centre at the origin, forward +x, up +z.
  const Real L = p.bucketLength, W = p.bucketWidth, H = p.bucketHeight, t = p.plate;
  s.bucket = std::make_shared<RigidBody>("bucket");
  s.blade = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.5 * L, 0.5 * W, 0.5 * t)), "blade");
  s.blade->getPropertyContainer().addPropertyVec3(Terrain::ShovelUpProperty, Vec3(0, 0, t));
  s.blade->getPropertyContainer().addPropertyVec3(Terrain::ShovelForwardProperty, Vec3(0.5 * L, 0, 0));
  s.bucket->add(s.blade);
  auto back = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.5 * t, 0.5 * W + t, 0.5 * H)), "back");
  back->setLocalPosition(Vec3(-0.5 * L - 0.5 * t, 0, 0.5 * H - 0.5 * t));
  s.bucket->add(back);
  for (Real side : {-1.0, 1.0}) {
    auto g = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.5 * L, 0.5 * t, 0.5 * H)),
                                        side < 0 ? "side -y" : "side +y");
    g->setLocalPosition(Vec3(0, side * (0.5 * W + 0.5 * t), 0.5 * H - 0.5 * t));
    s.bucket->add(g);
  }
  MaterialRef bucketMaterial = s.soil;
  if (p.steelBucket) {
    bucketMaterial = std::make_shared<Material>("steel");
    bucketMaterial->setYoungsModulus(2e11);
    bucketMaterial->setFrictionCoefficient(p.friction);
    s.terrain->getDataInterface().addExternalMaterial(bucketMaterial);
  }
  for (const GeometryRef& g : s.bucket->getGeometries()) g->setMaterial(bucketMaterial);
  s.bucket->setMotionControl(RigidBody::KINEMATICS);
  s.bucket->setPosition(Vec3(p.startX, 0, p.startZ));
  sim.add(s.bucket);

  const Real lowerSeconds = 0.5;
  s.phases = {{"lower", lowerSeconds, Vec3(0, 0, -(p.startZ + p.depth) / lowerSeconds), Vec3::Zero()},
              {"dig", p.trenchLength / p.digSpeed, Vec3(p.digSpeed, 0, 0), Vec3::Zero()},
              {"lift", 1.0, Vec3(0.3, 0, 0.5), Vec3::Zero()},
              {"dump", 1.0, Vec3::Zero(), Vec3(0, 2.0, 0)},
              {"settle", p.settleSeconds, Vec3::Zero(), Vec3::Zero()}};
  return s;
}

}  // namespace scree::scenes
