// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The contact law (solver-private): the one place where a contact point's material and state become the
// coefficients of its normal row, for rigid contacts (contact_rows.cpp) and particle contacts
// (granular_stage.cpp) alike, plus the point Jacobian and the disc projection both contact paths share.
//
// Normal row (SPOOK, solver/include/scree/solver/spook.h): a contact is a holonomic row on the gap
// g = restOverlap - depth with compliance 1/E (E the Young's modulus of the contact, N/m per point) and damping
// time tau:   J v+ + e lambda = rhs,   rhs = -a g + Upsilon J v0,   e = 4 / (E h^2 (1 + 4 tau/h)),
// lambda in [lo, +inf). At rest this is a spring lambda/h = E * overlap. The rest overlap is 0, or the adhesive
// overlap when the contact is adhesive; then lo = -adhesiveForce h (the row may pull), else lo = 0.
//   Speculative point (depth < 0, no adhesion): rhs = depth / h, e = 0, lo = 0 -- the approach may close the
//     gap within this step and no force acts before that, so nothing tunnels.
//   Impact: an approach faster than the restitution threshold (now, or the speed remembered from last step's
//     speculative stop) gets the Newtonian target J v+ >= restitution * approach speed instead of the spring.
//     A speculative stop of a free motion faster than the threshold reports that approach speed (impactSpeed)
//     for the caller to remember, so the next step bounces with the true speed, not the clamped one.
//   maxRecoverySpeed > 0 caps the push-out speed -a g.
#pragma once

#include <algorithm>
#include <cmath>

#include "scree/core/math.h"
#include "scree/solver/constraint_row.h"
#include "scree/solver/spook.h"

namespace scree::detail {

/// Step-wide settings of the law (Solver and Simulation settings).
struct ContactLawSettings {
  Real h = 0;                    ///< time step, s
  Real restitutionThreshold = 0; ///< m/s (Solver::setRestitutionThreshold)
  Real maxRecoverySpeed = 0;     ///< m/s, 0: unlimited (Solver::setMaxPenetrationRecoverySpeed)
};

/// One contact point as the law sees it. Velocities are along the row direction J (positive: separating).
struct NormalContactState {
  Real depth = 0;            ///< m, > 0 overlap, < 0 speculative gap
  Real vn0 = 0;              ///< J v at the start of the step, m/s
  Real vnFree = 0;           ///< J v after this step's external forces (free motion), m/s
  Real rememberedImpact = 0; ///< approach speed of last step's speculative stop at this point, m/s (0: none)
  Real adhesiveForce = 0;    ///< this point's share of the adhesive force, N (> 0: adhesive; inf: unbounded)
  Real adhesiveOverlap = 0;  ///< rest overlap of an adhesive contact, m
  Real restitution = 0;
};

struct NormalRowCoefficients {
  Real rhs = 0, e = 0, lo = 0;
  Real impactSpeed = 0;  ///< approach speed of a speculative stop this step (remember it), else 0
};

/// SPOOK coefficients of a contact of Young's modulus E (N/m) and damping time tau (s).
inline SpookCoefficients contactSpook(Real h, Real youngsModulus, Real dampingTime) {
  return spookHolonomic(h, 1.0 / youngsModulus, dampingTime);
}

/// The normal row of one contact point; `spook` from contactSpook (unused for a speculative point).
inline NormalRowCoefficients contactNormalRow(const ContactLawSettings& law, const SpookCoefficients& spook,
                                              const NormalContactState& c) {
  NormalRowCoefficients r;
  const Real h = law.h;
  const Real adhF = c.adhesiveForce;
  if (c.depth < 0 && adhF <= 0) {
    r.rhs = c.depth / h;
    r.e = 0;
    r.lo = 0;
    if (c.rememberedImpact > law.restitutionThreshold) {
      // Last step closed the gap at the remembered speed: the surfaces touch now, bounce from here.
      r.rhs = std::max(r.rhs, c.restitution * c.rememberedImpact);
    } else if (c.vnFree * h < c.depth && -c.vnFree > law.restitutionThreshold) {
      // The free motion closes the gap this step: the row stops it exactly at the surface.
      r.impactSpeed = -c.vnFree;
    }
    return r;
  }
  // g is the constraint violation: negative when the overlap exceeds the rest overlap.
  const Real g = (adhF > 0 ? c.adhesiveOverlap : 0.0) - c.depth;
  Real bias = -spook.a * g;
  if (law.maxRecoverySpeed > 0) bias = std::min(bias, law.maxRecoverySpeed);
  r.rhs = bias + spook.upsilon * c.vn0;
  r.e = spook.e;
  r.lo = adhF > 0 ? (std::isinf(adhF) ? -1e300 : -adhF * h) : 0.0;
  const Real approach = std::max(c.rememberedImpact, -c.vn0);
  if (approach > law.restitutionThreshold) r.rhs = std::max(r.rhs, c.restitution * approach);
  return r;
}

/// A row along direction d through a contact point: J = [d, ra x d, -d, -(rb x d)] on bodies (a, b), where
/// ra and rb are the point relative to each body's centre of mass. Other fields are reset.
inline ConstraintRow pointRow(int32_t bodyA, int32_t bodyB, const Vec3& ra, const Vec3& rb, const Vec3& d) {
  ConstraintRow row;
  row.bodyA = bodyA;
  row.bodyB = bodyB;
  row.jLinA = d;
  row.jAngA = ra.cross(d);
  row.jLinB = -d;
  row.jAngB = -rb.cross(d);
  return row;
}

/// The Jacobian fields of pointRow written into `row`, which must be freshly value-initialised (the contact rows
/// stage resizes its row array and fills the new rows in place: building a row and copying it in would zero and
/// copy every row's 344 bytes twice more, which was a fifth of that stage on tower10). Always inlined: the
/// contact row build calls it from a large function, where GCC stopped inlining it (3 % of pyramid20's step).
[[gnu::always_inline]] inline void setPointJacobian(ConstraintRow& row, int32_t bodyA, int32_t bodyB, const Vec3& ra,
                                                   const Vec3& rb, const Vec3& d) {
  row.bodyA = bodyA;
  row.bodyB = bodyB;
  row.jLinA = d;
  row.jAngA = ra.cross(d);
  row.jLinB = -d;
  row.jAngB = -rb.cross(d);
}

/// Scales the pair (l1, l2) radially onto the disc of radius lim when it lies outside: projected-cone friction
/// (lim = mu lambda_n) and the rolling-resistance disc, in the PGS sweeps and the particle sweeps.
/// The test is on squares so that the square root is paid only when projecting (the particle sweeps call this
/// twice per contact and sweep).
inline void projectOntoDisc(Real& l1, Real& l2, Real lim) {
  const Real mag2 = l1 * l1 + l2 * l2;
  if (mag2 > lim * lim) {
    const Real mag = std::sqrt(mag2);
    const Real s = mag > 0 ? lim / mag : 0;
    l1 *= s;
    l2 *= s;
  }
}

/// mu * lambda_n, with mu = +inf meaning "no slip" (and inf * 0 not turning into NaN).
inline Real frictionLimit(Real mu, Real lambdaN) {
  if (std::isinf(mu)) return 1e300;
  return mu * std::max<Real>(lambdaN, 0);
}

}  // namespace scree::detail
