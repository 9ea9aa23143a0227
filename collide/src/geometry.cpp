// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Geometry: placement, ids, materials and collision groups.
//
// Choices written down here (the header is silent):
// - setPosition/setRotation on a geometry attached to a body place it in the world at the body's current
//   pose, i.e. they set the local transform to body^-1 * world. Without a body they equal the local setters.
// - setLocalPosition/setLocalRotation/setMaterial on an attached geometry recompute the body's mass
//   properties at once (the mass depends on the placement and the density).
// - Group names map to ids starting at 1 << 30 (scree/core/collision_groups.h, shared with particles), so
//   named groups never collide with the small numeric ids users typically pick for addGroup(uint32_t).
#include "scree/collide/geometry.h"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <string>
#include <unordered_map>

#include "scree/core/collision_groups.h"
#include "scree/core/errors.h"

namespace scree {

namespace {

std::atomic<uint32_t> g_nextGeometryId{1};

}  // namespace

Geometry::Geometry(ShapeRef shape, const std::string& name) : name_(name), id_(0) {
  detail::requireNonNull("Geometry::Geometry", "shape", shape.get());
  shape_ = std::move(shape);
  id_ = g_nextGeometryId.fetch_add(1, std::memory_order_relaxed);
}

void Geometry::setLocalPosition(const Vec3& p) {
  detail::requireFinite("Geometry::setLocalPosition", "position", p);
  local_.p = p;
  if (RigidBody* b = getRigidBody()) b->updateMassProperties();
  updateTransform();
}

void Geometry::setLocalRotation(const Quat& q) {
  detail::requireRotation("Geometry::setLocalRotation", "rotation", q);
  local_.q = q.normalized();
  if (RigidBody* b = getRigidBody()) b->updateMassProperties();
  updateTransform();
}

void Geometry::setPosition(const Vec3& p) {
  detail::requireFinite("Geometry::setPosition", "position", p);
  if (const RigidBody* b = getRigidBody()) setLocalPosition(b->getTransform().applyInverse(p));
  else {
    local_.p = p;
    updateTransform();
  }
}

void Geometry::setRotation(const Quat& q) {
  detail::requireRotation("Geometry::setRotation", "rotation", q);
  if (const RigidBody* b = getRigidBody()) setLocalRotation(b->getRotation().conjugate() * q.normalized());
  else {
    local_.q = q.normalized();
    updateTransform();
  }
}

void Geometry::updateTransform() {
  if (const RigidBody* b = getRigidBody()) world_ = b->getTransform() * local_;
  else world_ = local_;
}

MassProperties Geometry::getMassPropertiesInBody() const {
  // Sensors and shapes without volume (plane, line, height field) carry no mass. No material: the default
  // density (MaterialDefaults::density).
  if (sensor_ || !(shape_->getVolume() > 0)) return {};
  const Real density = material_ ? material_->getDensity() : MaterialDefaults::density;
  const MassProperties mp = shape_->computeMassProperties(density);
  if (!(mp.mass > 0)) return {};
  // From the shape frame to the body frame: c = T c_shape, I = R I_shape R^T (inertia rotated into body axes).
  const Mat3 r = local_.q.toRotationMatrix();
  return {mp.mass, local_.apply(mp.cm), r * mp.inertia * r.transpose()};
}

std::string Geometry::describePart() const {
  return "geometry \"" + name_ + "\" (id " + std::to_string(id_) + ")";
}

void Geometry::setMaterial(MaterialRef m) {
  material_ = std::move(m);
  if (RigidBody* b = getRigidBody()) b->updateMassProperties();
}

void Geometry::addGroup(uint32_t id) {
  if (!hasGroup(id)) groups_.push_back(id);
}

void Geometry::addGroup(const std::string& name) { addGroup(groupId(name)); }

bool Geometry::removeGroup(uint32_t id) {
  auto it = std::find(groups_.begin(), groups_.end(), id);
  if (it == groups_.end()) return false;
  groups_.erase(it);
  return true;
}

bool Geometry::hasGroup(uint32_t id) const { return std::find(groups_.begin(), groups_.end(), id) != groups_.end(); }

uint32_t Geometry::groupId(const std::string& name) {
  if (name.empty()) detail::throwInvalid("Geometry::groupId", "name", name, "must not be empty");
  return detail::collisionGroupId(name);
}

}  // namespace scree
