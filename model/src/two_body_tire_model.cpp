// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scree/model/two_body_tire_model.h"

#include <cmath>

#include "scree/core/errors.h"
#include "scree/solver/simulation.h"

namespace scree {

using detail::ConstraintRow;  // the solver row type (scree/solver/constraint_row.h)

namespace {
constexpr const char* kCtor = "TwoBodyTireModel::TwoBodyTireModel";

// Validates the constructor's arguments before the Joint base is built (so a bad call changes nothing) and
// returns the rest frame: at the rim's model origin, z along the rotation axis.
Transform restFrame(const RigidBodyRef& tire, Real tireRadius, const RigidBodyRef& rim, Real rimRadius,
                    const Vec3& localAxis) {
  detail::requireNonNull(kCtor, "tireBody", tire.get());
  detail::requireNonNull(kCtor, "rimBody", rim.get());
  if (tire == rim) detail::throwInvalid(kCtor, "rimBody", rim->getName(), "must differ from tireBody");
  detail::requirePositive(kCtor, "tireRadius", tireRadius);
  detail::requirePositive(kCtor, "rimRadius", rimRadius);
  detail::requireFinite(kCtor, "localRotationAxis", localAxis);
  if (localAxis.norm() < 1e-12) detail::throwInvalid(kCtor, "localRotationAxis", localAxis, "must be non-zero");
  const Quat local = Quat::FromTwoVectors(Vec3::UnitZ(), localAxis.normalized());
  return {rim->getPosition(), (rim->getRotation() * local).normalized()};
}

// Sets the friction direction on the tire's contacts. Held by the model, registered while it is simulated.
class TireFrictionListener : public ContactEventListener {
 public:
  explicit TireFrictionListener(const TwoBodyTireModel* m) : ContactEventListener(IMPACT | CONTACT), model_(m) {}
  KeepContactPolicy impact(const TimeStamp&, GeometryContact& c) override {
    model_->alignFriction(c);
    return KEEP_CONTACT;
  }
  KeepContactPolicy contact(const TimeStamp&, GeometryContact& c) override {
    model_->alignFriction(c);
    return KEEP_CONTACT;
  }

 private:
  const TwoBodyTireModel* model_;
};
}  // namespace

TwoBodyTireModel::TwoBodyTireModel(RigidBodyRef tireBody, Real tireRadius, RigidBodyRef rimBody, Real rimRadius,
                                   const Vec3& localRotationAxis)
    : Joint(tireBody, rimBody, restFrame(tireBody, tireRadius, rimBody, rimRadius, localRotationAxis).p,
            restFrame(tireBody, tireRadius, rimBody, rimRadius, localRotationAxis).q, NUM_DOFS, "TwoBodyTireModel"),
      Model("TwoBodyTireModel"),
      tireRadius_(tireRadius),
      rimRadius_(rimRadius),
      localAxis_(localRotationAxis.normalized()) {
  stiffness_[RADIAL] = defaultRadialStiffness;
  dampingCoef_[RADIAL] = defaultRadialDamping;
  for (int m = LATERAL; m < NUM_MODES; ++m) {
    stiffness_[m] = defaultStiffness;
    dampingCoef_[m] = defaultDamping;
  }
  // Solve type: the constraint default, DIRECT_AND_ITERATIVE, like every joint (AGX's default). (An earlier
  // ITERATIVE default here worked around a DirectSolver bug -- a moving kinematic body's velocity was left out of
  // the direct rows, so a rig on a kinematic carriage got wrong wind-up -- fixed in direct.cpp.)
  listener_ = std::make_shared<TireFrictionListener>(this);
}

TwoBodyTireModel::~TwoBodyTireModel() = default;

void TwoBodyTireModel::checkMode(const char* where, DeformationMode mode) {
  if (int(mode) < 0 || int(mode) >= NUM_MODES)
    detail::throwInvalid(std::string("TwoBodyTireModel::") + where, "mode", (long long)int(mode),
                         "must be RADIAL, LATERAL, BENDING or TORSIONAL");
}

void TwoBodyTireModel::setStiffness(Real stiffness, DeformationMode mode) {
  checkMode("setStiffness", mode);
  detail::requirePositive("TwoBodyTireModel::setStiffness", "stiffness", stiffness);
  stiffness_[mode] = stiffness;
}
Real TwoBodyTireModel::getStiffness(DeformationMode mode) const {
  checkMode("getStiffness", mode);
  return stiffness_[mode];
}
void TwoBodyTireModel::setDamping(Real dampingCoefficient, DeformationMode mode) {
  checkMode("setDamping", mode);
  detail::requireNonNegative("TwoBodyTireModel::setDamping", "damping", dampingCoefficient);
  dampingCoef_[mode] = dampingCoefficient;
}
Real TwoBodyTireModel::getDamping(DeformationMode mode) const {
  checkMode("getDamping", mode);
  return dampingCoef_[mode];
}

Vec3 TwoBodyTireModel::getRotationAxis() const { return getFrame(1).q * Vec3::UnitZ(); }

Vec3 TwoBodyTireModel::getRadialDeflectionVector() const {
  const FrameState f = state();
  const Vec3 d = f.pA - f.pB;
  const Vec3 z = f.RB.col(2);
  return d - z.dot(d) * z;
}

Real TwoBodyTireModel::getDeformation(DeformationMode mode) const {
  checkMode("getDeformation", mode);
  const FrameState f = state();
  switch (mode) {
    case RADIAL: return getRadialDeflectionVector().norm();
    case LATERAL: return f.RB.col(2).dot(f.pA - f.pB);
    case BENDING: {
      const Vec3 th = rotationError(f);
      return std::hypot(th.x(), th.y());
    }
    default: return rotationError(f).z();
  }
}

Vec3 TwoBodyTireModel::getForceVector(DeformationMode mode) const {
  checkMode("getForceVector", mode);
  switch (mode) {
    case RADIAL: return lastForce_[RADIAL_1] * axisX_ + lastForce_[RADIAL_2] * axisY_;
    case LATERAL: return lastForce_[LATERAL_DOF] * axisZ_;
    case BENDING: return lastForce_[BENDING_1] * axisX_ + lastForce_[BENDING_2] * axisY_;
    default: return lastForce_[TORSIONAL_DOF] * axisZ_;
  }
}

Real TwoBodyTireModel::getForce(DeformationMode mode) const {
  checkMode("getForce", mode);
  switch (mode) {
    case RADIAL: return std::hypot(lastForce_[RADIAL_1], lastForce_[RADIAL_2]);
    case LATERAL: return lastForce_[LATERAL_DOF];
    case BENDING: return std::hypot(lastForce_[BENDING_1], lastForce_[BENDING_2]);
    default: return lastForce_[TORSIONAL_DOF];
  }
}

void TwoBodyTireModel::addRows(const ConstraintContext& ctx, std::vector<ConstraintRow>& rows,
                               std::vector<int>& outDofs) {
  const FrameState f = state();
  const Vec3 d = f.pA - f.pB;
  const Vec3 th = rotationError(f);
  axisX_ = f.RB.col(0);
  axisY_ = f.RB.col(1);
  axisZ_ = f.RB.col(2);
  // In-plane rows turn with the rim: warm-start them from last step's impulse vectors projected on the new axes.
  warm_[RADIAL_1] = radialWarm_.dot(axisX_);
  warm_[RADIAL_2] = radialWarm_.dot(axisY_);
  warm_[BENDING_1] = bendingWarm_.dot(axisX_);
  warm_[BENDING_2] = bendingWarm_.dot(axisY_);

  // Per mode: SPOOK compliance 1/K and damping time D/K (spring K parallel to damper D).
  const auto eps = [&](DeformationMode m) { return 1.0 / stiffness_[m]; };
  const auto tau = [&](DeformationMode m) { return dampingCoef_[m] / stiffness_[m]; };
  pushLinear(ctx, rows, outDofs, RADIAL_1, f, axisX_, axisX_.dot(d), eps(RADIAL), tau(RADIAL));
  pushLinear(ctx, rows, outDofs, RADIAL_2, f, axisY_, axisY_.dot(d), eps(RADIAL), tau(RADIAL));
  pushLinear(ctx, rows, outDofs, LATERAL_DOF, f, axisZ_, axisZ_.dot(d), eps(LATERAL), tau(LATERAL));
  pushAngular(ctx, rows, outDofs, BENDING_1, axisX_, th.x(), eps(BENDING), tau(BENDING));
  pushAngular(ctx, rows, outDofs, BENDING_2, axisY_, th.y(), eps(BENDING), tau(BENDING));
  pushAngular(ctx, rows, outDofs, TORSIONAL_DOF, axisZ_, th.z(), eps(TORSIONAL), tau(TORSIONAL));
}

void TwoBodyTireModel::storeResult(const ConstraintRow* rows, const int* dofs, size_t count, Real h) {
  Joint::storeResult(rows, dofs, count, h);
  radialWarm_ = warm_[RADIAL_1] * axisX_ + warm_[RADIAL_2] * axisY_;
  bendingWarm_ = warm_[BENDING_1] * axisX_ + warm_[BENDING_2] * axisY_;
}

void TwoBodyTireModel::onAdd(Simulation&) {
  // Adding the constraint already brings the listener in (addNotification); owning it too keeps the model's list
  // of what it installed complete (getNumOwned() == 2).
  addOwned(selfAs<Constraint>());
  addOwned(listener_);
}

// Both paths (Model and plain ConstraintRef) meet here, so the listener is tied to the constraint's membership.
// Simulation::add ignores a listener it already has: it is never installed twice.
void TwoBodyTireModel::addNotification(Simulation& sim) { sim.add(listener_); }
void TwoBodyTireModel::removeNotification(Simulation& sim) { sim.remove(listener_); }

void TwoBodyTireModel::alignFriction(GeometryContact& c) const {
  if (!alignFriction_) return;
  if (c.rigidBody(0) != a_.get() && c.rigidBody(1) != a_.get()) return;
  // The tire's own axle (its attachment frame's z): the rolling direction is axle x normal.
  const Vec3 axle = getFrame(0).q * Vec3::UnitZ();
  for (ContactPoint& p : c.points()) {
    const Vec3 roll = axle.cross(p.normal);
    if (roll.squaredNorm() > 1e-12) p.frictionDirection = roll;  // else the tire lies flat: leave the default
  }
}

}  // namespace scree
