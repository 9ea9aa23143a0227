// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scree/core/parallel.h"

#ifdef SCREE_WITH_OPENMP
#include <omp.h>
#endif

namespace scree {

#ifdef SCREE_WITH_OPENMP
void setNumThreads(int n) { omp_set_num_threads(n >= 1 ? n : omp_get_num_procs()); }
int getNumThreads() { return omp_get_max_threads(); }
#else
void setNumThreads(int) {}
int getNumThreads() { return 1; }
#endif

}  // namespace scree

// ---- issue 18 (sweep scheduling): the persistent team (parallel.h; docs/solver-internals.md "Persistent team") ----
#include <chrono>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace scree::detail {

void waitAtLeast(const std::atomic<uint32_t>& a, uint32_t target) {
  uint32_t v = a.load(std::memory_order_acquire);
  for (int spin = 0; v < target && spin < teamSpinCount(); ++spin) v = a.load(std::memory_order_acquire);
  while (v < target) {
    a.wait(v, std::memory_order_acquire);
    v = a.load(std::memory_order_acquire);
  }
}

void TeamBarrier::wait() {
  const uint32_t phase = phase_.load(std::memory_order_acquire);
  if (arrived_.fetch_add(1, std::memory_order_acq_rel) + 1 == n_) {
    arrived_.store(0, std::memory_order_relaxed);
    phase_.store(phase + 1, std::memory_order_release);
    phase_.notify_all();
    return;
  }
  uint32_t v = phase_.load(std::memory_order_acquire);
  for (int spin = 0; v == phase && spin < teamSpinCount(); ++spin) v = phase_.load(std::memory_order_acquire);
  while (v == phase) {
    phase_.wait(v, std::memory_order_acquire);
    v = phase_.load(std::memory_order_acquire);
  }
}

namespace {
thread_local bool tInsideJob = false;
constexpr std::chrono::microseconds kWorkerSpin{2000};

/// The team: worker k (1-based) runs t = k of every job whose n exceeds k. A job is published by bumping
/// `generation`; each worker it involves adds one to `finished` when done.
class Team {
 public:
  ~Team() {
    {
      std::lock_guard<std::mutex> lock(use_);
      stop_ = true;
      generation_.fetch_add(1, std::memory_order_release);
      generation_.notify_all();
    }
    for (std::thread& w : workers_) w.join();
  }
  /// False when another thread uses the team (the caller then runs the job alone).
  bool run(int n, void (*job)(void*, int, int), void* ctx) {
    std::unique_lock<std::mutex> lock(use_, std::try_to_lock);
    if (!lock.owns_lock()) return false;
    while (int(workers_.size()) < n - 1) {
      const int k = int(workers_.size()) + 1;
      const uint32_t seen = generation_.load(std::memory_order_acquire);
      workers_.emplace_back([this, k, seen] { loop(k, seen); });
    }
    job_ = job;
    ctx_ = ctx;
    n_ = n;
    finished_.store(0, std::memory_order_relaxed);
    generation_.fetch_add(1, std::memory_order_release);
    generation_.notify_all();
    tInsideJob = true;
    job(ctx, 0, n);
    tInsideJob = false;
    waitAtLeast(finished_, uint32_t(n - 1));
    return true;
  }

 private:
  void loop(int k, uint32_t seen) {
    tInsideJob = true;
    for (;;) {
      // Between jobs the worker spins for up to kWorkerSpin (yielding every 256 loads, so that it gives way when
      // the machine is oversubscribed) before it sleeps. Why this long: in the KVM guest this was measured on,
      // waking a sleeping worker through the futex cost about 0.2 ms (pyramid20 partitioned, 2 threads: solve
      // stage 1.0 ms with 4000-load spins, 0.55 ms with the worker never sleeping, 0.55 ms serial); a step of a
      // small scene is about 1 ms, so the worker stays awake while steps follow each other and sleeps once the
      // program stops stepping.
      uint32_t g = generation_.load(std::memory_order_acquire);
      if (g == seen) {
        const auto until = std::chrono::steady_clock::now() + kWorkerSpin;
        for (int spin = 1; g == seen; ++spin) {
          g = generation_.load(std::memory_order_acquire);
          if (spin % 256 == 0) {
            if (std::chrono::steady_clock::now() > until) break;
            std::this_thread::yield();
          }
        }
      }
      while (g == seen) {
        generation_.wait(g, std::memory_order_acquire);
        g = generation_.load(std::memory_order_acquire);
      }
      seen = g;
      if (stop_) return;
      if (k < n_) {
        job_(ctx_, k, n_);
        finished_.fetch_add(1, std::memory_order_acq_rel);
        finished_.notify_one();
      }
    }
  }

  std::mutex use_;
  std::vector<std::thread> workers_;
  void (*job_)(void*, int, int) = nullptr;
  void* ctx_ = nullptr;
  int n_ = 0;
  bool stop_ = false;
  alignas(64) std::atomic<uint32_t> generation_{0};
  alignas(64) std::atomic<uint32_t> finished_{0};
};
}  // namespace

void runTeamJob(int n, void (*job)(void*, int, int), void* ctx) {
  if (n > 1 && !tInsideJob) {
    static Team team;
    if (team.run(n, job, ctx)) return;
  }
  job(ctx, 0, 1);  // one thread: jobs split their work by (t, n), so the result is the same
}

}  // namespace scree::detail
