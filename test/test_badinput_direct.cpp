// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Bad input for the DIRECT solver's settings: std::invalid_argument naming the parameter and the value, the
// solver unchanged.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

#include <scree/scree.h>
#include <scree/solver/direct.h>

#include "test_badinput.h"
#include "test_build.h"

using namespace scree;
using namespace scree::test;
using scree::detail::ConstraintRow;
using scree::detail::DirectSolver;
using scree::detail::SolverBodyState;

TEST_CASE("Solver: pivot cap and hybrid rounds must be >= 1") {
  Solver s;
  s.setMaxPivots(7);
  s.setNumHybridRounds(3);
  expectInvalid([&] { s.setMaxPivots(0); }, "maxPivots", "0");
  expectInvalid([&] { s.setMaxPivots(-5); }, "maxPivots", "-5");
  expectInvalid([&] { s.setNumHybridRounds(0); }, "numHybridRounds", "0");
  CHECK(s.getMaxPivots() == 7);
  CHECK(s.getNumHybridRounds() == 3);
}

TEST_CASE("Solver: position projection iterations >= 1, tolerance > 0 and finite, error threshold > 0") {
  Solver s;
  s.setNumProjectionIterations(5);
  s.setPositionProjectionTolerance(1e-4);
  expectInvalid([&] { s.setNumProjectionIterations(0); }, "numProjectionIterations", "0");
  expectInvalid([&] { s.setPositionProjectionTolerance(0); }, "tolerance", "0");
  expectInvalid([&] { s.setPositionProjectionTolerance(-1); }, "tolerance", "-1");
  expectInvalid([&] { s.setPositionProjectionTolerance(std::nan("")); }, "tolerance", "nan");
  s.setConstraintErrorThreshold(0.5);
  s.setConstraintErrorThreshold(std::numeric_limits<Real>::infinity());  // off
  expectInvalid([&] { s.setConstraintErrorThreshold(0); }, "threshold", "0");
  expectInvalid([&] { s.setConstraintErrorThreshold(std::nan("")); }, "threshold", "nan");
  CHECK(std::isinf(s.getConstraintErrorThreshold()));
  CHECK(s.getNumProjectionIterations() == 5);
  CHECK(s.getPositionProjectionTolerance() == 1e-4);
}

TEST_CASE("DirectSolver: an empty set is a no-op") {
  DirectSolver d;
  std::vector<ConstraintRow> rows(2);
  std::vector<SolverBodyState> bodies(1);
  const auto r = d.solve(rows, {}, bodies, DirectSolver::Settings{});
  CHECK(r.factorisations == 0);
  // Without SuiteSparse solve() reports converged = false for any set (direct.h); available() says which.
  CHECK(DirectSolver::available() == test::kHasDirectSolver);
  CHECK(r.converged == test::kHasDirectSolver);
}
