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
