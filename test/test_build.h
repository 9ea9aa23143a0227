// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// What this build of Scree contains, for tests of an optional part (the DIRECT solver).
//
// CMake option SCREE_WITH_SUITESPARSE (default ON) builds the DIRECT solver on CHOLMOD and sets the compile
// definition of the same name on the solver library, publicly, so it reaches every test. Without it, rows whose
// solve type is DIRECT, SPLIT or DIRECT_AND_ITERATIVE are solved by PGS (with one logged warning), so a test of
// the direct solver's own results cannot hold there: such a test case carries `* test::needsDirectSolver()`
// (doctest reports it as skipped), and a case that compares solve types runs only the ones the build has.
#pragma once

#include <vector>

#include <doctest/doctest.h>

#include <scree/scree.h>

namespace scree::test {

#ifdef SCREE_WITH_SUITESPARSE
inline constexpr bool kHasDirectSolver = true;
#else
inline constexpr bool kHasDirectSolver = false;
#endif

/// TEST_CASE decorator: skip the case when the build has no DIRECT solver.
inline doctest::skip needsDirectSolver() { return doctest::skip(!kHasDirectSolver); }

/// `types` without the non-iterative solve types when the build has no DIRECT solver (they would run as PGS and
/// duplicate the ITERATIVE case under a wrong name).
inline std::vector<FrictionModel::SolveType> availableSolveTypes(std::vector<FrictionModel::SolveType> types) {
  if (kHasDirectSolver) return types;
  std::vector<FrictionModel::SolveType> out;
  for (auto t : types)
    if (t == FrictionModel::ITERATIVE) out.push_back(t);
  return out;
}

}  // namespace scree::test
