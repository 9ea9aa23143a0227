// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// A wheel on a TwoBodyTireModel tire carrying a 350 kg load: the tire's radial deflection is load / k
// (docs/tire.md).
#include <cstdio>
#include <scree/scree.h>
using namespace scree;

int main() {
  Simulation sim;
  sim.add(std::make_shared<Geometry>(std::make_shared<Plane>(Vec3::UnitZ(), 0.0)));  // the ground, z = 0

  const Real R = 0.4, rimRadius = 0.25;
  const Vec3 hub(0, 0, R);
  auto world = std::make_shared<RigidBody>("world");  // static: the vertical guide's other end
  world->setMotionControl(RigidBody::STATIC);
  world->setPosition(hub);
  auto carrier = std::make_shared<RigidBody>("carrier");  // 300 kg on a vertical slider
  carrier->setMass(300);
  carrier->setInertiaTensor(Vec3(5, 5, 5).asDiagonal());
  carrier->setPosition(hub);
  auto rim = std::make_shared<RigidBody>("rim");  // 50 kg, hinged to the carrier about y
  rim->setMass(50);
  rim->setInertiaTensor(Vec3(0.3, 0.5, 0.3).asDiagonal());
  rim->setPosition(hub);
  auto tire = std::make_shared<RigidBody>("tire");  // a Cylinder's axis is its local y
  tire->add(std::make_shared<Geometry>(std::make_shared<Cylinder>(R, 0.25)));
  tire->setPosition(hub);
  for (auto& b : {world, carrier, rim, tire}) sim.add(b);
  sim.add(std::make_shared<Prismatic>(carrier, world, hub, Vec3::UnitZ()));
  sim.add(std::make_shared<Hinge>(rim, carrier, hub, Vec3::UnitY()));  // drive it with its Motor1D

  auto model = std::make_shared<TwoBodyTireModel>(tire, R, rim, rimRadius);  // axis: the rim's local y
  model->setStiffness(3.5e5, TwoBodyTireModel::RADIAL);                      // N/m (the AGX default)
  model->setDamping(7e3, TwoBodyTireModel::RADIAL);                          // N s/m
  sim.add(model);

  for (int i = 0; i < 180; ++i) sim.stepForward();  // 3 s: settled
  std::printf("radial deflection %.2f mm (load / k = 350 kg g / 3.5e5 N/m = 9.81 mm)\n",
              1e3 * model->getRadialDeflection());
}
