// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scree/core/rigid_body.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <atomic>
#include <stdexcept>

#include "scree/core/errors.h"

namespace scree {

namespace {
uint32_t nextBodyId() {
  static std::atomic<uint32_t> counter{1};
  return counter++;
}
}  // namespace

RigidBody::RigidBody(const std::string& name) : name_(name), id_(nextBodyId()) {}

// A part that outlives its body (the user keeps the geometry) must not keep a dangling body pointer.
RigidBody::~RigidBody() {
  for (BodyPart* p : parts_) p->body_ = nullptr;
}

// ---- geometries and mass properties --------------------------------------------------------------------------
//
// Mass properties of a body = sum over its parts (geometries) of each part's mass properties in the body frame
// (BodyPart::getMassPropertiesInBody: a geometry gives its shape's at the material's density, placed by its
// local transform; sensors and shapes without volume give none):
//   m = sum m_i,  c = sum m_i c_i / m
//   I = sum [ I_i + m_i (|d_i|^2 1 - d_i d_i^T) ],  d_i = c_i - c    (parallel-axis theorem)
// applyComputedMass then applies explicit overrides (setMass, setInertiaTensor, setCmLocal).

void RigidBody::attach(GeometryRef geometry, BodyPart* part) {
  detail::requireNonNull("RigidBody::add", "geometry", part);
  if (part->body_ != nullptr)
    throw std::invalid_argument("RigidBody::add: " + part->describePart() + " is already attached to a body");
  part->body_ = this;
  geometries_.push_back(std::move(geometry));
  parts_.push_back(part);
  updateMassProperties();
  part->onBodyChanged();
}

bool RigidBody::remove(const GeometryRef& geometry) {
  if (!geometry) return false;
  auto it = std::find(geometries_.begin(), geometries_.end(), geometry);
  if (it == geometries_.end()) return false;
  const auto i = it - geometries_.begin();
  BodyPart* part = parts_[size_t(i)];
  geometries_.erase(it);
  parts_.erase(parts_.begin() + i);
  part->body_ = nullptr;
  part->onBodyChanged();  // without a body the local transform is the world placement
  updateMassProperties();
  return true;
}

void RigidBody::updateMassProperties() {
  // Bodies carry a handful of geometries; a small local vector is fine here (not a per-step path).
  std::vector<MassProperties> parts;
  parts.reserve(parts_.size());
  Real mass = 0;
  Vec3 moment = Vec3::Zero();
  for (const BodyPart* part : parts_) {
    const MassProperties p = part->getMassPropertiesInBody();
    if (!(p.mass > 0)) continue;
    mass += p.mass;
    moment += p.mass * p.cm;
    parts.push_back(p);
  }
  if (!(mass > 0)) {
    applyComputedMass(0, Vec3::Zero(), Mat3::Zero());
    return;
  }
  const Vec3 cm = moment / mass;
  Mat3 inertia = Mat3::Zero();
  for (const MassProperties& p : parts) {
    const Vec3 d = p.cm - cm;
    inertia += p.inertia + p.mass * (Mat3::Identity() * d.squaredNorm() - d * d.transpose());
  }
  inertia = (0.5 * (inertia + inertia.transpose())).eval();
  applyComputedMass(mass, cm, inertia);
}

void RigidBody::setMotionControl(MotionControl m) {
  if (m != STATIC && m != KINEMATICS && m != DYNAMICS)
    detail::throwInvalid("RigidBody::setMotionControl", "motionControl", (long long)m, "must be STATIC, KINEMATICS or DYNAMICS");
  motion_ = m;
  if (m == STATIC) {
    v_.setZero();
    w_.setZero();
  }
}

void RigidBody::setMass(Real mass) {
  detail::requirePositive("RigidBody::setMass", "mass", mass);
  // Keep the radius of gyration of a computed inertia: scale it with the mass.
  if (!inertiaExplicit_) setInertiaInternal(inertia_ * (mass / mass_));
  mass_ = mass;
  invMass_ = 1.0 / mass;
  massExplicit_ = true;
}

void RigidBody::setInertiaTensor(const Mat3& inertia) {
  if (!inertia.allFinite())
    throw std::invalid_argument("RigidBody::setInertiaTensor: inertia is invalid (must be finite)");
  if ((inertia - inertia.transpose()).norm() > 1e-9 * inertia.norm())
    throw std::invalid_argument("RigidBody::setInertiaTensor: inertia is invalid (must be symmetric)");
  Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (inertia + inertia.transpose()));
  const Vec3 ev = es.eigenvalues();
  if (!(ev.minCoeff() > 0))
    detail::throwInvalid("RigidBody::setInertiaTensor", "inertia eigenvalues", ev, "must be positive definite");
  // Principal moments must satisfy the triangle inequality for a physical mass distribution; allow a small
  // tolerance for user round-off.
  if (ev(0) + ev(1) < ev(2) * (1 - 1e-9))
    detail::throwInvalid("RigidBody::setInertiaTensor", "inertia eigenvalues", ev,
                         "violate the triangle inequality I1 + I2 >= I3");
  setInertiaInternal(inertia);
  inertiaExplicit_ = true;
}

void RigidBody::setInertiaInternal(const Mat3& inertia) {
  const Mat3 sym = 0.5 * (inertia + inertia.transpose());
  Eigen::SelfAdjointEigenSolver<Mat3> es(sym);
  Mat3 P = es.eigenvectors();
  if (P.determinant() < 0) P.col(2) = -P.col(2);
  inertia_ = sym;
  principal_ = es.eigenvalues();
  principalFrame_ = Quat(P);
  principalFrame_.normalize();
  invInertia_ = P * principal_.cwiseInverse().asDiagonal() * P.transpose();
}

void RigidBody::setCmLocal(const Vec3& cm) {
  detail::requireFinite("RigidBody::setCmLocal", "cm", cm);
  const Vec3 origin = getPosition();
  cmLocal_ = cm;
  x_ = origin + q_ * cmLocal_;
  cmExplicit_ = true;
}

void RigidBody::resetMassOverrides() {
  massExplicit_ = inertiaExplicit_ = cmExplicit_ = false;
  updateMassProperties();
}

void RigidBody::applyComputedMass(Real mass, const Vec3& cm, const Mat3& inertia) {
  const Vec3 origin = getPosition();
  if (!(mass > 0)) {
    // No massive geometry: 1 kg, unit inertia, centre of mass at the body origin (until set explicitly).
    computedMass_ = 1;
    if (!massExplicit_) {
      mass_ = 1;
      invMass_ = 1;
    }
    if (!inertiaExplicit_) setInertiaInternal(Mat3::Identity() * (massExplicit_ ? mass_ : 1.0));
    if (!cmExplicit_) cmLocal_.setZero();
  } else {
    computedMass_ = mass;
    if (!massExplicit_) {
      mass_ = mass;
      invMass_ = 1.0 / mass;
    }
    if (!inertiaExplicit_) setInertiaInternal(inertia * (mass_ / mass));
    if (!cmExplicit_) cmLocal_ = cm;
  }
  x_ = origin + q_ * cmLocal_;
}

void RigidBody::setPosition(const Vec3& p) {
  detail::requireFinite("RigidBody::setPosition", "position", p);
  x_ = p + q_ * cmLocal_;
}

void RigidBody::setRotation(const Quat& q) {
  detail::requireRotation("RigidBody::setRotation", "rotation", q);
  const Vec3 origin = getPosition();
  q_ = q.normalized();
  x_ = origin + q_ * cmLocal_;
}

void RigidBody::setVelocity(const Vec3& v) {
  detail::requireFinite("RigidBody::setVelocity", "velocity", v);
  v_ = v;
}

void RigidBody::setAngularVelocity(const Vec3& w) {
  detail::requireFinite("RigidBody::setAngularVelocity", "angularVelocity", w);
  w_ = w;
}

Mat3 RigidBody::getInvInertiaWorld() const {
  if (motion_ != DYNAMICS) return Mat3::Zero();
  const Mat3 R = q_.toRotationMatrix();
  return R * invInertia_ * R.transpose();
}

Vec3 RigidBody::getAngularMomentum() const {
  const Mat3 R = q_.toRotationMatrix();
  return R * (inertia_ * (R.transpose() * w_));
}

Real RigidBody::getKineticEnergy() const {
  const Mat3 R = q_.toRotationMatrix();
  const Vec3 wb = R.transpose() * w_;
  return 0.5 * mass_ * v_.squaredNorm() + 0.5 * wb.dot(inertia_ * wb);
}

void RigidBody::setLinearVelocityDamping(Real c) {
  detail::requireNonNegative("RigidBody::setLinearVelocityDamping", "damping", c);
  linDamping_ = c;
}
void RigidBody::setAngularVelocityDamping(Real c) {
  detail::requireNonNegative("RigidBody::setAngularVelocityDamping", "damping", c);
  angDamping_ = c;
}

void RigidBody::addForce(const Vec3& f) {
  detail::requireFinite("RigidBody::addForce", "force", f);
  force_ += f;
}
void RigidBody::addTorque(const Vec3& t) {
  detail::requireFinite("RigidBody::addTorque", "torque", t);
  torque_ += t;
}
void RigidBody::addForceAtPosition(const Vec3& f, const Vec3& worldPoint) {
  detail::requireFinite("RigidBody::addForceAtPosition", "force", f);
  detail::requireFinite("RigidBody::addForceAtPosition", "worldPoint", worldPoint);
  force_ += f;
  torque_ += (worldPoint - x_).cross(f);
}

}  // namespace scree
