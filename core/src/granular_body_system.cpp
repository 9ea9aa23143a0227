// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scree/core/granular_body_system.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <type_traits>
#include <stdexcept>

#include "scree/core/collision_groups.h"
#include "scree/core/errors.h"

namespace scree {

namespace {
constexpr uint32_t kNoSlot = UINT32_MAX;

std::string idText(size_t id) {
  return std::to_string(id) + " (slot " + std::to_string(uint32_t(id) - 1) + ", generation " +
         std::to_string(uint32_t(id >> 32)) + ")";
}
[[noreturn]] void throwBadId(const char* where, size_t id) {
  throw std::invalid_argument(std::string(where) + ": id = " + idText(id) + " is invalid (no live particle)");
}
}  // namespace

GranularBodySystem::GranularBodySystem() : currentMaterial_(std::make_shared<Material>("granular")) {
  materialTable_.push_back(currentMaterial_);
}

Real GranularBodySystem::sphereMass(Real density, Real radius) {
  return density * (4.0 / 3.0) * std::numbers::pi * radius * radius * radius;
}

uint32_t GranularBodySystem::materialIndexOf(const MaterialRef& m) {
  for (size_t k = 0; k < materialTable_.size(); ++k)
    if (materialTable_[k] == m) return uint32_t(k);
  materialTable_.push_back(m);
  return uint32_t(materialTable_.size() - 1);
}

uint32_t GranularBodySystem::slotOf(size_t id) const {
  if (id == 0) return kNoSlot;
  const uint32_t low = uint32_t(id & 0xffffffffu);
  const uint32_t gen = uint32_t(id >> 32);
  if (low == 0 || low > slots_.size()) return kNoSlot;
  const Slot& s = slots_[low - 1];
  if (!s.live || s.generation != gen) return kNoSlot;
  return low - 1;
}

bool GranularBodySystem::isValid(size_t id) const { return slotOf(id) != kNoSlot; }

size_t GranularBodySystem::checkedDense(const char* where, size_t id) const {
  const uint32_t s = slotOf(id);
  if (s == kNoSlot) throwBadId(where, id);
  return slots_[s].dense;
}

size_t GranularBodySystem::denseIndex(size_t id) const { return checkedDense("GranularBodySystem::denseIndex", id); }

size_t GranularBodySystem::idOfDense(size_t i) const {
  const uint32_t s = denseToSlot_[i];
  return makeId(s, slots_[s].generation);
}

size_t GranularBodySystem::createParticle(const Vec3& position, Real radius, const Vec3& velocity) {
  const char* where = "GranularBodySystem::createParticle";
  detail::requireFinite(where, "position", position);
  detail::requirePositive(where, "radius", radius);
  detail::requireFinite(where, "velocity", velocity);
  const Real mass = sphereMass(currentMaterial_->getDensity(), radius);
  if (!(std::isfinite(mass) && mass > 0)) detail::throwInvalid(where, "radius", radius, "gives a non-finite or zero mass");
  if (positions_.size() >= size_t(kNoSlot - 1))
    throw std::invalid_argument(std::string(where) + ": capacity exhausted");

  uint32_t s;
  if (!freeSlots_.empty()) {
    s = freeSlots_.back();
    freeSlots_.pop_back();
  } else {
    s = uint32_t(slots_.size());
    slots_.push_back(Slot{});
  }
  const uint32_t dense = uint32_t(positions_.size());
  slots_[s].dense = dense;
  slots_[s].live = true;

  positions_.push_back(position);
  velocities_.push_back(velocity);
  angularVelocities_.push_back(Vec3::Zero());
  radii_.push_back(radius);
  masses_.push_back(mass);
  invMasses_.push_back(1.0 / mass);
  materialIndices_.push_back(materialIndexOf(currentMaterial_));
  denseToSlot_.push_back(s);
  alive_.push_back(1);
  for (auto& b : customReal_) b.second.push_back(0.0);
  ++numLive_;
  ++revision_;
  return makeId(s, slots_[s].generation);
}

void GranularBodySystem::destroyParticle(size_t id) {
  const size_t i = checkedDense("GranularBodySystem::destroyParticle", id);
  const uint32_t s = denseToSlot_[i];
  slots_[s].live = false;
  ++slots_[s].generation;
  if (slots_[s].generation == 0) slots_[s].generation = 1;  // wrap: generation 0 is never used
  --numLive_;
  ++revision_;
  if (deferDepth_ > 0) {
    // Keep the dense entry until compaction; make it inert for any loop still running.
    alive_[i] = 0;
    invMasses_[i] = 0;
    velocities_[i].setZero();
    angularVelocities_[i].setZero();
    ++numDeadDense_;
    return;  // slot is freed at compaction so it is not reused while the dense entry still points at it
  }
  freeSlots_.push_back(s);
  removeDense(i);
}

void GranularBodySystem::removeDense(size_t i) {
  const size_t last = positions_.size() - 1;
  if (i != last) {
    positions_[i] = positions_[last];
    velocities_[i] = velocities_[last];
    angularVelocities_[i] = angularVelocities_[last];
    radii_[i] = radii_[last];
    masses_[i] = masses_[last];
    invMasses_[i] = invMasses_[last];
    materialIndices_[i] = materialIndices_[last];
    denseToSlot_[i] = denseToSlot_[last];
    alive_[i] = alive_[last];
    for (auto& b : customReal_) b.second[i] = b.second[last];
    if (alive_[i]) slots_[denseToSlot_[i]].dense = uint32_t(i);
  }
  positions_.pop_back();
  velocities_.pop_back();
  angularVelocities_.pop_back();
  radii_.pop_back();
  masses_.pop_back();
  invMasses_.pop_back();
  materialIndices_.pop_back();
  denseToSlot_.pop_back();
  alive_.pop_back();
  for (auto& b : customReal_) b.second.pop_back();
}

void GranularBodySystem::compact() {
  if (numDeadDense_ == 0) return;
  // Walk backwards so the entry moved into a gap has already been examined.
  for (size_t k = positions_.size(); k-- > 0;) {
    if (alive_[k]) continue;
    freeSlots_.push_back(denseToSlot_[k]);
    removeDense(k);
  }
  numDeadDense_ = 0;
  ++revision_;
}

void GranularBodySystem::endDeferral() {
  if (deferDepth_ > 0) --deferDepth_;
  if (deferDepth_ == 0) compact();
}

void GranularBodySystem::clear() {
  forEachParticle([this](size_t id) { destroyParticle(id); });
}

Vec3 GranularBodySystem::getPosition(size_t id) const {
  return positions_[checkedDense("GranularBodySystem::getPosition", id)];
}
Vec3 GranularBodySystem::getVelocity(size_t id) const {
  return velocities_[checkedDense("GranularBodySystem::getVelocity", id)];
}
Vec3 GranularBodySystem::getAngularVelocity(size_t id) const {
  return angularVelocities_[checkedDense("GranularBodySystem::getAngularVelocity", id)];
}
Real GranularBodySystem::getRadius(size_t id) const { return radii_[checkedDense("GranularBodySystem::getRadius", id)]; }
Real GranularBodySystem::getMass(size_t id) const { return masses_[checkedDense("GranularBodySystem::getMass", id)]; }
MaterialRef GranularBodySystem::getParticleMaterial(size_t id) const {
  return materialTable_[materialIndices_[checkedDense("GranularBodySystem::getParticleMaterial", id)]];
}

void GranularBodySystem::setPosition(size_t id, const Vec3& position) {
  const char* where = "GranularBodySystem::setPosition";
  const size_t i = checkedDense(where, id);
  detail::requireFinite(where, "position", position);
  positions_[i] = position;
}
void GranularBodySystem::setVelocity(size_t id, const Vec3& velocity) {
  const char* where = "GranularBodySystem::setVelocity";
  const size_t i = checkedDense(where, id);
  detail::requireFinite(where, "velocity", velocity);
  velocities_[i] = velocity;
}
void GranularBodySystem::setAngularVelocity(size_t id, const Vec3& angularVelocity) {
  const char* where = "GranularBodySystem::setAngularVelocity";
  const size_t i = checkedDense(where, id);
  detail::requireFinite(where, "angularVelocity", angularVelocity);
  angularVelocities_[i] = angularVelocity;
}
void GranularBodySystem::setRadius(size_t id, Real radius) {
  const char* where = "GranularBodySystem::setRadius";
  const size_t i = checkedDense(where, id);
  detail::requirePositive(where, "radius", radius);
  const Real mass = sphereMass(materialTable_[materialIndices_[i]]->getDensity(), radius);
  if (!(std::isfinite(mass) && mass > 0)) detail::throwInvalid(where, "radius", radius, "gives a non-finite or zero mass");
  radii_[i] = radius;
  masses_[i] = mass;
  invMasses_[i] = 1.0 / mass;
  ++revision_;
}
void GranularBodySystem::setParticleMaterial(size_t id, MaterialRef material) {
  const char* where = "GranularBodySystem::setParticleMaterial";
  const size_t i = checkedDense(where, id);
  if (!material) throw std::invalid_argument(std::string(where) + ": material = null is invalid (must not be null)");
  const Real mass = sphereMass(material->getDensity(), radii_[i]);
  materialIndices_[i] = materialIndexOf(material);
  masses_[i] = mass;
  invMasses_[i] = 1.0 / mass;
  ++revision_;
}

void GranularBodySystem::setMaterial(MaterialRef material) {
  if (!material)
    throw std::invalid_argument("GranularBodySystem::setMaterial: material = null is invalid (must not be null)");
  currentMaterial_ = std::move(material);
  materialIndexOf(currentMaterial_);
}

Real GranularBodySystem::getTotalMass() const {
  Real m = 0;
  for (size_t i = 0; i < size(); ++i)
    if (alive_[i]) m += masses_[i];
  return m;
}

Real GranularBodySystem::getMaxRadius() const {
  Real r = 0;
  for (Real x : radii_) r = std::max(r, x);
  return r;
}

std::vector<size_t> GranularBodySystem::getParticleIds() const {
  std::vector<size_t> ids;
  ids.reserve(numLive_);
  for (size_t i = 0; i < size(); ++i)
    if (alive_[i]) ids.push_back(idOfDense(i));
  return ids;
}

// ---- custom buffers ------------------------------------------------------------------------------------------

void GranularBodySystem::addCustomBufferReal(const std::string& name) {
  if (name.empty())
    throw std::invalid_argument("GranularBodySystem::addCustomBufferReal: name = \"\" is invalid (must not be empty)");
  if (hasCustomBufferReal(name)) return;
  customReal_.emplace_back(name, std::vector<Real>(size(), 0.0));
}

bool GranularBodySystem::hasCustomBufferReal(const std::string& name) const {
  for (const auto& b : customReal_)
    if (b.first == name) return true;
  return false;
}

void GranularBodySystem::removeCustomBufferReal(const std::string& name) {
  for (auto it = customReal_.begin(); it != customReal_.end(); ++it)
    if (it->first == name) {
      customReal_.erase(it);
      return;
    }
  detail::throwInvalid("GranularBodySystem::removeCustomBufferReal", "name", name, "no such buffer");
}

const Real* GranularBodySystem::customBufferReal(const std::string& name) const {
  for (const auto& b : customReal_)
    if (b.first == name) return b.second.data();
  return nullptr;
}
Real* GranularBodySystem::customBufferReal(const std::string& name) {
  for (auto& b : customReal_)
    if (b.first == name) return b.second.data();
  return nullptr;
}

void GranularBodySystem::setCustomReal(const std::string& name, size_t id, Real v) {
  const char* where = "GranularBodySystem::setCustomReal";
  const size_t i = checkedDense(where, id);
  Real* buf = customBufferReal(name);
  if (!buf) detail::throwInvalid(where, "name", name, "no such buffer");
  buf[i] = v;
}

Real GranularBodySystem::getCustomReal(const std::string& name, size_t id) const {
  const char* where = "GranularBodySystem::getCustomReal";
  const size_t i = checkedDense(where, id);
  const Real* buf = customBufferReal(name);
  if (!buf) detail::throwInvalid(where, "name", name, "no such buffer");
  return buf[i];
}

std::vector<std::string> GranularBodySystem::getCustomBufferRealNames() const {
  std::vector<std::string> names;
  for (const auto& b : customReal_) names.push_back(b.first);
  return names;
}

// ---- reorder -------------------------------------------------------------------------------------------------

void GranularBodySystem::reorder(const std::vector<uint32_t>& newOrder) {
  const char* where = "GranularBodySystem::reorder";
  if (deferDepth_ > 0) throw std::logic_error(std::string(where) + ": not allowed while destroys are deferred");
  const size_t n = size();
  if (newOrder.size() != n)
    detail::throwInvalid(where, "newOrder.size()", (long long)newOrder.size(), "must equal size()");
  std::vector<uint8_t> seen(n, 0);
  for (uint32_t k : newOrder) {
    if (k >= n || seen[k]) detail::throwInvalid(where, "newOrder entry", (long long)k, "must be a permutation of 0..size()-1");
    seen[k] = 1;
  }
  auto permute = [&](auto& arr) {
    std::remove_reference_t<decltype(arr)> tmp(n);
    for (size_t k = 0; k < n; ++k) tmp[k] = arr[newOrder[k]];
    arr.swap(tmp);
  };
  permute(positions_);
  permute(velocities_);
  permute(angularVelocities_);
  permute(radii_);
  permute(masses_);
  permute(invMasses_);
  permute(materialIndices_);
  permute(denseToSlot_);
  permute(alive_);
  for (auto& b : customReal_) permute(b.second);
  for (size_t k = 0; k < n; ++k) slots_[denseToSlot_[k]].dense = uint32_t(k);
  ++revision_;
}

// ---- collision groups ----------------------------------------------------------------------------------------

namespace {
uint32_t namedGroup(const char* where, const std::string& name) {
  if (name.empty()) detail::throwInvalid(where, "name", name, "must not be empty");
  return detail::collisionGroupId(name);
}
}  // namespace

void GranularBodySystem::addGroup(uint32_t id) {
  if (!hasGroup(id)) groups_.push_back(id);
}
void GranularBodySystem::addGroup(const std::string& name) {
  addGroup(namedGroup("GranularBodySystem::addGroup", name));
}
bool GranularBodySystem::removeGroup(uint32_t id) {
  auto it = std::find(groups_.begin(), groups_.end(), id);
  if (it == groups_.end()) return false;
  groups_.erase(it);
  return true;
}
bool GranularBodySystem::removeGroup(const std::string& name) {
  return removeGroup(namedGroup("GranularBodySystem::removeGroup", name));
}
bool GranularBodySystem::hasGroup(uint32_t id) const {
  return std::find(groups_.begin(), groups_.end(), id) != groups_.end();
}
bool GranularBodySystem::hasGroup(const std::string& name) const {
  return hasGroup(namedGroup("GranularBodySystem::hasGroup", name));
}

}  // namespace scree
