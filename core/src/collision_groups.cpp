// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scree/core/collision_groups.h"

#include <mutex>
#include <unordered_map>

namespace scree::detail {

namespace {
struct GroupRegistry {
  std::mutex mutex;
  std::unordered_map<std::string, uint32_t> ids;
  uint32_t next = uint32_t(1) << 30;
};
GroupRegistry& groupRegistry() {
  static GroupRegistry r;
  return r;
}
}  // namespace

uint32_t collisionGroupId(const std::string& name) {
  GroupRegistry& r = groupRegistry();
  std::lock_guard<std::mutex> lock(r.mutex);
  auto [it, inserted] = r.ids.try_emplace(name, r.next);
  if (inserted) ++r.next;
  return it->second;
}

}  // namespace scree::detail
