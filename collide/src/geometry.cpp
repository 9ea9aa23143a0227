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
  if (body_) body_->updateMassProperties();
  updateTransform();
}

void Geometry::setLocalRotation(const Quat& q) {
  detail::requireRotation("Geometry::setLocalRotation", "rotation", q);
  local_.q = q.normalized();
  if (body_) body_->updateMassProperties();
  updateTransform();
}

void Geometry::setPosition(const Vec3& p) {
  detail::requireFinite("Geometry::setPosition", "position", p);
  if (body_) setLocalPosition(body_->getTransform().applyInverse(p));
  else {
    local_.p = p;
    updateTransform();
  }
}

void Geometry::setRotation(const Quat& q) {
  detail::requireRotation("Geometry::setRotation", "rotation", q);
  if (body_) setLocalRotation(body_->getRotation().conjugate() * q.normalized());
  else {
    local_.q = q.normalized();
    updateTransform();
  }
}

void Geometry::updateTransform() {
  if (body_) world_ = body_->getTransform() * local_;
  else world_ = local_;
}

void Geometry::setMaterial(MaterialRef m) {
  material_ = std::move(m);
  if (body_) body_->updateMassProperties();
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
