// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// A suction cup on a kinematic holder lifts a 2 kg box (docs/suction.md).
#include <cstdio>
#include <scree/scree.h>
using namespace scree;

int main() {
  Simulation sim;
  auto ground = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(1, 1, 0.05)));
  ground->setPosition(Vec3(0, 0, -0.05));
  sim.add(ground);

  auto box = std::make_shared<RigidBody>("box");  // 0.2 m cube, 2 kg
  box->add(std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.1, 0.1, 0.1))));
  box->setMass(2);
  box->setPosition(Vec3(0, 0, 0.1));
  sim.add(box);

  auto holder = std::make_shared<RigidBody>("holder");  // moved by the program: KINEMATICS
  holder->setMotionControl(RigidBody::KINEMATICS);
  holder->setPosition(Vec3(0, 0, 0.21));
  auto gripper = std::make_shared<SuctionGripper>();
  gripper->setHolderRigidBody(holder);
  // One cup: lip radius 3 cm, lip height 1 cm, 8 seal sensors; mounted under the holder, facing down.
  gripper->add(std::make_shared<SuctionCup>(nullptr, 0.03, 0.01, 8), Vec3(0, 0, -0.005));
  gripper->getVacuumSystem()->setDesiredVacuum(0.5);  // mount pressure P_a (1 - 0.5): holds 143 N over the lip
  sim.add(holder);
  sim.add(gripper);

  for (int i = 0; i < 30; ++i) sim.stepForward();   // seal
  holder->setVelocity(Vec3(0, 0, 0.2));               // lift at 0.2 m/s for 1 s
  for (int i = 0; i < 60; ++i) sim.stepForward();
  std::printf("box lifted to z = %.3f m (from 0.1 m)\n", box->getPosition().z());
}
