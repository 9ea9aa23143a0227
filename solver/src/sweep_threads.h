// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The thread count of the partitioned sweeps, chosen by measurement (solver-private; Solver::
// setUseAdaptiveSweepThreads, docs/solver-internals.md "Partitioned sweeps: the thread count by measurement").
//
// DESIGN (issue 18): the partitioned sweeps and shock pass give the same bits on any number of threads, so the
// count is free to change from step to step. Whether a second thread pays depends on the host more than on the
// scene: on the 2-core KVM guest this was written on, a cache line took either about 150 ns or about 550 ns to
// cross between the cores, in states that lasted hours; in the slow state pyramid20's partitioned solve took
// 0.65 ms per step on two threads against 0.43 ms on one; in the fast state two threads took about 1.1x less. A
// user who asks for two threads should never get a slower simulation for it. So the step times the span of its
// partitioned work and this class picks the count. The span runs from the contact row build (which runs on the
// same count) to the end of the store (step_stages.h beginPartitionedWork, endPartitionedWork): the serial stages
// in between, prepare, the records and the store, also pay for the data the second thread wrote (pyramid20 in
// the slow state: the store 0.018 ms on one thread, 0.043 ms after two-thread sweeps), so timing only the sweeps
// and the shock pass, as before stop 44, showed a second thread as better than it was.
//  - probe: kProbeSteps steps on every available thread (at most one per region), then kProbeSteps on one; the
//    first kSettleSteps of each block are not counted (the step that moves the work between the cores pays for
//    pulling its data over, as does a scene's first step for its allocations);
//  - the count with the lower median wins, one thread on a tie (it leaves the other core to the program);
//  - hold it for kFirstHold steps, then probe again; each probe that confirms the previous choice doubles the hold
//    up to kMaxHold, so on a host whose state does not change the probes cost less and less (at most 8 of 7680
//    steps on the slower count).
// Only the timing is adaptive: the schedule of probes is fixed by the step count, and the results never depend on
// it.
#pragma once

#include <algorithm>

namespace scree::detail {

class SweepThreadChoice {
 public:
  static constexpr int kProbeSteps = 8;   ///< steps per count in a probe
  static constexpr int kSettleSteps = 2;  ///< of those, not timed
  static constexpr int kFirstHold = 120;  ///< steps the choice is kept after a probe that changed it
  static constexpr int kMaxHold = 7680;   ///< longest hold (doubling from kFirstHold)

  /// The thread count for this step's partitioned work, given the threads available (the team's size, capped
  /// at the number of regions; values < 2 mean one thread and no probing).
  int begin(int available) {
    if (available < 2) {
      available_ = available;
      return 1;
    }
    if (available != available_) reset(available);
    switch (phase_) {
      case Phase::PROBE_MANY: return available_;
      case Phase::PROBE_ONE: return 1;
      case Phase::HOLD: break;
    }
    return chosen_;
  }

  /// Wall time (s) of this step's partitioned work, run on the count begin() returned. +infinity for a step that
  /// asked the team for more threads and ran on one (another Simulation held the team): a probe of the many
  /// then picks one thread when at least half of its timed steps did not get the team.
  void end(double seconds) {
    if (available_ < 2) return;
    switch (phase_) {
      case Phase::PROBE_MANY:
        if (step_ >= kSettleSteps) many_[step_ - kSettleSteps] = seconds;
        if (++step_ == kProbeSteps) {
          phase_ = Phase::PROBE_ONE;
          step_ = 0;
        }
        break;
      case Phase::PROBE_ONE:
        if (step_ >= kSettleSteps) one_[step_ - kSettleSteps] = seconds;
        if (++step_ == kProbeSteps) decide();
        break;
      case Phase::HOLD:
        if (++step_ >= hold_) {
          phase_ = Phase::PROBE_MANY;
          step_ = 0;
        }
        break;
    }
  }

  /// The count of the last decision (0 before the first), the current hold, and whether a probe is running.
  int chosen() const { return chosen_; }
  int hold() const { return hold_; }
  bool probing() const { return available_ >= 2 && phase_ != Phase::HOLD; }
  /// Medians of the last probe's timed steps (s) on the available threads and on one.
  double medianMany() const { return medianMany_; }
  double medianOne() const { return medianOne_; }

 private:
  enum class Phase { PROBE_MANY, PROBE_ONE, HOLD };
  static constexpr int kTimed = kProbeSteps - kSettleSteps;

  void reset(int available) {
    available_ = available;
    phase_ = Phase::PROBE_MANY;
    step_ = 0;
    chosen_ = 0;
    hold_ = kFirstHold;
  }
  static double median(double* t) {
    std::sort(t, t + kTimed);
    return kTimed % 2 ? t[kTimed / 2] : 0.5 * (t[kTimed / 2 - 1] + t[kTimed / 2]);
  }
  void decide() {
    medianMany_ = median(many_);
    medianOne_ = median(one_);
    const int choice = medianOne_ <= medianMany_ ? 1 : available_;
    hold_ = choice == chosen_ ? std::min(2 * hold_, kMaxHold) : kFirstHold;
    chosen_ = choice;
    phase_ = Phase::HOLD;
    step_ = 0;
  }

  int available_ = 0;
  Phase phase_ = Phase::PROBE_MANY;
  int step_ = 0;
  int chosen_ = 0;
  int hold_ = kFirstHold;
  double many_[kTimed] = {}, one_[kTimed] = {};
  double medianMany_ = 0, medianOne_ = 0;
};

}  // namespace scree::detail
