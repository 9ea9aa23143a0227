// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Where rows are solved, and how hard (docs/solvers.md).
#include <cstdio>
#include <scree/scree.h>
using namespace scree;

int main() {
  Simulation sim;
  auto steel = std::make_shared<Material>("steel");
  Solver& solver = sim.getSolver();
  solver.setNumIterations(20);  // PGS sweeps per step (default 10)

  // Contacts between two materials: ITERATIVE (PGS, the default), DIRECT (CHOLMOD), SPLIT or
  // DIRECT_AND_ITERATIVE. Without SuiteSparse (-DSCREE_WITH_SUITESPARSE=OFF) non-ITERATIVE rows go to PGS.
  sim.getMaterialManager().getOrCreateContactMaterial(steel, steel)->setSolveType(FrictionModel::SPLIT);

  // Joints default to DIRECT_AND_ITERATIVE; a joint may ask for PGS instead.
  auto a = std::make_shared<RigidBody>("a");
  a->add(std::make_shared<Geometry>(std::make_shared<Sphere>(0.1)));
  a->setMotionControl(RigidBody::STATIC);
  auto b = std::make_shared<RigidBody>("b");
  b->add(std::make_shared<Geometry>(std::make_shared<Sphere>(0.1)));
  b->setPosition(Vec3(0, 0, -1));
  sim.add(a);
  sim.add(b);
  auto joint = std::make_shared<BallJoint>(a, b, Vec3(0, 0, 0));
  joint->setSolveType(FrictionModel::ITERATIVE);
  sim.add(joint);

  for (int i = 0; i < 60; ++i) sim.stepForward();
  std::printf("%s\nball hangs at z = %.4f m\n", getConfigurationString(), b->getPosition().z());
}
