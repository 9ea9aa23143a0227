// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Per-step overhead of the pipeline: an empty simulation and one box resting on the ground. Small; run in CI.
#include "overhead_fixtures.h"

BENCHMARK_MAIN();
