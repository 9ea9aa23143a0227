// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Process CPU time for the benches that report ms of CPU per step (bench_terrain_dig, bench_rigid_stages).
// Unlike the wall clock, it does not count the time a shared machine gave to other processes; it does count every
// thread of this process, so on 2 threads it is the sum of both.
#pragma once

#include <ctime>

namespace scree::bench {

/// CPU time of the whole process (all threads), ms.
inline double cpuMs() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

}  // namespace scree::bench
