// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Scree core math: Eigen aliases and the rigid transform used everywhere.
// Units are SI; the world is z-up.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace scree {

using Real = double;
using Vec3 = Eigen::Matrix<Real, 3, 1>;
using Vec2 = Eigen::Matrix<Real, 2, 1>;
using Quat = Eigen::Quaternion<Real>;
using Mat3 = Eigen::Matrix<Real, 3, 3>;

/// Rigid transform x_world = q * x_local + p.
struct Transform {
  Vec3 p = Vec3::Zero();
  Quat q = Quat::Identity();

  Vec3 apply(const Vec3& x) const { return q * x + p; }
  Vec3 applyInverse(const Vec3& x) const { return q.conjugate() * (x - p); }
  Vec3 rotate(const Vec3& v) const { return q * v; }
  Vec3 rotateInverse(const Vec3& v) const { return q.conjugate() * v; }
  Transform operator*(const Transform& o) const { return {q * o.p + p, q * o.q}; }
  Transform inverse() const {
    Quat qi = q.conjugate();
    return {-(qi * p), qi};
  }
};

/// Axis-aligned bounding box in world coordinates. An empty box has lo > hi.
struct Aabb {
  Vec3 lo = Vec3::Constant(1e300);
  Vec3 hi = Vec3::Constant(-1e300);

  bool overlaps(const Aabb& o) const {
    return lo.x() <= o.hi.x() && o.lo.x() <= hi.x() && lo.y() <= o.hi.y() && o.lo.y() <= hi.y() &&
           lo.z() <= o.hi.z() && o.lo.z() <= hi.z();
  }
  void expand(const Vec3& x) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  void inflate(Real r) {
    lo.array() -= r;
    hi.array() += r;
  }
  Vec3 extent() const { return hi - lo; }
};

/// Skew-symmetric cross-product matrix: skew(a) * b == a.cross(b).
inline Mat3 skew(const Vec3& a) {
  Mat3 m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

/// Two unit vectors orthogonal to unit n and to each other (right-handed: t1 x t2 = n).
inline void orthonormalBasis(const Vec3& n, Vec3& outT1, Vec3& outT2) {
  // Pixar's branchless construction (Duff et al. 2017), continuous except at n.z = -1.
  const Real s = n.z() >= 0 ? 1.0 : -1.0;
  const Real a = -1.0 / (s + n.z());
  const Real b = n.x() * n.y() * a;
  outT1 = Vec3(1 + s * n.x() * n.x() * a, s * b, -s * n.x());
  outT2 = Vec3(b, s + n.y() * n.y() * a, -n.y());
}

}  // namespace scree
