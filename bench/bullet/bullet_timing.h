// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Shared by the Bullet side-by-side benches (bench_bullet_granular.cpp, bench_bullet_scenes.cpp): per-step
// wall-clock timing of a run, so both binaries report Scree and Bullet the same way.
#pragma once

#include <algorithm>
#include <chrono>
#include <utility>
#include <vector>

namespace scree::bench {

// Times `steps` calls of step(), returns {median, mean} in ms.
template <class Step>
std::pair<double, double> timeRun(int steps, Step&& step) {
  std::vector<double> ms;
  ms.reserve(size_t(steps));
  for (int i = 0; i < steps; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    step();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  double mean = 0;
  for (double x : ms) mean += x / double(ms.size());
  std::nth_element(ms.begin(), ms.begin() + long(ms.size() / 2), ms.end());
  return {ms[ms.size() / 2], mean};
}

}  // namespace scree::bench
