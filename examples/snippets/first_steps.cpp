// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include <cstdio>
#include <scree/scree.h>
using namespace scree;

int main() {
  Simulation sim;                                       // z up, gravity (0, 0, -9.80665), h = 1/60 s
  auto ground = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(10, 10, 0.5)));
  ground->setPosition(Vec3(0, 0, -0.5));                // a static geometry: top face at z = 0
  sim.add(ground);

  auto steel = std::make_shared<Material>("steel");
  steel->setDensity(7800);
  auto box = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)));
  box->setMaterial(steel);
  auto crate = std::make_shared<RigidBody>("crate");   // mass from volume x density: 7800 kg
  crate->add(box);
  crate->setPosition(Vec3(0, 0, 2));
  sim.add(crate);

  for (int i = 0; i < 120; ++i) sim.stepForward();     // 2 s
  std::printf("crate at z = %.4f m\n", crate->getPosition().z());   // ~0.5: resting on the ground
}
