// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Exact ball–box intersection volume (model/src/sphere_box_volume): closed-form cases (whole ball, half
// spaces, caps, quarters, octants), an independent reference (slice areas in closed form integrated over z by
// adaptive Simpson), Monte Carlo, and the split pieces a voxelisation uses.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <vector>

#include "../model/src/sphere_box_volume.h"

using namespace scree;
using scree::detail::ballSplitVolumes;
using scree::detail::ballVolume;
using scree::detail::sphereBoxVolume;

namespace {

constexpr Real kPi = std::numbers::pi_v<Real>;
constexpr Real kBig = 1e3;  // "infinite" box bound, far outside every ball below

/// Area of the disc of radius rho (centre at the origin) inside [x0, x1] x [y0, y1], exact: the integrand
/// over x is piecewise y1 - y0, min(y1, w) - max(y0, -w) with w = sqrt(rho^2 - x^2); it is split at the x where
/// w crosses |y0| or |y1| and each piece integrated with the primitive of w, G(x) = (x w + rho^2 asin(x/rho))/2.
Real discRectArea(Real rho, Real x0, Real x1, Real y0, Real y1) {
  if (rho <= 0) return 0;
  x0 = std::max(x0, -rho);
  x1 = std::min(x1, rho);
  if (x0 >= x1 || y0 >= y1) return 0;
  auto w = [&](Real x) { return std::sqrt(std::max(Real(0), rho * rho - x * x)); };
  auto G = [&](Real x) { return 0.5 * (x * w(x) + rho * rho * std::asin(std::clamp(x / rho, -1.0, 1.0))); };
  std::vector<Real> cuts = {x0, x1};
  for (Real y : {y0, y1})
    if (std::abs(y) < rho)
      for (Real x : {-std::sqrt(rho * rho - y * y), std::sqrt(rho * rho - y * y)})
        if (x > x0 && x < x1) cuts.push_back(x);
  std::sort(cuts.begin(), cuts.end());
  Real area = 0;
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    const Real a = cuts[i], b = cuts[i + 1], m = 0.5 * (a + b), wm = w(m);
    // On (a, b) the top is y1 or w, the bottom y0 or -w, fixed over the piece (decided at the midpoint).
    const bool topIsW = wm < y1, bottomIsW = -wm > y0;
    if ((topIsW ? wm : y1) <= (bottomIsW ? -wm : y0)) continue;  // empty piece
    Real top = topIsW ? G(b) - G(a) : y1 * (b - a);
    Real bottom = bottomIsW ? -(G(b) - G(a)) : y0 * (b - a);
    area += top - bottom;
  }
  return area;
}

/// Adaptive Simpson on [a, b] to an absolute tolerance.
Real simpson(const std::function<Real(Real)>& f, Real a, Real b, Real fa, Real fm, Real fb, Real whole, Real tol,
             int depth) {
  const Real m = 0.5 * (a + b), lm = 0.5 * (a + m), rm = 0.5 * (m + b);
  const Real flm = f(lm), frm = f(rm);
  const Real left = (m - a) / 6 * (fa + 4 * flm + fm), right = (b - m) / 6 * (fm + 4 * frm + fb);
  if (depth <= 0 || std::abs(left + right - whole) <= 15 * tol) return left + right + (left + right - whole) / 15;
  return simpson(f, a, m, fa, flm, fm, left, tol / 2, depth - 1) + simpson(f, m, b, fm, frm, fb, right, tol / 2, depth - 1);
}

/// Reference volume: integral over z of the exact slice area, independent of the closed-form z-antiderivative.
/// The slice area changes form where the slice circle passes a box edge line or corner (rho(z) = |x_b|, |y_b|
/// or the corner distance), so the z-range is split there and each smooth piece integrated adaptively.
Real referenceVolume(Real r, const Vec3& lo, const Vec3& hi) {
  const Real z0 = std::max(lo.z(), -r), z1 = std::min(hi.z(), r);
  if (z0 >= z1) return 0;
  auto f = [&](Real z) { return discRectArea(std::sqrt(std::max(Real(0), r * r - z * z)), lo.x(), hi.x(), lo.y(), hi.y()); };
  std::vector<Real> cuts = {z0, z1, 0.0};
  for (Real x : {lo.x(), hi.x()})
    for (Real y : {lo.y(), hi.y(), 0.0})
      for (Real t2 : {x * x + y * y, y * y}) {
        if (t2 >= r * r) continue;
        const Real zc = std::sqrt(r * r - t2);
        for (Real z : {-zc, zc})
          if (z > z0 && z < z1) cuts.push_back(z);
      }
  std::sort(cuts.begin(), cuts.end());
  Real total = 0;
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    const Real a = std::max(cuts[i], z0), b = std::min(cuts[i + 1], z1);
    if (b <= a) continue;
    const Real fa = f(a), fb = f(b), fm = f(0.5 * (a + b));
    total += simpson(f, a, b, fa, fm, fb, (b - a) / 6 * (fa + 4 * fm + fb), 1e-13 * r * r * r, 40);
  }
  return total;
}

}  // namespace

TEST_SUITE("model.sphere_box_volume") {

TEST_CASE("a ball fully inside a box has volume 4/3 pi r^3") {
  for (Real r : {1e-3, 0.05, 1.0, 7.5}) {
    const Vec3 c(0.3 * r, -0.2 * r, 0.1 * r);
    const Real v = sphereBoxVolume(c, r, c - Vec3::Constant(1.5 * r), c + Vec3(1.01 * r, 2 * r, 1.2 * r));
    // The box bounds are all outside the ball, so no corner term is evaluated: exact up to one rounding.
    CHECK(v == doctest::Approx(4.0 / 3.0 * kPi * r * r * r).epsilon(1e-15));
  }
}

TEST_CASE("half spaces, caps, quarters and octants have their closed-form volumes") {
  const Real r = 0.7;
  const Vec3 c(1.0, 2.0, -3.0);
  const Real V = ballVolume(r);
  // Rounding only: a few ulp of r^3 through asin/atan2 sums of O(r^3) terms.
  const Real tol = 1e-14;
  for (int axis = 0; axis < 3; ++axis) {
    Vec3 lo = c - Vec3::Constant(kBig), hi = c + Vec3::Constant(kBig);
    lo[axis] = c[axis];
    CHECK(sphereBoxVolume(c, r, lo, hi) / V == doctest::Approx(0.5).epsilon(tol));
    // A cap of height h = r - a: pi h^2 (3 r - h) / 3, for planes on either side of the centre.
    for (Real a : {-0.6, -0.25, 0.1, 0.45, 0.69}) {
      lo[axis] = c[axis] + a;
      const Real h = r - a;
      CHECK(sphereBoxVolume(c, r, lo, hi) == doctest::Approx(kPi * h * h * (3 * r - h) / 3).epsilon(tol));
    }
  }
  for (int sign = 0; sign < 8; ++sign) {  // the eight octants about the centre
    Vec3 lo, hi;
    for (int i = 0; i < 3; ++i) {
      lo[i] = (sign >> i & 1) ? c[i] : c[i] - kBig;
      hi[i] = (sign >> i & 1) ? c[i] + kBig : c[i];
    }
    CHECK(sphereBoxVolume(c, r, lo, hi) / V == doctest::Approx(0.125).epsilon(tol));
    Vec3 hiQ = hi;
    hiQ.z() = c.z() + kBig;
    Vec3 loQ = lo;
    loQ.z() = c.z() - kBig;
    CHECK(sphereBoxVolume(c, r, loQ, hiQ) / V == doctest::Approx(0.25).epsilon(tol));
  }
  // A slab |x| < a through the centre: V - 2 caps.
  const Real a = 0.3, h = r - a;
  CHECK(sphereBoxVolume(c, r, c - Vec3(a, kBig, kBig), c + Vec3(a, kBig, kBig)) ==
        doctest::Approx(V - 2 * kPi * h * h * (3 * r - h) / 3).epsilon(tol));
  // Disjoint and empty boxes.
  CHECK(sphereBoxVolume(c, r, c + Vec3(r, -1, -1), c + Vec3(2, 1, 1)) == 0.0);
  CHECK(sphereBoxVolume(c, r, c + Vec3(0.6, 0.6, 0.6), c + Vec3(2, 2, 2)) == 0.0);  // corner outside the ball
  CHECK(sphereBoxVolume(c, r, c, c) == 0.0);
}

TEST_CASE("random boxes match an independent slice integration") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<Real> u(-1.2, 1.2), len(0.05, 1.5);
  const Real r = 1.0;
  Real worst = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const Vec3 lo(u(rng), u(rng), u(rng));
    const Vec3 hi = lo + Vec3(len(rng), len(rng), len(rng));
    const Real exact = sphereBoxVolume(Vec3::Zero(), r, lo, hi);
    const Real ref = referenceVolume(r, lo, hi);
    worst = std::max(worst, std::abs(exact - ref));
    INFO("box " << lo.transpose() << " .. " << hi.transpose());
    // Simpson is driven to 1e-13 r^3 per smooth piece (a handful of pieces); the endpoint sqrt behaviour costs
    // it some digits, so 1e-11 r^3 leaves margin while any error in the antiderivative (O(r^3)) fails.
    CHECK(std::abs(exact - ref) < 1e-11);
  }
  MESSAGE("largest |closed form - slice integration| over 60 boxes: " << worst);
}

TEST_CASE("random boxes match Monte Carlo within its standard error") {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<Real> u(-1.0, 1.0), len(0.2, 1.5);
  const Real r = 1.0;
  const int samples = 200000;
  for (int trial = 0; trial < 8; ++trial) {
    const Vec3 lo(u(rng), u(rng), u(rng));
    const Vec3 hi = lo + Vec3(len(rng), len(rng), len(rng));
    long hits = 0;
    for (int s = 0; s < samples; ++s) {
      const Vec3 p(u(rng), u(rng), u(rng));
      if (p.squaredNorm() <= 1 && (p.array() >= lo.array()).all() && (p.array() < hi.array()).all()) ++hits;
    }
    const Real frac = Real(hits) / samples;
    const Real mc = 8 * frac, sigma = 8 * std::sqrt(frac * (1 - frac) / samples);
    // 5 standard errors (plus a floor for boxes that barely touch the ball): a false alarm has p < 1e-6.
    CHECK(std::abs(sphereBoxVolume(Vec3::Zero(), r, lo, hi) - mc) < 5 * sigma + 1e-4);
  }
}

TEST_CASE("split pieces sum to the ball and equal the box volumes they stand for") {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<Real> u(-1.1, 1.1);
  const Real r = 1.0, V = ballVolume(r);
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 d(u(rng), u(rng), u(rng));
    const std::array<bool, 3> split = {trial % 2 == 0, trial % 3 != 0, trial % 5 != 0};
    const auto pieces = ballSplitVolumes(r, d, split);
    Real sum = 0;
    for (int idx = 0; idx < 8; ++idx) {
      Vec3 lo, hi;
      for (int i = 0; i < 3; ++i) {
        if (!split[i]) {  // unsplit axis: everything is "lower"
          lo[i] = (idx >> i & 1) ? kBig : -kBig;
          hi[i] = kBig;
          if (!(idx >> i & 1)) continue;
          lo[i] = hi[i] = 0;  // empty
        } else {
          lo[i] = (idx >> i & 1) ? d[i] : -kBig;
          hi[i] = (idx >> i & 1) ? kBig : d[i];
        }
      }
      const Real box = sphereBoxVolume(Vec3::Zero(), r, lo, hi);
      CHECK(pieces[idx] == doctest::Approx(box).epsilon(1e-12).scale(V));
      sum += pieces[idx];
    }
    // Inclusion–exclusion of at most 8 terms of size <= V: a few ulp of V.
    CHECK(std::abs(sum - V) < 1e-14 * V);
  }
  // The centre on a voxel corner: 1/8 each; on a face: 1/2 each.
  const auto corner = ballSplitVolumes(r, Vec3::Zero(), {true, true, true});
  for (Real p : corner) CHECK(p / V == doctest::Approx(0.125).epsilon(1e-14));
  const auto face = ballSplitVolumes(r, Vec3::Zero(), {false, true, false});
  CHECK(face[0] / V == doctest::Approx(0.5).epsilon(1e-14));
  CHECK(face[2] / V == doctest::Approx(0.5).epsilon(1e-14));
}

}  // TEST_SUITE
