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

// ---- issue 18 (sweep scheduling): a persistent team of threads (core/src/parallel.cpp;
// docs/solver-internals.md "Partitioned sweeps", "Persistent team") ----
#include <atomic>
#include <cstdint>
#include <type_traits>

namespace scree::detail {

/// Runs `job(ctx, t, n)` for t = 0 .. n-1 at once, t = 0 on the calling thread, the others on threads of a team
/// kept for the life of the process (created on first use, joined at exit); returns when every t is done.
///
/// DESIGN (why not `#pragma omp parallel`): libgomp's fork and join spin for GOMP_SPINCOUNT loads (by default
/// tens of milliseconds' worth) before sleeping; with more runnable threads than cores, a spinning thread holds the
/// core its partner needs, and the partitioned pyramid20 step took 10-35 ms on two threads instead of 1.5 ms on
/// one. Between jobs a worker spins for up to 2 ms, yielding every 256 loads (waking a sleeping worker through the
/// futex cost about 0.2 ms in the KVM guest this was measured on, more than half the parallel work of a small
/// scene's step), then sleeps on a futex for at most 20 ms at a time (see publish); the caller, the barrier and
/// waitAtLeast spin for `teamSpinTime()` microseconds, yield 4 times, then sleep for at most 1 ms at a time. A
/// fork-join to a spinning worker costs about 0.5 us (bench_rigid_stages BM_team_fork_join).
/// Called from inside a job, or while another thread of the program uses the team, the job runs once on the
/// calling thread as job(ctx, 0, 1): a job must split its work by (t, n) and give the same result for any n (the
/// partitioned sweeps do), and must not wait for a partner when n is 1.
void runTeamJob(int n, void (*job)(void*, int, int), void* ctx);

/// runTeamJob with a callable `f(t, n)`.
template <class F>
void runTeam(int n, F&& f) {
  using Fn = std::remove_reference_t<F>;
  runTeamJob(n, [](void* c, int t, int nt) { (*static_cast<Fn*>(c))(t, nt); }, const_cast<void*>(static_cast<const void*>(&f)));
}

/// Microseconds a waiting thread spins before it yields and sleeps (TeamBarrier, waitAtLeast; core/src/parallel.cpp,
/// spinWhile, says why a time and not a count of loads).
constexpr int teamSpinTime() { return 50; }

/// Waits until `a` holds at least `target`: spins for teamSpinTime() microseconds, yields 4 times, then sleeps on the
/// atomic for at most 1 ms at a time (see publish).
void waitAtLeast(const std::atomic<uint32_t>& a, uint32_t target);

/// Stores `value` into `a` and wakes every thread sleeping on `a` (waitAtLeast, TeamBarrier, the team). Every
/// store that a sleeping thread waits for goes through this (or publishAdd), never a bare store and notify.
///
/// DESIGN (a lost wake-up, found in December 2026): bench_rigid_stages BM_team_barrier hung in 3 of 13 runs in a
/// KVM guest: both threads asleep in TeamBarrier::wait, one of them waiting for the phase before the
/// current one, so its wake-up had been lost. Two fixes were measured and did not cure it: a sequentially
/// consistent fence between the store and std::atomic::notify_all (libstdc++ 12 skips the wake when its count of
/// sleepers reads zero, and the plain store and load around that check may be reordered on x86), and the futex
/// system call directly with an unconditional wake (1 run in 12 still hung). The cause is not known. What holds
/// is a bound on every sleep (core/src/parallel.cpp, sleepWhile: 1 ms inside a step, 20 ms for the idle worker),
/// after which the sleeper looks at the value again: 14 of 14 runs passed, and test_unit_coloured_sweeps makes a
/// lost wake-up certain and checks that the waiter still returns.
void publish(std::atomic<uint32_t>& a, uint32_t value);
/// Adds `delta` to `a` and wakes every thread sleeping on `a`.
void publishAdd(std::atomic<uint32_t>& a, uint32_t delta);

/// A reusable barrier for a team of n threads (phase counting), spinning then sleeping like the team.
class TeamBarrier {
 public:
  explicit TeamBarrier(int n) : n_(uint32_t(n)) {}
  void wait();

 private:
  const uint32_t n_;
  alignas(64) std::atomic<uint32_t> arrived_{0};
  alignas(64) std::atomic<uint32_t> phase_{0};
};

}  // namespace scree::detail
