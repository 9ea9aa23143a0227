// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Friction anchors of contact manifolds (issue 18, solver-private; Solver::setUseFrictionAnchors,
// docs/solver-internals.md "Friction anchors").
//
// Why (DESIGN): friction rows are velocity-level rows, J v+ = 0 while sticking, with no position term. Whatever
// tangential velocity the sweeps leave in a contact that should stick (10 sweeps do not converge a pyramid of
// 20 rows) becomes tangential displacement that no later step undoes: the creep accumulates. Without the shock
// pass pyramid20 leans 78.6 cm at 10 s that way, every row slid a little relative to the one below in the
// direction the contact list's order favours. A normal row does not have this defect: SPOOK's position term
// -a g pulls its overlap back to the spring's rest.
//
// The law: when a manifold's friction starts sticking, its centre is remembered as an anchor point in the frames
// of both bodies, together with the manifold's first tangent as an anchor direction in both frames (keyed by the
// geometry pair, carried from step to step like the warm start). While it sticks, the manifold's friction rows
// (the centre tangent pair and the twist row, contact_rows.h) get the SPOOK position term of a holonomic row:
//   tangent k:  rhs += -a t_k . (p_A - p_B)       p_A, p_B the anchor points in world coordinates
//   twist:      rhs += -a phi                     phi the angle of A's anchor direction from B's about n
// with a = 4 / (h (1 + 4 tau/h)), tau the contact's damping time: the gain the normal rows use on their overlap,
// so the separation of the anchors decays like a normal row's penetration does. The rows keep their bounds
// (mu times the manifold's normal impulse; the twist's mu r_eff times it) and their viscous regularisation, so a
// contact can only hold what Coulomb allows; the position term changes only the velocity the row aims at.
//
// Slip: after the solve (storeFrictionAnchors) a manifold whose tangent pair or twist is at its Coulomb bound
// (within kAnchorSlipTolerance) and whose anchors, at the end of the step, lie more than kAnchorSlipDistance
// times its mean point radius apart is slipping: it drops its anchor, and the next step starts a new one at the
// then current centre, where the separation is 0. A new anchor adds nothing to its rows and rows at their bound
// give the bound whatever their target (the projected cone: in the same direction while the anchors' separation
// lies along the slip, as in a straight slide), so a sliding contact moves bit for bit as without anchors (slide and
// incline mu 0.5 are unchanged); a box stopping from a slide may be pulled back by at most the slip distance.
// Dropping every anchor at its bound instead was measured much worse: without the shock pass the top of
// pyramid20 rattles, nearly unloaded manifolds touch their bound every few steps and each restart lost the
// position held so far (docs/solver-internals.md "Friction anchors"). For the same reason an old anchor whose
// manifold carries no load this step is kept (the box lands where it was held); a new one is not.
// An anchor also resets when the contact has moved on either body by more than kAnchorReach times the
// manifold's mean point radius (a cylinder rolling on its side keeps its friction inside the bound while its
// contact line moves over both bodies; its material anchor points would otherwise be pulled back together).
//
// Only manifold friction (Solver::setUseManifoldFriction, contact_rows.h) is anchored: a single-point contact
// (sphere, capsule tip) rolls, and its material points leave the contact at once.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "scree/core/math.h"

namespace scree::detail {

struct SimulationState;

class FrictionAnchorCache {
 public:
  /// One manifold's anchor: its centre and its first tangent, in each body's frame (world for a side without a
  /// solver body).
  struct Anchor {
    uint64_t pair;
    Vec3 localA, localB;  ///< anchor point relative to each body's centre of mass, body frame, m
    Vec3 dirA, dirB;      ///< anchor direction (unit tangent), body frame
    bool operator<(const Anchor& o) const { return pair < o.pair; }
  };
  /// A manifold anchored in this step's rows (kept or dropped by storeFrictionAnchors).
  struct Active {
    Anchor anchor;
    int32_t t1;     ///< first tangent row (t2 = t1 + 1)
    int32_t twist;  ///< twist row
    int32_t ia, ib; ///< solver bodies (-1: world)
    Vec3 normal;
    Real rEff;      ///< the manifold's mean point radius, m
    bool isNew;     ///< anchored this step at the current centre
  };
  const Anchor* find(uint64_t pair) const {
    const Anchor key{pair, Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
    auto it = std::lower_bound(current_.begin(), current_.end(), key);
    return it != current_.end() && it->pair == pair ? &*it : nullptr;
  }
  void beginStep() { active.clear(); }
  /// The anchors of the manifolds that kept sticking become next step's cache.
  void commit(std::vector<Anchor>& kept) {
    std::sort(kept.begin(), kept.end());
    std::swap(current_, kept);
  }
  size_t size() const { return current_.size(); }
  std::vector<Active> active;  ///< this step's anchored manifolds, in row-build order
  std::vector<Anchor> scratch; ///< reused storage for commit

 private:
  std::vector<Anchor> current_;
};

/// Fraction of the Coulomb bound at which a manifold's friction counts as at its bound.
inline constexpr Real kAnchorSlipTolerance = 1e-6;
/// A manifold at its bound slips (drops its anchor) once its anchors lie farther apart than this times its mean
/// point radius (tangential separation, or twist angle times the radius).
inline constexpr Real kAnchorSlipDistance = 0.01;
/// An anchor resets when either body's anchor point lies farther than this times the manifold's mean point
/// radius from the current centre (in the tangent plane).
inline constexpr Real kAnchorReach = 0.05;

/// Row-build hook (contact_rows.cpp, manifold friction): adds the anchor's position term to the rows
/// [t1, t1 + 1] (tangents mt1, mt2) and twist (about `normal`) of the manifold of `pair` centred at `centre`, and
/// records the anchor for storeFrictionAnchors. A manifold without a kept anchor gets a new one at `centre`
/// (rows unchanged). dampingTime is the contact law's (it sets the gain a, spook.h). The record goes to `active`
/// (FrictionAnchorCache::active, or a thread's list of the parallel row build, appended to it in contact order).
void anchorManifoldFriction(SimulationState& s, uint64_t pair, int ia, int ib, const Vec3& centre,
                            const Vec3& normal, const Vec3& mt1, const Vec3& mt2, Real rEff, int32_t t1,
                            int32_t twist, Real dampingTime, std::vector<FrictionAnchorCache::Active>& active);

/// Store hook (store_results.cpp): keeps the anchors of manifolds whose friction stayed inside its bound.
void storeFrictionAnchors(SimulationState& s);

}  // namespace scree::detail
