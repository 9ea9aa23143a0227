// Solver settings and per-step statistics (AGX: agx::Solver / agx::DynamicsSystem's solver knobs).
#pragma once

#include <cstddef>

#include "scree/core/math.h"

namespace scree {

struct SolverStats {
  size_t numBodies = 0;      ///< dynamic bodies in the solve
  size_t numContacts = 0;    ///< geometry contacts solved
  size_t numContactPoints = 0;
  size_t numRows = 0;        ///< constraint rows (normals + friction + joints)
  size_t numIterations = 0;
  size_t numWarmStarted = 0; ///< contact points matched to last step's impulses
  Real lastResidual = 0;     ///< max |delta lambda| of the last PGS sweep, N s
};

class Solver {
 public:
  /// PGS sweeps per step, >= 1. Default 16.
  void setNumIterations(int n);
  int getNumIterations() const { return iterations_; }
  /// Reuse last step's impulses of matched contact points (default on).
  void setUseWarmStarting(bool on) { warm_ = on; }
  bool getUseWarmStarting() const { return warm_; }
  /// Approach speed above which a contact gets the restitution (impact) treatment, m/s, >= 0. Default 0.2.
  void setRestitutionThreshold(Real v);
  Real getRestitutionThreshold() const { return restitutionThreshold_; }
  /// Largest speed a penetrating contact may push out at, m/s (0: unlimited). Default 0: SPOOK's damping
  /// already limits the push-out.
  void setMaxPenetrationRecoverySpeed(Real v);
  Real getMaxPenetrationRecoverySpeed() const { return maxRecovery_; }
  /// Shock propagation after the PGS sweeps (default on, see PgsSolver::shockPass): contacts between bodies of
  /// different support levels are solved once more from the static ground upwards with the supporting
  /// (lower) body held immovable, so stacks and heavy-on-light supports hold at low iteration counts. It gives
  /// up exact momentum exchange between the two bodies in that pass (the support does not feel the reaction);
  /// switch it off for the plain PGS result.
  void setUseShockPropagation(bool on) { shock_ = on; }
  bool getUseShockPropagation() const { return shock_; }
  /// Largest number of sweeps per support level in the shock pass, >= 1. Default 16.
  void setNumShockIterations(int n);
  int getNumShockIterations() const { return shockIterations_; }
  const SolverStats& getStats() const { return stats_; }
  SolverStats& stats() { return stats_; }

 private:
  int iterations_ = 16;
  bool warm_ = true;
  Real restitutionThreshold_ = 0.2;
  Real maxRecovery_ = 0;
  bool shock_ = true;
  int shockIterations_ = 16;
  SolverStats stats_;
};

}  // namespace scree
