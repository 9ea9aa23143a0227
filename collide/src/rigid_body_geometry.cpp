// RigidBody members that need shapes (declared in core/include/scree/core/rigid_body.h, defined here so that
// scree_core does not depend on scree_collide).
//
// Mass properties of a body = sum over its non-sensor geometries with volume of the shape's mass properties
// at the geometry material's density (MaterialDefaults::density without a material), each expressed in the
// body frame:
//   m_i, c_i = T_i c_i^shape, I_i = R_i I_i^shape R_i^T            (rotate the inertia into body axes)
//   m = Σ m_i,  c = Σ m_i c_i / m
//   I = Σ [ I_i + m_i (|d_i|^2 1 - d_i d_i^T) ],  d_i = c_i - c    (parallel-axis theorem)
// RigidBody::applyComputedMass then applies explicit overrides (setMass, setInertiaTensor, setCmLocal).
#include "scree/collide/geometry.h"
#include "scree/core/errors.h"
#include "scree/core/rigid_body.h"

#include <algorithm>

namespace scree {

void RigidBody::add(GeometryRef geometry) {
  detail::requireNonNull("RigidBody::add", "geometry", geometry.get());
  if (geometry->getRigidBody() != nullptr)
    throw std::invalid_argument("RigidBody::add: geometry \"" + geometry->getName() + "\" (id " +
                                std::to_string(geometry->getId()) + ") is already attached to a body");
  geometry->setRigidBody(this);
  geometries_.push_back(geometry);
  updateMassProperties();
  geometry->updateTransform();
}

bool RigidBody::remove(const GeometryRef& geometry) {
  if (!geometry) return false;
  auto it = std::find(geometries_.begin(), geometries_.end(), geometry);
  if (it == geometries_.end()) return false;
  geometries_.erase(it);
  geometry->setRigidBody(nullptr);
  geometry->updateTransform();  // without a body the local transform is the world placement
  updateMassProperties();
  return true;
}

void RigidBody::updateMassProperties() {
  struct Part {
    Real m;
    Vec3 c;
    Mat3 inertia;
  };
  // Bodies carry a handful of geometries; a small local vector is fine here (not a per-step path).
  std::vector<Part> parts;
  parts.reserve(geometries_.size());
  Real mass = 0;
  Vec3 moment = Vec3::Zero();
  for (const GeometryRef& g : geometries_) {
    if (g->isSensor()) continue;
    const Shape& s = *g->getShape();
    if (!(s.getVolume() > 0)) continue;
    const Real density = g->getMaterial() ? g->getMaterial()->getDensity() : MaterialDefaults::density;
    const MassProperties mp = s.computeMassProperties(density);
    if (!(mp.mass > 0)) continue;
    const Transform& t = g->getLocalTransform();
    const Mat3 r = t.q.toRotationMatrix();
    Part p{mp.mass, t.apply(mp.cm), r * mp.inertia * r.transpose()};
    mass += p.m;
    moment += p.m * p.c;
    parts.push_back(p);
  }
  if (!(mass > 0)) {
    applyComputedMass(0, Vec3::Zero(), Mat3::Zero());
    return;
  }
  const Vec3 cm = moment / mass;
  Mat3 inertia = Mat3::Zero();
  for (const Part& p : parts) {
    const Vec3 d = p.c - cm;
    inertia += p.inertia + p.m * (Mat3::Identity() * d.squaredNorm() - d * d.transpose());
  }
  inertia = (0.5 * (inertia + inertia.transpose())).eval();
  applyComputedMass(mass, cm, inertia);
}

}  // namespace scree

namespace scree {
// Defined here with add/remove: a geometry that outlives its body must not keep a dangling body pointer.
RigidBody::~RigidBody() {
  for (const GeometryRef& g : geometries_)
    if (g) g->setRigidBody(nullptr);
}
}  // namespace scree
