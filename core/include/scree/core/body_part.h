// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// BodyPart: what a RigidBody needs from the things attached to it, declared in core so that RigidBody's code
// lives in core without knowing shapes. A Geometry (scree_collide) is the one implementation: it gives the mass
// of its shape placed in the body frame and refreshes its world placement when it changes body.
#pragma once

#include <string>

#include "scree/core/math.h"

namespace scree {

class RigidBody;

/// Mass, centre of mass and inertia tensor about the centre of mass, in one frame (a shape's own frame for
/// Shape::computeMassProperties, the body frame for BodyPart).
struct MassProperties {
  Real mass = 0;
  Vec3 cm = Vec3::Zero();
  Mat3 inertia = Mat3::Zero();
};

class BodyPart {
 public:
  virtual ~BodyPart() = default;
  BodyPart(const BodyPart&) = delete;
  BodyPart& operator=(const BodyPart&) = delete;

  /// The body this part is attached to, or nullptr.
  RigidBody* getRigidBody() const { return body_; }

 protected:
  BodyPart() = default;

 private:
  // Used by RigidBody only (it sets body_ on attach and detach).
  friend class RigidBody;
  /// The part's contribution to its body's mass properties: centre of mass in body coordinates, inertia about
  /// it in body axes. Mass 0 contributes nothing (a sensor, a shape without volume).
  virtual MassProperties getMassPropertiesInBody() const = 0;
  /// Called after getRigidBody() changed (attached or detached): refresh what follows the body.
  virtual void onBodyChanged() = 0;
  /// The part as error messages name it, e.g. geometry "wheel" (id 12).
  virtual std::string describePart() const = 0;

  RigidBody* body_ = nullptr;
};

}  // namespace scree
