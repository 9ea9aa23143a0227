// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Contact materials, a sliding box and a pendulum on a hinge (docs/rigid-bodies.md).
#include <cmath>
#include <cstdio>
#include <scree/scree.h>
using namespace scree;

int main() {
  Simulation sim;
  auto floorMaterial = std::make_shared<Material>("floor");
  auto rubber = std::make_shared<Material>("rubber");
  auto floor = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(10, 10, 0.5)));
  floor->setPosition(Vec3(0, 0, -0.5));
  floor->setMaterial(floorMaterial);
  sim.add(floor);

  // Contact material of the pair: friction, restitution, stiffness (Young's modulus) and damping time.
  ContactMaterialRef cm = sim.getMaterialManager().getOrCreateContactMaterial(floorMaterial, rubber);
  cm->setFrictionCoefficient(0.5);
  cm->setRestitution(0.0);
  cm->setYoungsModulus(1e8);  // Pa

  // A 0.2 m rubber cube thrown along x at 3 m/s: friction stops it.
  auto cubeGeometry = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.1, 0.1, 0.1)));
  cubeGeometry->setMaterial(rubber);
  auto cube = std::make_shared<RigidBody>("cube");
  cube->add(cubeGeometry);
  cube->setPosition(Vec3(0, 0, 0.1));
  cube->setVelocity(Vec3(3, 0, 0));
  sim.add(cube);

  // A 1 m pendulum: a sphere on a hinge about y through a static anchor body 2 m up.
  auto anchor = std::make_shared<RigidBody>("anchor");
  anchor->setMotionControl(RigidBody::STATIC);
  anchor->setPosition(Vec3(5, 0, 2));
  sim.add(anchor);
  auto bob = std::make_shared<RigidBody>("bob");
  bob->add(std::make_shared<Geometry>(std::make_shared<Sphere>(0.05)));
  bob->setPosition(Vec3(6, 0, 2));  // horizontal: released from 90 degrees
  sim.add(bob);
  sim.add(std::make_shared<Hinge>(bob, anchor, Vec3(5, 0, 2), Vec3(0, 1, 0)));

  for (int i = 0; i < 120; ++i) sim.stepForward();  // 2 s
  const Vec3 b = bob->getPosition() - anchor->getPosition();
  std::printf("cube stopped after %.3f m; pendulum at %.1f deg below horizontal\n",
              cube->getPosition().x(), std::atan2(-b.z(), b.x()) * 180 / M_PI);
}
