// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Closed-form ball–box intersection volume (see the header for the decomposition).
//
// Derivation of the z-antiderivative. For s >= 0 let rho(z) = sqrt(r^2 - z^2), k = sqrt(r^2 - s^2) and
// q(z) = sqrt(k^2 - z^2). The term of A(rho(z)) that carries s is
//   g_s(z) = 1/2 [ rho^2 asin(s/rho) + s sqrt(rho^2 - s^2) ]     (half the area of the disc strip 0 <= x <= s).
// Integrating rho^2 asin(s/rho) by parts with d/dz asin(s/rho) = s z / (q rho^2) leaves rational integrands in
// z and q; after polynomial division they reduce to the standard integrals
//   ∫ dz/q = asin(z/k),  ∫ z^2/q dz = (k^2 asin(z/k) - z q)/2,  ∫ dz/(q (r^2 - z^2)) = atan(s z/(r q))/(r s),
// and together
//   H_s(z) = (r^2 z - z^3/3) asin(s/rho) + 2/3 s z q + s (r^2 - s^2/3) asin(z/k) - 2/3 r^3 atan2(s z, r q)
// satisfies H_s' = 2 g_s on |z| <= k. H_s is odd in z and vanishes identically for s = 0. The corner volume is
//   C(a, b, c) = [F(z)]_c^Z,  F(z) = pi/4 (r^2 z - z^3/3) + a b z - H_a(z)/2 - H_b(z)/2,
// with Z = sqrt(r^2 - a^2 - b^2); on [c, Z] the quadrant corner (a, b) stays inside the disc, where the
// formula for A holds. atan2 keeps the endpoint q = 0 (b = 0 at z = Z) finite.
#include "sphere_box_volume.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>

namespace scree::detail {
namespace {

constexpr Real kPi = std::numbers::pi_v<Real>;

Real clampUnit(Real x) { return std::clamp(x, Real(-1), Real(1)); }

/// H_s(z) of the file comment, for 0 <= s < r and |z| <= sqrt(r^2 - s^2).
Real antiderivativeH(Real r, Real s, Real z) {
  if (s == 0) return 0;
  const Real r2 = r * r;
  const Real rho = std::sqrt(std::max(Real(0), r2 - z * z));
  const Real k = std::sqrt(r2 - s * s);
  const Real q = std::sqrt(std::max(Real(0), r2 - s * s - z * z));
  return (r2 * z - z * z * z / 3) * std::asin(clampUnit(s / rho)) + Real(2) / 3 * s * z * q +
         s * (r2 - s * s / 3) * std::asin(clampUnit(z / k)) - Real(2) / 3 * r2 * r * std::atan2(s * z, r * q);
}

Real cornerF(Real r, Real a, Real b, Real z) {
  return kPi / 4 * (r * r * z - z * z * z / 3) + a * b * z - Real(0.5) * antiderivativeH(r, a, z) -
         Real(0.5) * antiderivativeH(r, b, z);
}

/// F(Z) at the top of the z-range, Z = sqrt(r^2 - a^2 - b^2) > 0, a, b >= 0. There q_a = b, q_b = a and
/// asin(a/rho) + asin(b/rho) = pi/2, so the pi/4 term cancels against the first terms of H_a and H_b and what is
/// left needs four atan2 and no asin (cheaper, and no cancellation of O(r^3) terms):
///   F(Z) = a b Z/3 - a (r^2 - a^2/3) atan2(Z, b)/2 - b (r^2 - b^2/3) atan2(Z, a)/2
///          + r^3/3 (atan2(a Z, r b) + atan2(b Z, r a)).
/// For a = b = 0 both H vanish and F(r) = pi r^3/6.
Real cornerFTop(Real r, Real a, Real b, Real zTop) {
  if (a == 0 && b == 0) return kPi / 6 * r * r * r;
  const Real r2 = r * r;
  return a * b * zTop / 3 - Real(0.5) * a * (r2 - a * a / 3) * std::atan2(zTop, b) -
         Real(0.5) * b * (r2 - b * b / 3) * std::atan2(zTop, a) +
         r2 * r / 3 * (std::atan2(a * zTop, r * b) + std::atan2(b * zTop, r * a));
}

/// Spherical cap {x >= a}, a >= 0.
Real capVolume(Real r, Real a) {
  if (a >= r) return 0;
  return kPi / 3 * (r - a) * (r - a) * (2 * r + a);
}

/// {x >= a, y >= b}, a, b >= 0.
Real wedgeVolume(Real r, Real a, Real b) {
  const Real z2 = r * r - a * a - b * b;
  if (z2 <= 0) return 0;
  return 2 * cornerFTop(r, a, b, std::sqrt(z2));  // F is odd: [F]_{-Z}^{Z} = 2 F(Z)
}

/// {x >= a, y >= b, z >= c}, a, b, c >= 0; fTop = F(Z) of the pair (a, b) when the caller has it.
Real octantCornerVolume(Real r, Real a, Real b, Real c, const Real* fTop = nullptr) {
  const Real z2 = r * r - a * a - b * b;
  if (z2 <= c * c) return 0;
  const Real top = fTop ? *fTop : cornerFTop(r, a, b, std::sqrt(z2));
  return std::max(Real(0), top - cornerF(r, a, b, c));
}

/// Corner volume for n nonnegative thresholds t[0..n) (the ball is symmetric under axis permutations, so only
/// the values matter).
Real nonnegCorner(Real r, const Real* t, int n) {
  switch (n) {
    case 0: return ballVolume(r);
    case 1: return capVolume(r, t[0]);
    case 2: return wedgeVolume(r, t[0], t[1]);
    default: return octantCornerVolume(r, t[0], t[1], t[2]);
  }
}

/// Corner volume for n thresholds of any sign: a threshold <= -r constrains nothing, one >= r empties the
/// region, a negative one is reflected: {x >= t} = all - mirror{x >= -t} (the plane itself has measure 0).
Real signedCorner(Real r, const Real* t, int n) {
  Real kept[3];
  int m = 0;
  for (int i = 0; i < n; ++i) {
    if (t[i] >= r) return 0;
    if (t[i] > -r) kept[m++] = t[i];
  }
  for (int i = 0; i < m; ++i) {
    if (kept[i] < 0) {
      Real without[3], flipped[3];
      int w = 0;
      for (int j = 0; j < m; ++j) {
        if (j != i) without[w++] = kept[j];
        flipped[j] = (j == i) ? -kept[j] : kept[j];
      }
      return signedCorner(r, without, w) - signedCorner(r, flipped, m);
    }
  }
  return nonnegCorner(r, kept, m);
}

}  // namespace

Real ballCornerVolume(Real r, const Vec3& t, const std::array<bool, 3>& has) {
  Real v[3];
  int n = 0;
  for (int i = 0; i < 3; ++i)
    if (has[i]) v[n++] = t[i];
  return std::max(Real(0), signedCorner(r, v, n));
}

Real sphereBoxVolume(const Vec3& centre, Real r, const Vec3& lo, const Vec3& hi) {
  const Vec3 l = lo - centre, h = hi - centre;
  for (int i = 0; i < 3; ++i)
    if (!(l[i] < h[i]) || l[i] >= r || h[i] <= -r) return 0;
  // 1[l <= x < h] = 1[x >= l] - 1[x >= h]; a bound outside the ball drops its term.
  Real total = 0;
  for (int mask = 0; mask < 8; ++mask) {
    Real t[3];
    int n = 0;
    int sign = 1;
    bool skip = false;
    for (int i = 0; i < 3 && !skip; ++i) {
      if (mask & (1 << i)) {  // the "-1[x >= h]" term
        if (h[i] >= r) skip = true;
        t[n++] = h[i];
        sign = -sign;
      } else if (l[i] > -r) {
        t[n++] = l[i];
      }
    }
    if (!skip) total += sign * signedCorner(r, t, n);
  }
  return std::clamp(total, Real(0), ballVolume(r));
}

std::array<Real, 8> ballSplitVolumes(Real r, const Vec3& d, const std::array<bool, 3>& split) {
  // Axes that are really cut (a plane at |d| >= r leaves the ball on one side).
  int axes[3];
  Real alpha[3];
  int k = 0;
  unsigned farIsUpper = 0;   // bit i: the far side (not holding the centre) of axis i is x_i >= d_i
  unsigned wholeUpper = 0;   // bit i: an uncut axis whose ball lies entirely on the upper side
  for (int i = 0; i < 3; ++i) {
    if (!split[i]) continue;
    if (d[i] >= r) continue;                       // ball entirely below the plane
    if (d[i] <= -r) { wholeUpper |= 1u << i; continue; }  // entirely above
    axes[k] = i;
    alpha[k] = std::abs(d[i]);
    if (d[i] >= 0) farIsUpper |= 1u << i;
    ++k;
  }
  // Corner volumes C(S) for every subset S of the cut axes (nonnegative offsets).
  // With three cuts the octant corner reuses F(Z) of the wedge of axes 0 and 1 (subset 0b011).
  Real corner[8];
  Real fTop01 = 0;
  bool haveTop01 = false;
  for (unsigned s = 0; s < (1u << k); ++s) {
    Real t[3];
    int n = 0;
    for (int j = 0; j < k; ++j)
      if (s & (1u << j)) t[n++] = alpha[j];
    if (n == 2) {
      const Real z2 = r * r - t[0] * t[0] - t[1] * t[1];
      Real top = 0;
      if (z2 > 0) top = cornerFTop(r, t[0], t[1], std::sqrt(z2));
      if (s == 3u) { fTop01 = top; haveTop01 = true; }
      corner[s] = 2 * top;
    } else if (n == 3 && haveTop01) {
      corner[s] = octantCornerVolume(r, t[0], t[1], t[2], &fTop01);
    } else {
      corner[s] = nonnegCorner(r, t, n);
    }
  }
  std::array<Real, 8> pieces{};
  const unsigned all = (1u << k) - 1;
  for (unsigned far = 0; far <= all; ++far) {
    // piece(far) = sum over T ⊆ near of (-1)^|T| C(far ∪ T)
    const unsigned nearSet = all & ~far;
    Real v = 0;
    for (unsigned t = nearSet;; t = (t - 1) & nearSet) {
      const int bits = std::popcount(t);
      v += (bits & 1) ? -corner[far | t] : corner[far | t];
      if (t == 0) break;
    }
    unsigned index = wholeUpper;
    for (int j = 0; j < k; ++j) {
      const bool isFar = far & (1u << j);
      const bool upper = isFar == bool(farIsUpper & (1u << axes[j]));
      if (upper) index |= 1u << axes[j];
    }
    pieces[index] = std::max(Real(0), v);
  }
  return pieces;
}

}  // namespace scree::detail
