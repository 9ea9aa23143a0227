// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Rolling radius of a geometry for rolling resistance (solver-private; rigid contacts in contact_rows.cpp, and
// particle-geometry contacts through the collide stage, collide_stage.cpp): spheres, cylinders and capsules
// roll, other shapes do not.
#pragma once

#include "scree/collide/geometry.h"
#include "scree/collide/shapes.h"

namespace scree::detail {

inline Real rollingRadius(const Geometry* g) {
  const Shape* s = g->getShape().get();
  switch (s->getType()) {
    case Shape::SPHERE: return static_cast<const Sphere*>(s)->getRadius();
    case Shape::CYLINDER: return static_cast<const Cylinder*>(s)->getRadius();
    case Shape::CAPSULE: return static_cast<const Capsule*>(s)->getRadius();
    default: return 0;
  }
}

}  // namespace scree::detail
