// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Filters for ContactEventListener (AGX: agxSDK::GeometryFilter, RigidBodyFilter, ExecuteFilter).
// A listener with a filter hears only about pairs the filter matches.
#pragma once

#include <string>

#include "scree/collide/geometry.h"
#include "scree/core/listeners.h"

namespace scree {

/// Matches pairs that include g0 (and g1, when given) in either order.
class GeometryFilter : public ExecuteFilter {
 public:
  explicit GeometryFilter(const Geometry* g0, const Geometry* g1 = nullptr) : g0_(g0), g1_(g1) {}
  bool match(const Geometry* a, const Geometry* b) const override {
    if (!g1_) return a == g0_ || b == g0_;
    return (a == g0_ && b == g1_) || (a == g1_ && b == g0_);
  }

 private:
  const Geometry* g0_;
  const Geometry* g1_;
};

/// Matches pairs where one geometry belongs to body b0 (and the other to b1, when given).
class RigidBodyFilter : public ExecuteFilter {
 public:
  explicit RigidBodyFilter(const RigidBody* b0, const RigidBody* b1 = nullptr) : b0_(b0), b1_(b1) {}
  bool match(const Geometry* a, const Geometry* b) const override {
    const RigidBody* ba = a->getRigidBody();
    const RigidBody* bb = b->getRigidBody();
    if (!b1_) return ba == b0_ || bb == b0_;
    return (ba == b0_ && bb == b1_) || (ba == b1_ && bb == b0_);
  }

 private:
  const RigidBody* b0_;
  const RigidBody* b1_;
};

/// Matches pairs where at least one geometry has a property with this name (any type).
class PropertyFilter : public ExecuteFilter {
 public:
  explicit PropertyFilter(std::string name) : name_(std::move(name)) {}
  bool match(const Geometry* a, const Geometry* b) const override {
    return a->getPropertyContainer().hasProperty(name_) || b->getPropertyContainer().hasProperty(name_);
  }

 private:
  std::string name_;
};

}  // namespace scree
