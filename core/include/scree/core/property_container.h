// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Named properties on a geometry (AGX's agx::PropertyContainer). The model layer keys on them, e.g. a
// terrain shovel is a geometry with Vec3 properties "ShovelUpProperty" and "ShovelForwardProperty".
#pragma once

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <variant>

#include "scree/core/math.h"

namespace scree {

class PropertyContainer {
 public:
  using Value = std::variant<bool, Real, int, std::string, Vec3>;

  // add*: create or overwrite. set*: overwrite an existing property of the same type, else throw.
  void addPropertyBool(const std::string& name, bool v) { props_[name] = v; }
  void addPropertyReal(const std::string& name, Real v) { props_[name] = v; }
  void addPropertyInt(const std::string& name, int v) { props_[name] = v; }
  void addPropertyString(const std::string& name, const std::string& v) { props_[name] = v; }
  void addPropertyVec3(const std::string& name, const Vec3& v) { props_[name] = v; }

  bool hasProperty(const std::string& name) const { return props_.count(name) != 0; }
  bool hasPropertyBool(const std::string& name) const { return has<bool>(name); }
  bool hasPropertyReal(const std::string& name) const { return has<Real>(name); }
  bool hasPropertyInt(const std::string& name) const { return has<int>(name); }
  bool hasPropertyString(const std::string& name) const { return has<std::string>(name); }
  bool hasPropertyVec3(const std::string& name) const { return has<Vec3>(name); }

  /// Getters throw std::invalid_argument when the property is missing or of another type.
  bool getPropertyBool(const std::string& name) const { return get<bool>(name); }
  Real getPropertyReal(const std::string& name) const { return get<Real>(name); }
  int getPropertyInt(const std::string& name) const { return get<int>(name); }
  const std::string& getPropertyString(const std::string& name) const { return get<std::string>(name); }
  const Vec3& getPropertyVec3(const std::string& name) const { return get<Vec3>(name); }

  bool removeProperty(const std::string& name) { return props_.erase(name) != 0; }
  size_t size() const { return props_.size(); }
  const std::map<std::string, Value>& all() const { return props_; }

 private:
  template <class T>
  bool has(const std::string& name) const {
    auto it = props_.find(name);
    return it != props_.end() && std::holds_alternative<T>(it->second);
  }
  template <class T>
  const T& get(const std::string& name) const;

  std::map<std::string, Value> props_;
};

template <class T>
const T& PropertyContainer::get(const std::string& name) const {
  auto it = props_.find(name);
  if (it == props_.end())
    throw std::invalid_argument("PropertyContainer::getProperty: name = \"" + name + "\" is invalid (no such property)");
  if (!std::holds_alternative<T>(it->second))
    throw std::invalid_argument("PropertyContainer::getProperty: name = \"" + name +
                                "\" is invalid (property has another type)");
  return std::get<T>(it->second);
}

}  // namespace scree
