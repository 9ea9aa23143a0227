// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Exact volume of the intersection of a ball with an axis-aligned box, in closed form.
//
// Used by GranularFieldPostProcessor: a particle's weight in a voxel is the fraction of its volume inside the
// voxel. Everything here is in the ball's own frame (centre at the origin, radius r > 0).
//
// Building block: the "corner" volume C(a, b, c) = |{ |p| <= r, x >= a, y >= b, z >= c }| for a, b, c >= 0
// (a constraint may also be absent). With A(rho) the area of the disc of radius rho in the quadrant
// {x >= a, y >= b} (corner inside the disc),
//   A(rho) = rho^2/2 (pi/2 - asin(a/rho) - asin(b/rho)) - a/2 sqrt(rho^2-a^2) - b/2 sqrt(rho^2-b^2) + a b,
// and C = integral of A(sqrt(r^2 - z^2)) dz over z from c to Z = sqrt(r^2 - a^2 - b^2). The z-integral is done
// in closed form (see sphere_box_volume.cpp for the antiderivative and its derivation), so the result is exact
// up to floating-point rounding (a few ulp of r^3 away from tangency).
// A negative threshold is removed by reflection: {x >= -t} = everything minus the mirror image of {x >= t}.
// A box is the inclusion–exclusion of its eight corners.
#pragma once

#include <array>

#include "scree/core/math.h"

namespace scree::detail {

/// Volume of the ball of radius r, m^3.
inline Real ballVolume(Real r) { return Real(4) / 3 * Real(3.14159265358979323846) * r * r * r; }

/// |{ |p| <= r, p_i >= t_i for the axes i where has[i] }|. Any sign of t; absent axes are unconstrained.
Real ballCornerVolume(Real r, const Vec3& t, const std::array<bool, 3>& has);

/// Exact volume of ball(centre, r) ∩ [lo, hi] (axis-aligned box, lo <= hi componentwise; infinite bounds
/// allowed). Returns 0 for an empty box.
Real sphereBoxVolume(const Vec3& centre, Real r, const Vec3& lo, const Vec3& hi);

/// The pieces of a ball cut by at most one plane per axis. The plane on axis i is x_i = d[i] (ball frame) where
/// split[i]; an axis without a plane is not cut. Piece index bits: bit i = 1 means the side x_i >= d[i]
/// ("upper"), 0 the side x_i < d[i]. Pieces whose bit is set on an unsplit axis are 0 (that axis has one side
/// only, reported as "lower"). The eight volumes sum to the ball volume up to rounding; they are built from the
/// corner volumes of the nonnegative offsets |d| by inclusion–exclusion (2^k corner evaluations for k cuts).
std::array<Real, 8> ballSplitVolumes(Real r, const Vec3& d, const std::array<bool, 3>& split);

}  // namespace scree::detail
