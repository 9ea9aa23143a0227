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
#include <climits>
#include <memory>
#ifdef __linux__
#include <linux/futex.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>
#endif
#include <mutex>
#include <thread>
#include <vector>

namespace scree::detail {

namespace {
// Sleeping and waking on a 32-bit atomic (parallel.h, publish). On Linux the futex system call directly, with the
// sleep bounded; elsewhere the standard library's wait and notify (not bounded: the lost wake-up below was only seen
// on Linux, the platform CI runs on).
//
// A sleeper counts itself in `gSleepers` (a read-modify-write) before the kernel compares the value; a waker stores
// the value, then reads the count with a read-modify-write too (adding 0), and skips the system call only when
// nobody sleeps. Both read-modify-writes are in the one modification order of `gSleepers`: if the sleeper's comes
// first, the waker reads a count of at least 1 and wakes it; if the waker's comes first, the sleeper's acquires the
// waker's release, so the sleeper's load (and the kernel's compare) sees the new value and does not sleep.
// DESIGN (December 2026): the waker used to fence (`atomic_thread_fence`) and load the count. That is as correct
// (the store-buffering pattern with fences on both sides), but ThreadSanitizer does not model fences, so CI's TSan
// stage could not check this hand-off; with the read-modify-write the argument is plain happens-before, which TSan
// follows. Cost (the count's line is now written by each waker): none measurable. bench_rigid_stages, 3 rounds
// interleaved with the fence's binary, medians of 3: BM_team_barrier/2 300, 316, 110 ns against 361, 323, 104 ns;
// the partitioned pyramid20 on two threads 0.784, 0.777, 0.713 ms per step against 0.774, 0.788, 0.772 ms.
//
// The bound (parallel.h, publish): with std::atomic::wait, and then with the futex waking unconditionally,
// bench_rigid_stages BM_team_barrier still hung now and then in the KVM guest it was measured on: one thread
// asleep waiting for the barrier phase before the current one, the other one round ahead, so the wake-up of a
// queued sleeper was lost (not explained). With every sleep bounded, 14 of 14 runs passed, and a lost wake-up
// costs at most the bound. Inside a step the bound is 1 ms; the idle worker between jobs, which
// sleeps for as long as the program does not step, wakes every 20 ms to look.
std::atomic<int> gSleepers{0};

void sleepWhile(const std::atomic<uint32_t>& a, uint32_t v, long boundNs = 1000000) {
#ifdef __linux__
  // A few yields first (as libstdc++'s wait does): on two busy cores the partner often arrives within a time slice,
  // and a futex sleep and wake costs microseconds in a virtual machine.
  for (int k = 0; k < 4; ++k) {
    std::this_thread::yield();
    if (a.load(std::memory_order_acquire) != v) return;
  }
  gSleepers.fetch_add(1, std::memory_order_seq_cst);
  if (a.load(std::memory_order_seq_cst) == v) {
    const timespec bound{0, boundNs};
    syscall(SYS_futex, reinterpret_cast<const uint32_t*>(&a), FUTEX_WAIT_PRIVATE, v, &bound, nullptr, 0);
  }
  gSleepers.fetch_sub(1, std::memory_order_release);
#else
  (void)boundNs;
  a.wait(v, std::memory_order_acquire);
#endif
}
// Spins while `waiting()` holds, for at most teamSpinTime(), with the processor's spin-wait hint between loads.
// DESIGN (a time, not a count of loads; December 2026): the spin used to be 4000 loads. A load of a line held in the
// core's own cache takes about half a cycle, so 4000 loads are under a microsecond, about the time the partner
// needs to reach the barrier when both threads work. Once one thread spun out into its yields and futex sleep (a
// system call, microseconds in a KVM guest), it arrived late at the next barrier, so its partner spun out too: the
// two kept each other in the slow path. BM_team_barrier/2 measured 8.4 us per barrier while two threads
// handing a flag back and forth took 0.18 us per round trip on the same host, and stops 33 to 39 read the 8.4 us
// as the host's. Bounding the spin by time breaks the cycle: the partner of a working thread arrives within the
// bound, and a descheduled one still lets the waiter go to sleep after it.
template <class Waiting>
void spinWhile(Waiting waiting) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(teamSpinTime());
  for (uint32_t spin = 1; waiting(); ++spin) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
    if (spin % 64 == 0 && std::chrono::steady_clock::now() > until) return;
  }
}

void wakeAll(std::atomic<uint32_t>& a) {
#ifdef __linux__
  if (gSleepers.fetch_add(0, std::memory_order_acq_rel) == 0) return;
  syscall(SYS_futex, reinterpret_cast<uint32_t*>(&a), FUTEX_WAKE_PRIVATE, INT_MAX, nullptr, nullptr, 0);
#else
  a.notify_all();
#endif
}
}  // namespace

void waitAtLeast(const std::atomic<uint32_t>& a, uint32_t target) {
  uint32_t v = a.load(std::memory_order_acquire);
  if (v < target) spinWhile([&] { return (v = a.load(std::memory_order_acquire)) < target; });
  while (v < target) {
    sleepWhile(a, v);
    v = a.load(std::memory_order_acquire);
  }
}

void publish(std::atomic<uint32_t>& a, uint32_t value) {
  a.store(value, std::memory_order_release);
  wakeAll(a);
}

void publishAdd(std::atomic<uint32_t>& a, uint32_t delta) {
  a.fetch_add(delta, std::memory_order_acq_rel);
  wakeAll(a);
}

void TeamBarrier::wait() {
  const uint32_t phase = phase_.load(std::memory_order_acquire);
  if (arrived_.fetch_add(1, std::memory_order_acq_rel) + 1 == n_) {
    arrived_.store(0, std::memory_order_relaxed);
    publish(phase_, phase + 1);
    return;
  }
  uint32_t v = phase_.load(std::memory_order_acquire);
  if (v == phase) spinWhile([&] { return (v = phase_.load(std::memory_order_acquire)) == phase; });
  while (v == phase) {
    sleepWhile(phase_, v);
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
      publishAdd(generation_, 1);
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
    publishAdd(generation_, 1);
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
        sleepWhile(generation_, g, 20000000);
        g = generation_.load(std::memory_order_acquire);
      }
      seen = g;
      if (stop_) return;
      if (k < n_) {
        job_(ctx_, k, n_);
        publishAdd(finished_, 1);
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
