// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Suction gripper cost: N cups (1..64) on one static holder, each cup's lip resting sealed on its own 1 kg box
// that stands on the ground (10 % vacuum, lip radius 2.5 cm: 19.7 N of vacuum per cup, more than the box's
// 9.81 N weight, so each box is pulled up against its lip and stays there). The baseline is the same bodies, joints and cup
// cylinders with no gripper: no sensors, no listener, no vacuum; its boxes rest on the ground instead.
// Reported: ms/step (median over repetitions), plus counters: cups, sealed cups and the largest box drift
// from its start (m) in the gripper variant.
//
// Overhead = time(gripper, N) / time(baseline, N); the README quotes the measured ratios.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <vector>

#include "scenes/scenes.h"

using namespace scree;

namespace {

struct SuctionBenchScene : scenes::Scene {
  SuctionGripperRef gripper;
  std::vector<SuctionCupRef> cups;
  std::vector<RigidBodyRef> boxes;
  std::vector<Vec3> start;
};

/// N cups on a grid 0.3 m apart; withGripper = false builds the baseline.
std::unique_ptr<SuctionBenchScene> buildSuctionScene(int n, bool withGripper) {
  auto s = std::make_unique<SuctionBenchScene>();
  scenes::initScene(*s, "suction", 0.5, 1.0 / 60.0, 0);
  scenes::addGround(*s);
  const int side = int(std::ceil(std::sqrt(double(n))));
  const Real lip = 0.025, boxHalf = 0.1;
  auto holder = std::make_shared<RigidBody>("holder");
  holder->setMotionControl(RigidBody::STATIC);
  holder->setPosition(Vec3(0, 0, 2 * boxHalf + 0.05));  // lips at the boxes' top faces
  s->sim->add(holder);
  if (withGripper) {
    s->gripper = std::make_shared<SuctionGripper>();
    s->gripper->setHolderRigidBody(holder);
    s->gripper->getVacuumSystem()->setDesiredVacuum(0.1);
    s->sim->add(s->gripper);
  }
  for (int i = 0; i < n; ++i) {
    const Vec3 xy(0.3 * (i % side), 0.3 * (i / side), 0);
    s->boxes.push_back(scenes::addBox(*s, Vec3(boxHalf, boxHalf, boxHalf), 1.0, xy + Vec3(0, 0, boxHalf)));
    s->start.push_back(s->boxes.back()->getPosition());
    const Vec3 local = xy + Vec3(0, 0, -0.05);
    if (withGripper) {
      auto cup = std::make_shared<SuctionCup>(nullptr, lip, 0.01, 8, Vec3(0, 0, -0.1), 0.01);
      s->gripper->add(cup, local);
      s->cups.push_back(cup);
    } else {
      // The same cup body (cylinder of the lip radius and height, axis along z) locked to the holder.
      auto body = std::make_shared<RigidBody>("cup");
      auto geom = std::make_shared<Geometry>(std::make_shared<Cylinder>(lip, 0.01));
      geom->setLocalRotation(Quat(Eigen::AngleAxis<Real>(0.5 * 3.14159265358979323846, Vec3::UnitX())));
      geom->setLocalPosition(Vec3(0, 0, 0.005));
      body->add(geom);
      body->setPosition(holder->getPosition() + local);
      s->sim->add(body);
      auto j = std::make_shared<LockJoint>(body, holder);
      j->setEnableCollisions(false);
      s->sim->add(j);
    }
  }
  return s;
}

void suctionStep(benchmark::State& state, bool withGripper) {
  const int n = int(state.range(0));
  auto s = buildSuctionScene(n, withGripper);
  for (int i = 0; i < 60; ++i) s->step();  // warm up: contacts, warm-start cache, interactions
  for (auto _ : state) s->step();
  state.counters["cups"] = n;
  if (withGripper) {
    int sealed = 0;
    for (const auto& c : s->cups) sealed += c->isSealed() ? 1 : 0;
    state.counters["sealed"] = sealed;
  }
  Real drift = 0;
  for (size_t i = 0; i < s->boxes.size(); ++i)
    drift = std::max<Real>(drift, (s->boxes[i]->getPosition() - s->start[i]).norm());
  state.counters["box_drift_m"] = drift;
}

void BM_suction_gripper(benchmark::State& state) { suctionStep(state, true); }
void BM_suction_baseline(benchmark::State& state) { suctionStep(state, false); }

}  // namespace

BENCHMARK(BM_suction_baseline)->Arg(1)->Arg(4)->Arg(16)->Arg(64)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_suction_gripper)->Arg(1)->Arg(4)->Arg(16)->Arg(64)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
