// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// scree_demo: the demo the README's first command runs. A built-in scene showing what the engine does today:
// a 10-box tower, a 6-row pyramid, a box sliding to rest on friction, a bouncing ball (restitution), a heavy
// box on a light one (1000:1), and a mixed pile of spheres, capsules, cylinders and convex hulls dropped on the
// ground, plus jointed mechanisms: a motor-driven arm (hinge with a speed motor and a force limit) and a six-link
// pendulum chain on ball joints, a suction gripper pick-and-place (demo_suction.h) and a granular pile poured
// from a nozzle (demo_granular.h). Prints a one-line summary per simulated second. Then a four-wheeled vehicle on
// TwoBodyTireModel tires drives over a bump (demo_vehicle.h), and the same vehicle drives forward, back and forward
// over soft ground (a deformable Terrain) and prints how much deeper its ruts get per pass (demo_terrain.h), and a
// bucket digs a trench in a Terrain, lifts and dumps the soil, and the heap merges back (demo_dig.h), and a
// dozer blade pushes soil into a berm that slumps toward its angle of repose (demo_dozer.h).
//
// Usage: scree_demo [seconds=5] [iterations=16] [--record FILE]
//   --record FILE  also writes the first, combined scene as a recording (docs/recording.md) that
//                  `scree view FILE` turns into a replay page; scripts/demo.sh does both.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <scree/io/recording.h>
#include <scree/scree.h>

#include "demo_vehicle.h"
#include "demo_suction.h"
#include "demo_granular.h"
#include "demo_terrain.h"
#include "demo_dig.h"
#include "demo_dozer.h"

using namespace scree;

namespace {
RigidBodyRef makeBody(Simulation& sim, ShapeRef shape, const Vec3& pos, const MaterialRef& mat, const std::string& name) {
  auto body = std::make_shared<RigidBody>(name);
  auto geom = std::make_shared<Geometry>(std::move(shape));
  geom->setMaterial(mat);
  body->add(geom);
  body->setPosition(pos);
  sim.add(body);
  return body;
}
}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args;
  std::string recordPath;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--record") {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "scree_demo: --record needs a file name\n");
        return 2;
      }
      recordPath = argv[++i];
    } else {
      args.push_back(argv[i]);
    }
  }
  const double seconds = args.size() > 0 ? std::atof(args[0].c_str()) : 5.0;
  const int iterations = args.size() > 1 ? std::atoi(args[1].c_str()) : 16;
  std::printf("%s\n", getConfigurationString());

  Simulation sim;
  sim.getSolver().setNumIterations(iterations);
  sim.setUniformGravity(Vec3(0, 0, -9.81));

  auto stone = std::make_shared<Material>("stone");
  stone->setDensity(1000);
  auto rubber = std::make_shared<Material>("rubber");
  rubber->setDensity(1000);
  auto& mm = sim.getMaterialManager();
  auto cmStone = mm.getOrCreateContactMaterial(stone, stone);
  cmStone->setFrictionCoefficient(0.5);
  cmStone->setRestitution(0.0);
  auto cmRubber = mm.getOrCreateContactMaterial(rubber, stone);
  cmRubber->setRestitution(0.8);

  auto groundGeom = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(50, 50, 0.5)), "ground");
  groundGeom->setMaterial(stone);
  groundGeom->setPosition(Vec3(0, 0, -0.5));
  sim.add(groundGeom);

  // Tower of 10 unit cubes.
  std::vector<RigidBodyRef> tower;
  for (int i = 0; i < 10; ++i)
    tower.push_back(makeBody(sim, std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)), Vec3(-8, 0, 0.5 + i), stone, "tower"));
  // Pyramid with a base of 6.
  RigidBodyRef pyramidTop;
  for (int row = 0; row < 6; ++row)
    for (int k = 0; k < 6 - row; ++k)
      pyramidTop = makeBody(sim, std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)),
                            Vec3(-1.01 * (5 - row) / 2.0 + 1.01 * k, 8, 0.5 + row), stone, "pyramid");
  // A box sliding at 5 m/s.
  auto slider = makeBody(sim, std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)), Vec3(0, -8, 0.5), stone, "slider");
  slider->setVelocity(Vec3(5, 0, 0));
  // A rubber ball dropped from 2 m.
  auto ball = makeBody(sim, std::make_shared<Sphere>(0.25), Vec3(8, 0, 2.25), rubber, "ball");
  // 1000 kg box on a 1 kg box.
  auto light = makeBody(sim, std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)), Vec3(8, 8, 0.5), stone, "light");
  light->setMass(1);
  auto heavy = makeBody(sim, std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)), Vec3(8, 8, 1.5), stone, "heavy");
  heavy->setMass(1000);
  // A pile of mixed shapes.
  std::vector<Vec3> hull = {{-0.3, -0.2, -0.2}, {0.3, -0.2, -0.2}, {0, 0.3, -0.2}, {0, 0, 0.3}, {0.1, 0.1, -0.25}};
  std::vector<RigidBodyRef> pile;
  for (int i = 0; i < 24; ++i) {
    ShapeRef s;
    switch (i % 4) {
      case 0: s = std::make_shared<Sphere>(0.2); break;
      case 1: s = std::make_shared<Capsule>(0.15, 0.4); break;
      case 2: s = std::make_shared<Cylinder>(0.2, 0.3); break;
      default: s = std::make_shared<Convex>(hull); break;
    }
    const Vec3 p(-0.6 + 0.6 * (i % 3), -0.6 + 0.6 * ((i / 3) % 3), 1.0 + 0.7 * (i / 9));
    auto b = makeBody(sim, s, p, stone, "pile");
    b->setRotation(Quat(Eigen::AngleAxis<Real>(0.3 * i, Vec3(1, 2, 3).normalized())));
    pile.push_back(b);
  }

  // Motor-driven arm: a 2 m bar on a hinge about y at (0, 12, 3), driven at 1 rad/s with up to 2000 N m.
  auto arm = makeBody(sim, std::make_shared<Box>(Vec3(1.0, 0.1, 0.1)), Vec3(1.0, 12, 3), stone, "arm");
  arm->setMass(50);
  auto armHinge = std::make_shared<Hinge>(arm, nullptr, Vec3(0, 12, 3), Vec3::UnitY());
  armHinge->getMotor1D().setEnable(true);
  armHinge->getMotor1D().setSpeed(1.0);
  armHinge->getMotor1D().setForceRange(-2000, 2000);
  sim.add(armHinge);
  // Pendulum chain: six 0.4 m links on ball joints from a pivot at (0, -14, 4), released horizontally.
  std::vector<std::shared_ptr<BallJoint>> chainJoints;
  RigidBodyRef prevLink;
  for (int i = 0; i < 6; ++i) {
    auto link = makeBody(sim, std::make_shared<Box>(Vec3(0.2, 0.05, 0.05)), Vec3(0.4 * i + 0.2, -14, 4), stone, "link");
    link->setMass(2);
    auto j = std::make_shared<BallJoint>(link, prevLink, Vec3(0.4 * i, -14, 4));
    sim.add(j);
    chainJoints.push_back(j);
    prevLink = link;
  }

  // Suction gripper: picks a 4 kg box at (0, 17, 0), carries it 1.5 m along x and releases it (pump off).
  auto suction = SuctionPickPlace::build(sim, stone, Vec3(0, 17, 0));
  // Granular pile at (-5, -5): particles poured at run time.
  auto granularPile = std::make_shared<demo::GranularPile>(sim, stone);
  sim.add(granularPile);

  const Real towerTop0 = tower.back()->getPosition().z();
  const Real pyramidTop0 = pyramidTop->getPosition().z();
  const Real sliderX0 = slider->getPosition().x();
  Real ballApex = 0;
  double solveTime = 0, totalTime = 0;
  int steps = 0;
  // The recording (docs/recording.md) of this combined scene at 30 frames per simulated second.
  io::RecordingWriter recorder;
  if (!recordPath.empty()) {
    recorder.open(recordPath);
    recorder.setRecordEvery(std::max(1, int(std::lround(1.0 / (30.0 * sim.getTimeStep())))));
    // The pile's grain is the particle system's material before the first grain exists, so that the recording
    // lists it (a material first used later is recorded as unknown).
    sim.getGranularBodySystem().setMaterial(granularPile->getGrainMaterial());
    recorder.begin(sim, "scree_demo");
  }
  std::printf("%5s %9s %9s %9s %9s %9s %9s %9s %9s %8s %8s\n", "t[s]", "tower[cm]", "pyr[cm]", "slide[m]", "ball[m]",
              "heavy[mm]", "pileKE[J]", "arm[rad]", "chain[mm]", "contacts", "ms/step");
  while (sim.getTimeStamp() < seconds - 1e-9) {
    sim.stepForward();
    if (recorder.isOpen()) recorder.writeFrame(sim);
    ++steps;
    solveTime += sim.getStepStats().solve;
    totalTime += sim.getStepStats().total;
    ballApex = std::max<Real>(ballApex, ball->getPosition().z() - 0.25);
    const Real t = sim.getTimeStamp();
    if (std::abs(t - std::round(t)) < 0.5 * sim.getTimeStep()) {
      Real ke = 0;
      for (auto& b : pile) ke += b->getKineticEnergy();
      const Vec3 top = tower.back()->getPosition();
      Real chainErr = 0;
      for (auto& j : chainJoints) chainErr = std::max<Real>(chainErr, (j->getFrame(0).p - j->getFrame(1).p).norm());
      std::printf("%5.1f %9.3f %9.3f %9.4f %9.3f %9.3f %9.4f %9.3f %9.3f %8zu %8.3f\n", t,
                  100 * std::hypot(top.x() + 8, top.y()) + 100 * std::abs(top.z() - towerTop0),
                  100 * std::abs(pyramidTop->getPosition().z() - pyramidTop0), slider->getPosition().x() - sliderX0,
                  ballApex, 1000 * (heavy->getPosition().z() - 1.5), ke, armHinge->getAngle(), 1000 * chainErr,
                  sim.getStepStats().numContactPoints,
                  1000 * totalTime / steps);
      ballApex = 0;
    }
  }
  if (recorder.isOpen()) {
    const uint32_t frames = recorder.getNumFrames();
    const uint64_t bytes = recorder.close();
    std::printf("recorded %u frames (%.2f MB) to %s\n", frames, bytes / 1e6, recordPath.c_str());
  }
  const Real expectedSlide = 25.0 / (2 * 0.5 * 9.81);
  std::printf("slider stopped after %.4f m (Coulomb: v^2/(2 mu g) = %.4f m)\n", slider->getPosition().x() - sliderX0,
              expectedSlide);
  suction->printSummary();
  granularPile->printSummary();
  std::printf("%d steps, %.3f ms/step (solve %.3f ms)\n", steps, 1000 * totalTime / steps, 1000 * solveTime / steps);
  const auto& report = sim.getLastStepReport();
  const bool vehicleOk = runVehicleDemo(std::min(seconds, 4.0));
  const bool terrainOk = runTerrainDemo(std::min(seconds, 5.0) / 2.5);
  const bool digOk = runDigDemo();
  const bool dozerOk = runDozerDemo();
  return report.ok() && vehicleOk && terrainOk && digOk && dozerOk ? 0 : 1;
}
