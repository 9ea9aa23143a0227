// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Geometry (AGX: agxCollide::Geometry): one shape placed in a body frame (or in the world when it has no
// body), with a material, sensor flag, collision switch, collision groups and a property container. To its body
// it is a BodyPart (scree/core/body_part.h): it gives its shape's mass properties in the body frame.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "scree/collide/shapes.h"
#include "scree/core/body_part.h"
#include "scree/core/material.h"
#include "scree/core/math.h"
#include "scree/core/property_container.h"
#include "scree/core/rigid_body.h"

namespace scree {

class Geometry : public BodyPart {
 public:
  /// shape must not be null.
  explicit Geometry(ShapeRef shape, const std::string& name = "");
  Geometry(const Geometry&) = delete;
  Geometry& operator=(const Geometry&) = delete;

  const ShapeRef& getShape() const { return shape_; }
  const std::string& getName() const { return name_; }
  void setName(const std::string& n) { name_ = n; }
  /// Unique per process, never reused; orders pairs deterministically.
  uint32_t getId() const { return id_; }

  /// Placement relative to the body frame. Changing it updates the body's mass properties.
  void setLocalPosition(const Vec3& p);
  void setLocalRotation(const Quat& q);
  const Transform& getLocalTransform() const { return local_; }
  /// For a geometry without a body: world placement (same as the local transform).
  void setPosition(const Vec3& p);
  void setRotation(const Quat& q);
  /// World placement (from the body, refreshed by updateTransform()).
  Vec3 getPosition() const { return world_.p; }
  Quat getRotation() const { return world_.q; }
  const Transform& getTransform() const { return world_; }
  /// Recomputes the world transform from the body pose (the simulation calls it every step).
  void updateTransform();
  /// World AABB of the shape at the current transform.
  Aabb getBoundingBox() const { return shape_->getBoundingBox(world_); }

  // getRigidBody(): the body it is attached to, or nullptr (from BodyPart).

  void setMaterial(MaterialRef m);
  /// May be null: the simulation's default material is used.
  const MaterialRef& getMaterial() const { return material_; }

  /// A sensor reports contacts to listeners and produces no force (nor mass).
  void setSensor(bool s) { sensor_ = s; }
  bool isSensor() const { return sensor_; }
  void setEnableCollisions(bool e) { collisions_ = e; }
  bool getEnableCollisions() const { return collisions_; }

  /// Collision groups: pairs of groups can be disabled in the Space (Simulation::setEnableCollisions).
  /// String names map to ids through a process-wide registry.
  void addGroup(uint32_t id);
  void addGroup(const std::string& name);
  bool removeGroup(uint32_t id);
  bool hasGroup(uint32_t id) const;
  const std::vector<uint32_t>& getGroups() const { return groups_; }
  static uint32_t groupId(const std::string& name);

  PropertyContainer& getPropertyContainer() { return props_; }
  const PropertyContainer& getPropertyContainer() const { return props_; }

 private:
  // BodyPart, called by the body.
  MassProperties getMassPropertiesInBody() const override;
  void onBodyChanged() override { updateTransform(); }
  std::string describePart() const override;

  ShapeRef shape_;
  std::string name_;
  uint32_t id_;
  Transform local_;
  Transform world_;
  MaterialRef material_;
  bool sensor_ = false;
  bool collisions_ = true;
  std::vector<uint32_t> groups_;
  PropertyContainer props_;
};

}  // namespace scree
