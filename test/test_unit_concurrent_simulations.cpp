// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Independent Simulations stepped on separate threads at the same time (docs/solvers.md "Several simulations
// on several threads"): each gives the bits it gives when the Simulations are stepped one after the
// other on one thread. What the Simulations share is the logger and the collision-group names (both behind a
// mutex), the atomic counters that number bodies, geometries, materials and grippers' groups, and the
// persistent team of the partitioned sweeps (a second caller that finds it busy runs its job on
// its own thread, which gives the same bits). This is what bench_rigid_stages BM_independent_pyramids measures
// (about 2x on two cores, docs/solver-internals.md "The ceiling of two threads").
#include <doctest/doctest.h>

#include <cstring>
#include <functional>
#include <latch>
#include <set>
#include <thread>
#include <vector>

#include "body_state.h"
#include "scenes/scenes.h"
#include "scree/core/parallel.h"
#include "scree/model/suction_gripper.h"

using namespace scree;

TEST_SUITE("concurrent simulations") {

namespace {
using test::bodyState;  // the state compared bit for bit (test/body_state.h)
using test::sameBits;

struct Job {
  std::function<scenes::PyramidScene()> build;
  int threads = 1;  // scree::setNumThreads on the thread that steps it
  int steps = 0;
};

// `start`, when given, holds the stepping back until both threads have built their scenes, so that their first
// steps (every contact's manifold computed afresh) overlap.
std::vector<Real> runJob(const Job& job, std::latch* start = nullptr) {
  setNumThreads(job.threads);
  scenes::PyramidScene s = job.build();
  if (start) start->arrive_and_wait();
  for (int i = 0; i < job.steps; ++i) s.step();
  setNumThreads(1);
  return bodyState(*s.sim);
}

}  // namespace

TEST_CASE("two Simulations stepped at once on two threads give the bits of the serial run") {
  // Two different pyramids with the default settings (so that a mix-up of their data would show), and a pair whose
  // partitioned sweeps both ask for two threads: one of them gets the persistent team, the other runs its sweeps
  // on its own thread, and neither may change its bits. 10 and 12 rows (55 and 78 boxes) for 120 steps (2 s): the
  // contacts settle and the warm starts are in use, at a cost small enough for the sanitizer build.
  auto pyramid = [](int rows, bool partitioned) {
    return [rows, partitioned] {
      scenes::PyramidScene s = scenes::buildPyramid(rows);
      if (partitioned) {
        s.sim->getSolver().setUsePartitionedSweeps(true);
        s.sim->getSolver().setUseAdaptiveSweepThreads(false);
      }
      return s;
    };
  };
  const std::vector<std::pair<Job, Job>> pairs = {
      {{pyramid(10, false), 1, 120}, {pyramid(12, false), 1, 120}},
      {{pyramid(10, true), 2, 120}, {pyramid(12, true), 2, 120}},
  };
  for (size_t p = 0; p < pairs.size(); ++p) {
    CAPTURE(p);
    const auto& [a, b] = pairs[p];
    // The reference: one after the other on this thread, each on one thread.
    Job a1 = a, b1 = b;
    a1.threads = b1.threads = 1;
    const std::vector<Real> refA = runJob(a1), refB = runJob(b1);
    // At once, several times (the threads' interleaving differs from run to run).
    for (int rep = 0; rep < 5; ++rep) {
      CAPTURE(rep);
      std::latch start(2);
      std::vector<Real> gotB;
      std::thread other([&] { gotB = runJob(b, &start); });
      const std::vector<Real> gotA = runJob(a, &start);
      other.join();
      CHECK(sameBits(gotA, refA));
      CHECK(sameBits(gotB, refB));
    }
    // The two pyramids differ, so the comparison above can tell them apart.
    CHECK(refA.size() != refB.size());
  }
}

TEST_CASE("suction grippers made on two threads at once get distinct collision groups") {
  // Each SuctionGripper takes a collision group of its own, numbered by a process-wide counter, so that its
  // holder, cups and sensors do not collide with each other. Two threads that build scenes with grippers at once
  // must not hand out one number twice (a plain counter did: a data race, which the ThreadSanitizer stage of CI
  // reports, and two grippers that could share a group).
  constexpr int kPerThread = 500;
  std::vector<uint32_t> mine(kPerThread), theirs(kPerThread);
  std::latch start(2);
  auto make = [&](std::vector<uint32_t>& groups) {
    start.arrive_and_wait();
    for (uint32_t& g : groups) g = std::make_shared<SuctionGripper>()->getCollisionGroup();
  };
  std::thread other([&] { make(theirs); });
  make(mine);
  other.join();
  std::set<uint32_t> all(mine.begin(), mine.end());
  all.insert(theirs.begin(), theirs.end());
  CHECK(all.size() == size_t(2 * kPerThread));
}

}  // TEST_SUITE
