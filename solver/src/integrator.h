// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Position/orientation update after the velocity solve (solver-private).
//
// Translation: symplectic Euler, x += h v+ (so free fall follows x_n = x_0 + n h v_0 + h^2 g n(n+1)/2 exactly).
//
// Rotation: an angular-momentum-conserving splitting. After the solve the body has world angular momentum
// L = I_w(q) w+. The torque-free rotation over h is integrated with the symmetric Lie-Poisson splitting of
// the free rigid body Hamiltonian H = sum_k L_k^2/(2 I_k) (McLachlan 1993; Touma & Wisdom 1994; Dullweber,
// Leimkuhler & McLachlan 1997): five exact rotations about the principal axes, k = 1, 2, 3, 2, 1 with steps
// h/2, h/2, h, h/2, h/2. Each keeps L fixed in the world, so |L| is conserved to round-off; the scheme is
// symplectic and time-reversible, so the kinetic energy does not drift (it oscillates by O(h^2)). The new
// angular velocity is w = I_w(q+)^-1 L: the gyroscopic term is thereby handled inside the position update,
// not as an explicit torque (explicit gyroscopic torques make energy grow). A final projection puts L back on
// the energy ellipsoid of the start of the update, so free rotation conserves |L| and kinetic energy to
// round-off. For bodies with equal principal moments this reduces to q+ = exp(h w) q.
#pragma once

#include "body_access.h"

namespace scree::detail {

inline Quat expRotation(const Vec3& w, Real h) {
  const Real angle = w.norm() * h;
  if (angle < 1e-300) return Quat::Identity();
  return Quat(Eigen::AngleAxis<Real>(angle, w / w.norm()));
}

/// Advances the orientation of a dynamic body by h with the L-conserving splitting; updates w accordingly.
inline void integrateRotation(RigidBody& b, Real h) {
  Quat& q = BodyAccess::rotation(b);
  Vec3& w = BodyAccess::angularVelocity(b);
  const Vec3& I = BodyAccess::principalMoments(b);
  const Real spread = I.maxCoeff() - I.minCoeff();
  if (spread <= 1e-12 * I.maxCoeff()) {
    q = (expRotation(w, h) * q).normalized();
    return;
  }
  // Principal frame in the world: qp maps principal coordinates to world.
  Quat qp = q * BodyAccess::principalFrame(b);
  // Body-principal components of L.
  Vec3 Lp = qp.conjugate() * w;  // principal-frame angular velocity
  Lp = Lp.cwiseProduct(I);
  const Real T0 = 0.5 * Lp.cwiseProduct(Lp).cwiseQuotient(I).sum();
  static constexpr int axes[5] = {0, 1, 2, 1, 0};
  static constexpr Real frac[5] = {0.5, 0.5, 1.0, 0.5, 0.5};
  for (int s = 0; s < 5; ++s) {
    const int k = axes[s];
    const Real theta = frac[s] * h * Lp[k] / I[k];
    // The body turns by theta about its own principal axis k; L (fixed in the world) turns by -theta
    // in principal coordinates. One sine and cosine of the half angle serve both: the turn's quaternion is
    // (cos theta/2, sin theta/2 e_k), and cos theta = 1 - 2 sin^2 theta/2, sin theta = 2 sin theta/2 cos theta/2
    // (issue 18: the two angles' sin and cos and the general quaternion product were 10 % of the step of
    // `scree run chain20`, perf).
    const Real sh = std::sin(0.5 * theta), ch = std::cos(0.5 * theta);
    const Real c = 1 - 2 * sh * sh, sn = 2 * sh * ch;
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const Real li = Lp[i], lj = Lp[j];
    Lp[i] = c * li + sn * lj;
    Lp[j] = -sn * li + c * lj;
    // qp (w, v) times (ch, sh e_k): w ch - v_k sh, and ch v + w sh e_k + sh v x e_k, where v x e_k has
    // v_j at i, -v_i at j and 0 at k.
    const Real qw = qp.w(), vi = qp.vec()[i], vj = qp.vec()[j], vk = qp.vec()[k];
    qp.w() = qw * ch - vk * sh;
    qp.vec()[k] = vk * ch + qw * sh;
    qp.vec()[i] = vi * ch + vj * sh;
    qp.vec()[j] = vj * ch - vi * sh;
  }
  // Energy projection: the splitting conserves |L| exactly but the energy only to O(h^2). Move L (principal
  // coordinates) on its sphere |L| = const to the ellipsoid sum L_k^2 / (2 I_k) = T0 with Newton steps along the
  // sphere-tangent gradient, then turn the body so that the corrected L still maps to the same world vector.
  // The correction is O(h^2) small; both invariants of free rotation then hold to round-off.
  const Real L2 = Lp.squaredNorm();
  Vec3 Lc = Lp;
  for (int it = 0; it < 3 && L2 > 0; ++it) {
    const Real T = 0.5 * Lc.cwiseProduct(Lc).cwiseQuotient(I).sum();
    const Vec3 grad = Lc.cwiseQuotient(I);
    const Vec3 d = grad - (grad.dot(Lc) / L2) * Lc;
    const Real slope = grad.dot(d);
    if (!(slope > 1e-300) || std::abs(T - T0) <= 1e-15 * T0) break;
    Lc -= ((T - T0) / slope) * d;
    Lc *= std::sqrt(L2 / Lc.squaredNorm());
  }
  if (L2 > 0 && (Lc - Lp).squaredNorm() > 0) {
    qp = qp * Quat::FromTwoVectors(Lc, Lp);
    Lp = Lc;
  }
  qp.normalize();
  q = (qp * BodyAccess::principalFrame(b).conjugate()).normalized();
  w = qp * Lp.cwiseQuotient(I);
}

}  // namespace scree::detail
