// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// hello_world: a box dropped on the ground, printing its height.
#include <cstdio>

#include <scree/scree.h>

int main() {
  using namespace scree;
  Simulation sim;

  // Ground: a static 100 x 100 x 1 m box with its top face at z = 0.
  auto ground = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(50, 50, 0.5)));
  ground->setPosition(Vec3(0, 0, -0.5));
  sim.add(ground);

  // A 1 m cube (1000 kg at the default density) released 2 m above the ground.
  auto box = std::make_shared<RigidBody>("box");
  box->add(std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.5, 0.5, 0.5))));
  box->setPosition(Vec3(0, 0, 2.5));
  sim.add(box);

  for (int step = 0; step <= 120; ++step) {
    if (step % 10 == 0) std::printf("t = %5.2f s   z = %.4f m\n", sim.getTimeStamp(), box->getPosition().z());
    sim.stepForward();
  }
  return 0;
}
