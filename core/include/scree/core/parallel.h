// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Thread control for Scree's parallel stages (OpenMP when built with SCREE_WITH_OPENMP, serial otherwise).
// Parallel stages are written so that their results do not depend on the number of threads (work split into
// fixed chunks, per-chunk outputs merged in chunk order; the particle solver sweeps even spatial slabs, then odd
// ones, slabs of one parity sharing no particle; with Solver::setUsePartitionedSweeps, the rigid narrowphase in
// fixed chunks of candidate pairs and the rigid sweeps in two regions sharing no body, docs/solver-internals.md
// "Partitioned sweeps"): setNumThreads changes speed, not results.
#pragma once

namespace scree {

/// Threads used by the parallel stages (>= 1; values < 1 select the OpenMP default). Without OpenMP a no-op.
void setNumThreads(int n);
/// Threads the parallel stages will use (1 without OpenMP).
int getNumThreads();

}  // namespace scree
