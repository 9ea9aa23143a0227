// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scenes/terrain_plate.h"

#include <limits>

namespace scree::scenes {

TerrainPlateScene buildTerrainPlate(const TerrainPlateParams& p) {
  TerrainPlateScene s;
  initScene(s, "terrain_plate", 0.5, p.dt, 0);
  s.contactMaterial->setYoungsModulus(p.youngsModulus);
  const Real size = p.cell * Real(p.n - 1);
  auto hf = std::make_shared<HeightField>(p.n, p.n, size, size);
  hf->setHeights(std::vector<Real>(p.n * p.n, s.thickness));
  s.terrain = std::make_shared<Terrain>(hf);
  s.terrain->getGeometry()->setMaterial(s.material);
  s.terrain->getGeometry()->setPosition(Vec3(0, 0, -s.thickness));
  s.sim->add(s.terrain);
  TerrainDataInterface& di = s.terrain->getDataInterface();
  di.add(s.material, 0, 0.0, p.deformability);
  di.setYieldPressure(p.yieldPressure);
  di.setMaxCompressionMultiplier(p.maxMultiplier);
  di.setDepthForMaxCompression(p.depthForMax);
  di.setMaxYoungsChangePerTimestep(std::numeric_limits<Real>::infinity());
  const Real r = 0.2 * p.cell;
  for (size_t j = 0; j < p.n; ++j)
    for (size_t i = 0; i < p.n; ++i) {
      Vec3 at = hf->getVertex(i, j);
      at.z() = r;
      auto geom = std::make_shared<Geometry>(std::make_shared<Sphere>(r));
      geom->setMaterial(s.material);
      auto piston = std::make_shared<RigidBody>("piston");
      piston->add(geom);
      piston->setMass(p.pressure * p.cell * p.cell / SceneConstants::gravity);
      piston->setPosition(at);
      s.sim->add(piston);
      s.sim->add(std::make_shared<Prismatic>(piston, nullptr, at, Vec3::UnitZ()));
    }
  return s;
}

Real TerrainPlateScene::meanInnerSinkage() const {
  const HeightField& hf = *terrain->getHeightField();
  const size_t n = hf.getResolutionX();
  Real sum = 0;
  for (size_t y = 1; y + 1 < n; ++y)
    for (size_t x = 1; x + 1 < n; ++x) sum += thickness - hf.getHeight(x, y);
  return sum / Real((n - 2) * (n - 2));
}

}  // namespace scree::scenes
