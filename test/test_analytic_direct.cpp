// DIRECT solver (solver/include/scree/solver/direct.h) against closed-form values and against converged PGS.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>

#include "test_world.h"

using namespace scree;

namespace {
scenes::ChainMetrics runChain(bool hanging, FrictionModel::SolveType t, Real dt, int steps, int iterations = 10) {
  scenes::Chain20Scene s = scenes::buildChain20(100.0, hanging);
  s.sim->setTimeStep(dt);
  s.sim->getSolver().setNumIterations(iterations);
  for (auto& j : s.joints) j->setSolveType(t);
  scenes::ChainObserver obs(s);
  for (int i = 0; i < steps; ++i) {
    s.sim->stepForward();
    obs.observe();
  }
  return obs.result();
}
}  // namespace

TEST_CASE("chain20 explore") {
  for (Real dt : {1.0 / 60, 1.0 / 600}) {
    int steps = int(std::lround(10.0 / dt));
    auto d = runChain(false, FrictionModel::DIRECT, dt, steps);
    auto p = runChain(false, FrictionModel::ITERATIVE, dt, steps);
    auto dh = runChain(true, FrictionModel::DIRECT, dt, steps);
    auto ph = runChain(true, FrictionModel::ITERATIVE, dt, steps);
    std::printf("dt %g released: direct max %.3e final %.3e, pgs %.3e; hanging direct %.4e pgs %.4e\n", dt,
                d.maxSeparation, d.finalSeparation, p.maxSeparation, dh.maxSeparation, ph.maxSeparation);
  }
}
