// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Validation helpers for the API boundary. Every public setter validates first and only then writes, so a
// rejected call leaves the object unchanged. Messages name the function, the parameter and the value:
//   "Sphere::setRadius: radius = -1 is invalid (must be > 0)".
#pragma once

#include <cmath>
#include <charconv>
#include <stdexcept>
#include <string>
#include <string_view>

#include "scree/core/math.h"

namespace scree::detail {

/// Shortest text that reads back to the same double ("0.1", "-1e-09", "nan", "inf").
inline std::string formatValue(Real v) {
  char buf[64];
  auto res = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, res.ptr);
}
// Built with append: GCC 12 emits a false -Wrestrict warning for chained operator+ on strings here.
inline std::string formatValue(const Vec3& v) {
  std::string s("(");
  s.append(formatValue(v.x())).append(", ").append(formatValue(v.y())).append(", ").append(formatValue(v.z()));
  s.append(")");
  return s;
}
inline std::string formatValue(const Quat& q) {
  std::string s("(w=");
  s.append(formatValue(q.w())).append(", x=").append(formatValue(q.x())).append(", y=").append(formatValue(q.y()));
  s.append(", z=").append(formatValue(q.z())).append(")");
  return s;
}
inline std::string formatValue(long long v) { return std::to_string(v); }
inline std::string formatValue(const std::string& v) { return "\"" + v + "\""; }

template <class T>
[[noreturn]] void throwInvalid(std::string_view where, std::string_view param, const T& value,
                               std::string_view requirement) {
  throw std::invalid_argument(std::string(where) + ": " + std::string(param) + " = " + formatValue(value) +
                              " is invalid (" + std::string(requirement) + ")");
}

inline bool isFinite(Real v) { return std::isfinite(v); }
inline bool isFinite(const Vec3& v) { return v.allFinite(); }
inline bool isFinite(const Quat& q) { return q.coeffs().allFinite(); }
inline bool isFinite(const Mat3& m) { return m.allFinite(); }

inline void requireFinite(std::string_view where, std::string_view param, Real v) {
  if (!std::isfinite(v)) throwInvalid(where, param, v, "must be finite");
}
inline void requireFinite(std::string_view where, std::string_view param, const Vec3& v) {
  if (!v.allFinite()) throwInvalid(where, param, v, "must be finite");
}
inline void requirePositive(std::string_view where, std::string_view param, Real v) {
  if (!(std::isfinite(v) && v > 0)) throwInvalid(where, param, v, "must be finite and > 0");
}
inline void requireNonNegative(std::string_view where, std::string_view param, Real v) {
  if (!(std::isfinite(v) && v >= 0)) throwInvalid(where, param, v, "must be finite and >= 0");
}
/// Non-negative, +infinity allowed (e.g. an infinite friction coefficient or adhesive force).
inline void requireNonNegativeOrInf(std::string_view where, std::string_view param, Real v) {
  if (!(v >= 0)) throwInvalid(where, param, v, "must be >= 0 (may be infinite)");
}
inline void requireInRange(std::string_view where, std::string_view param, Real v, Real lo, Real hi) {
  if (!(std::isfinite(v) && v >= lo && v <= hi))
    throwInvalid(where, param, v, "must be in [" + formatValue(lo) + ", " + formatValue(hi) + "]");
}
/// A rotation must be finite and non-zero; it is normalised by the caller.
inline void requireRotation(std::string_view where, std::string_view param, const Quat& q) {
  if (!q.coeffs().allFinite() || q.norm() < 1e-12) throwInvalid(where, param, q, "must be a finite, non-zero quaternion");
}
inline void requireNonNull(std::string_view where, std::string_view param, const void* p) {
  if (p == nullptr) throw std::invalid_argument(std::string(where) + ": " + std::string(param) + " = null is invalid (must not be null)");
}

}  // namespace scree::detail
