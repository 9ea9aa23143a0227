// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Narrowphase: contact points between two placed geometries.
//
// Dispatch is a table over (Shape::Type, Shape::Type). Analytic pairs first (sphere, box, capsule, plane,
// height field, line); libccd (MPR, then GJK/EPA where MPR fails) for the remaining convex pairs, behind one
// adapter (ccd_adapter.cpp is the only file that includes libccd).
//
// Conventions: normal points from geometry 1 towards geometry 0 (geometry 0 is pushed along +normal),
// depth > 0 is overlap, depth < 0 a gap. Points with depth >= -margin are returned (speculative contacts,
// so fast bodies do not tunnel). At most 4 points per pair. Every convex pair gets a full manifold where its
// shapes touch along a face, cap or line: box-box, box-plane, box-height-field and convex-convex by SAT and
// clipping; the pairs without an analytic routine (cylinder, capsule and hull pairs) by clipping the two
// shapes' supporting features along the penetration normal (collide/src/convex_manifold.cpp,
// docs/design.md "Contact manifolds for every convex pair"). Each point carries a featureId that stays the
// same while the same features touch (warm starting keys on it).
#pragma once

#include <vector>

#include "scree/collide/geometry.h"
#include "scree/core/contact.h"

namespace scree {

/// Appends the contact points between g0 and g1 (world transforms must be current) to `out`; returns how
/// many were appended. Pairs that no routine handles (e.g. plane-plane, height field-height field) return 0.
int collideGeometries(const Geometry& g0, const Geometry& g1, Real margin, std::vector<ContactPoint>& out);

/// True when a routine exists for the two shape types (in either order).
bool hasCollider(Shape::Type a, Shape::Type b);

}  // namespace scree
