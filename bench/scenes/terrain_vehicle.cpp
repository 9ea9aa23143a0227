// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scenes/terrain_vehicle.h"

namespace scree::scenes {

TerrainVehicleScene buildTerrainVehicle(const TerrainVehicleParams& p) {
  TerrainVehicleScene s;
  s.vehicle = buildVehicle(p.vehicle);
  Simulation& sim = *s.vehicle.sim;
  // vehicle.h grounds the vehicle on a plane; replace it by the field unless the field is to stay untouched.
  if (!p.untouched)
    for (const GeometryRef& g : sim.getStaticGeometries())
      if (g->getShape()->getType() == Shape::PLANE) {
        sim.remove(g);
        break;
      }

  auto hf = std::make_shared<HeightField>(p.resolution, p.resolution, p.size, p.size);
  hf->setHeights(std::vector<Real>(p.resolution * p.resolution, p.thickness));
  s.field = std::make_shared<Geometry>(hf, "ground");
  auto soil = std::make_shared<Material>("soil");
  auto cm = sim.getMaterialManager().getOrCreateContactMaterial(s.vehicle.material, soil);
  cm->setYoungsModulus(p.soilYoungsModulus);
  cm->setFrictionCoefficient(p.vehicle.mu);
  cm->setRestitution(0);
  s.field->setMaterial(soil);
  s.field->setPosition(Vec3(p.untouched ? 100.0 : p.offsetX, 0, -p.thickness));
  if (p.terrain) {
    s.terrain = std::make_shared<Terrain>(s.field);
    s.terrain->getDataInterface().add(soil, 0, 0.0, p.deformability);
    sim.add(s.terrain);
  } else {
    sim.add(s.field);
  }
  return s;
}

}  // namespace scree::scenes
