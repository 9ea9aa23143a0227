// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Shared by the bad-input suites (test_badinput_*.cpp): the expectation that a call throws
// std::invalid_argument whose message names the parameter and the offending value (STYLE: bad input names both,
// and the object stays unchanged -- each suite checks that part itself).
#pragma once

#include <doctest/doctest.h>

#include <initializer_list>
#include <limits>
#include <stdexcept>
#include <string>

#include <scree/core/math.h>

namespace scree::test {

inline const Real kNaN = std::numeric_limits<Real>::quiet_NaN();
inline const Real kInf = std::numeric_limits<Real>::infinity();

/// Runs f and expects std::invalid_argument whose message contains every string in `needles`.
template <class F>
void expectInvalid(F&& f, std::initializer_list<std::string> needles) {
  bool thrown = false;
  try {
    f();
  } catch (const std::invalid_argument& e) {
    thrown = true;
    const std::string what = e.what();
    for (const std::string& n : needles) {
      INFO("message: " << what << "  expected to contain: " << n);
      CHECK(what.find(n) != std::string::npos);
    }
  }
  CHECK(thrown);
}

/// The usual pair: the parameter's name and the printed value.
template <class F>
void expectInvalid(F&& f, const std::string& param, const std::string& value) {
  expectInvalid(std::forward<F>(f), {param, value});
}

}  // namespace scree::test
