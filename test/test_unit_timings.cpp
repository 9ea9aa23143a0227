// Simulation::getTimings(): the per-stage step times in milliseconds (StepTimings).
#include <doctest/doctest.h>

#include <chrono>
#include <cmath>

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

}  // TEST_SUITE
