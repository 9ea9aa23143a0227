// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// SPOOK regularisation (Lacoursiere 2007), the one place where material/constraint parameters map to the
// row coefficients. With time step h, compliance eps and damping time tau (d = tau/h):
//   a = 4/(h(1+4d)),  Upsilon = 1/(1+4d),  e = 4 eps/(h^2 (1+4d))          (holonomic rows: joints, normals)
// and the row equation  G v+ + a g - Upsilon G v + e lambda = 0  (lambda an impulse, N s).
// At rest this gives lambda/h = -g/eps: a spring of stiffness 1/eps, damped over ~tau.
// Velocity-level rows (friction, motors) have no g; their regularisation is e = eps/h, eps a viscous
// compliance (m/s per N).
//
// Contact normals: eps = 1/(Young's modulus of the contact, N/m per point), tau = contact damping time.
// Constraint defaults (AGX): compliance 1e-8, damping time 2/60 s. A user stiffness K and damping coefficient
// D map to eps = 1/K, tau = D/K.
#pragma once

#include <algorithm>

#include "scree/core/math.h"

namespace scree {

struct SpookDefaults {
  static constexpr Real compliance = 1e-8;
  static constexpr Real damping = 2.0 / 60.0;
};

struct SpookCoefficients {
  Real a;        ///< position-error gain, 1/s
  Real upsilon;  ///< velocity carry-over factor
  Real e;        ///< regularisation added to the Schur diagonal (impulse units)
};

/// Holonomic row. tau is clamped below at 0: d = 0 gives a = 4/h, Upsilon = 1.
inline SpookCoefficients spookHolonomic(Real h, Real compliance, Real dampingTime) {
  const Real d = std::max<Real>(dampingTime, 0) / h;
  const Real k = 1.0 / (1.0 + 4.0 * d);
  return {4.0 * k / h, k, 4.0 * compliance * k / (h * h)};
}

/// Velocity-level row.
inline Real spookVelocityRegularisation(Real h, Real compliance) { return compliance / h; }

}  // namespace scree
