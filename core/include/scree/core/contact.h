// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Contact data written by the narrowphase, modified by contact listeners and read back after the step.
#pragma once

#include <cstdint>
#include <vector>

#include "scree/core/material.h"
#include "scree/core/math.h"

namespace scree {

class Geometry;
class RigidBody;

/// One contact point. Geometry 0 is pushed along +normal, geometry 1 along -normal.
struct ContactPoint {
  Vec3 point = Vec3::Zero();   ///< world, m: midway between the two surfaces
  Vec3 normal = Vec3::UnitZ(); ///< unit, from geometry 1 towards geometry 0
  Real depth = 0;              ///< m; > 0 overlap, < 0 a speculative gap (no force until it closes)

  // --- results of the last step --------------------------------------------------------------------------
  Real normalForce = 0;                ///< N, >= 0 push (negative while adhesion pulls)
  Vec3 frictionForce = Vec3::Zero();   ///< N, world, acting on geometry 0

  // --- per-point overrides a ContactEventListener may set; a negative value means "use the material" --------
  bool enabled = true;          ///< false: the solver ignores this point
  Real youngsModulus = -1;      ///< N/m per point
  Real damping = -1;            ///< SPOOK damping time, s
  Real frictionCoefficient = -1;
  Real restitution = -1;
  /// Target tangential velocity of geometry 0 relative to geometry 1 at the point, world m/s (a conveyor belt).
  /// Only its tangential part is used.
  Vec3 surfaceVelocity = Vec3::Zero();
  /// Primary friction direction, world (AGX: an oriented friction frame). Zero (default): the solver picks
  /// an arbitrary tangent basis. Otherwise its tangential part, normalised, is the first friction row and
  /// normal x that the second (the tire model sets it along the rolling direction).
  Vec3 frictionDirection = Vec3::Zero();

  /// Feature id from the narrowphase (stable while the same features touch); keys warm starting.
  uint32_t featureId = 0;

  // --- solver data kept for warm starting ------------------------------------------------------------------
  Real normalImpulse = 0;              ///< N s of the last step
  Vec3 frictionImpulse = Vec3::Zero(); ///< N s of the last step, world
  Real impactSpeed = 0;                ///< approach speed remembered across a speculative step, m/s
};

/// All contact points between two geometries in one step.
class GeometryContact {
 public:
  GeometryContact() = default;
  GeometryContact(Geometry* g0, Geometry* g1, RigidBody* b0, RigidBody* b1) : geoms_{g0, g1}, bodies_{b0, b1} {}

  /// Re-targets this object at another pair for a new step, keeping the points' storage (no allocation).
  void reset(Geometry* g0, Geometry* g1, RigidBody* b0, RigidBody* b1) {
    geoms_[0] = g0;
    geoms_[1] = g1;
    bodies_[0] = b0;
    bodies_[1] = b1;
    points_.clear();
    params_ = SurfaceParameters{};
    friction_ = nullptr;
    enabled_ = true;
    impact_ = false;
    sensor_ = false;
  }

  Geometry* geometry(int i) const { return geoms_[i]; }
  /// The bodies of the geometries (nullptr for a static geometry without a body).
  RigidBody* rigidBody(int i) const { return bodies_[i]; }
  std::vector<ContactPoint>& points() { return points_; }
  const std::vector<ContactPoint>& points() const { return points_; }

  /// A disabled contact is reported to listeners but not solved.
  bool isEnabled() const { return enabled_; }
  void setEnable(bool e) { enabled_ = e; }
  /// True on the first step the pair touches (the impact event).
  bool isImpact() const { return impact_; }
  void setImpact(bool i) { impact_ = i; }
  /// Sensor pairs produce no force.
  bool isSensor() const { return sensor_; }
  void setSensor(bool s) { sensor_ = s; }

  /// Resolved contact parameters (explicit contact material or the combination). Listeners may change them
  /// for this step only.
  SurfaceParameters& material() { return params_; }
  const SurfaceParameters& material() const { return params_; }
  const FrictionModel* frictionModel() const { return friction_; }
  void setFrictionModel(const FrictionModel* f) { friction_ = f; }

 private:
  Geometry* geoms_[2] = {nullptr, nullptr};
  RigidBody* bodies_[2] = {nullptr, nullptr};
  std::vector<ContactPoint> points_;
  SurfaceParameters params_;
  const FrictionModel* friction_ = nullptr;
  bool enabled_ = true;
  bool impact_ = false;
  bool sensor_ = false;
};

}  // namespace scree
