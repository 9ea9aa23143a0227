// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Simulation::getTimings(): the per-stage step times in milliseconds (StepTimings).
#include <doctest/doctest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <type_traits>

#include "test_world.h"

using namespace scree;
using scree::test::TestWorld;

TEST_SUITE("timings") {

TEST_CASE("getTimings: milliseconds per stage that add up to the step's total within the clock's resolution") {
  TestWorld w(1.0 / 60.0, 9.81);
  w.addGround();
  for (int i = 0; i < 5; ++i) w.addBox(Vec3(0.3, 0.3, 0.3), Vec3(0, 0, 0.3 + 0.6 * i), 216.0);
  const StepTimings before = w.sim->getTimings();
  CHECK(before.total == 0);
  CHECK(before.sumOfStages() == 0);
  // One clock tick in ms (steady_clock's period), times the number of stages: each stage is one difference of
  // clock reads, so their sum telescopes to the total up to the rounding of each difference.
  const double tickMs = 1e3 * double(std::chrono::steady_clock::period::num) /
                        double(std::chrono::steady_clock::period::den);
  for (int step = 0; step < 20; ++step) {
    w.steps(1);
    const StepTimings t = w.sim->getTimings();
    const StepStats& s = w.sim->getStepStats();
    CHECK(t.total > 0);
    CHECK(t.solve >= 0);
    CHECK(t.collideGeometries >= 0);
    CHECK(std::abs(t.sumOfStages() - t.total) <= 18 * tickMs + 1e-9 * t.total);
    // The same times as StepStats, in milliseconds.
    CHECK(t.total == doctest::Approx(1e3 * s.total).epsilon(1e-12));
    CHECK(t.solve == doctest::Approx(1e3 * s.solve).epsilon(1e-12));
    CHECK(t.contactRows == doctest::Approx(1e3 * s.contactRows).epsilon(1e-12));
  }
}

TEST_CASE("getTimings: each stage's time lands in its own field; idle stages report exactly 0") {
  // The step reads a tick counter at each stage boundary and hands each field the step's time times its share of
  // the ticks (solver/src/simulation.cpp), so a field mixed up with another would show another stage's time.
  // Listeners that spin for known durations (1, 2 and 4 ms of steady-clock time, each far above the other
  // stages' microseconds) give the three listener fields lower bounds; a swapped or shifted field would read a
  // few microseconds instead. Being descheduled only lengthens a stage, so the bounds hold on a busy machine.
  TestWorld w(1.0 / 60.0, 9.81);
  w.addGround();
  for (int i = 0; i < 5; ++i) w.addBox(Vec3(0.3, 0.3, 0.3), Vec3(0, 0, 0.3 + 0.6 * i), 216.0);
  w.steps(2);
  // No listeners, constraints, particles or projected ranges: those stages are idle and read 0 exactly.
  StepTimings t = w.sim->getTimings();
  CHECK(t.preCollide == 0);
  CHECK(t.pre == 0);
  CHECK(t.post == 0);
  CHECK(t.constraintRows == 0);
  CHECK(t.collideParticles == 0);
  CHECK(t.particleRows == 0);
  CHECK(t.projectPositions == 0);
  CHECK(t.compactParticles == 0);
  CHECK(t.solve > 0);

  struct Spinner : StepEventListener {
    Spinner() : StepEventListener(ALL) {}
    static void spin(double ms) {
      const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double, std::milli>(ms);
      while (std::chrono::steady_clock::now() < end) {
      }
    }
    void preCollide(const TimeStamp&) override { spin(1.0); }
    void pre(const TimeStamp&) override { spin(2.0); }
    void post(const TimeStamp&) override { spin(4.0); }
  };
  w.sim->add(std::static_pointer_cast<StepEventListener>(std::make_shared<Spinner>()));
  for (int step = 0; step < 3; ++step) {
    w.steps(1);
    t = w.sim->getTimings();
    // The share of ticks and the steady clock measure the same wall time; 2 % covers their rates' mismatch.
    CHECK(t.preCollide >= 0.98 * 1.0);
    CHECK(t.pre >= 0.98 * 2.0);
    CHECK(t.post >= 0.98 * 4.0);
    CHECK(t.total >= 0.98 * 7.0);
    CHECK(t.sumOfStages() == doctest::Approx(t.total).epsilon(1e-9));
  }
}

TEST_CASE("StepTimings += adds every field, total included") {
  // StepTimings is a plain struct of doubles: fill two with distinct powers of two through their bytes, so a
  // field that operator+= forgets (also one added later) shows up as a wrong element.
  static_assert(std::is_trivially_copyable_v<StepTimings> && sizeof(StepTimings) % sizeof(double) == 0);
  constexpr size_t n = sizeof(StepTimings) / sizeof(double);
  double a[n], b[n], r[n];
  for (size_t k = 0; k < n; ++k) {
    a[k] = std::ldexp(1.0, int(k));
    b[k] = std::ldexp(3.0, int(k) + 20);
  }
  StepTimings ta, tb;
  std::memcpy(&ta, a, sizeof ta);
  std::memcpy(&tb, b, sizeof tb);
  ta += tb;
  std::memcpy(r, &ta, sizeof ta);
  for (size_t k = 0; k < n; ++k) CHECK(r[k] == a[k] + b[k]);  // exact: powers of two far apart

  // Accumulated over real steps: the sums of the totals and of the stages match.
  TestWorld w(1.0 / 60.0, 9.81);
  w.addGround();
  w.addBox(Vec3(0.3, 0.3, 0.3), Vec3(0, 0, 0.3), 216.0);
  StepTimings sum;
  double total = 0, stages = 0;
  for (int step = 0; step < 10; ++step) {
    w.steps(1);
    const StepTimings t = w.sim->getTimings();
    sum += t;
    total += t.total;
    stages += t.sumOfStages();
  }
  CHECK(sum.total == doctest::Approx(total).epsilon(1e-12));
  CHECK(sum.sumOfStages() == doctest::Approx(stages).epsilon(1e-12));
}

}  // TEST_SUITE
