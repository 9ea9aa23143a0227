// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Collision group names (solver- and collide-internal): one registry maps a group name to its id, shared by
// Geometry::addGroup(const std::string&) and GranularBodySystem::addGroup(const std::string&), so a name
// means the same group for geometries and particles.
#pragma once

#include <cstdint>
#include <string>

namespace scree::detail {

/// The id of a named collision group, assigned on first use (from 2^30 up, so that names do not collide with
/// small numeric ids users pick). Thread-safe. `name` must not be empty (callers check and report it).
uint32_t collisionGroupId(const std::string& name);

}  // namespace scree::detail
