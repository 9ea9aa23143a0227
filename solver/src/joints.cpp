// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scree/solver/joints.h"

#include <cmath>

#include "scree/core/errors.h"

namespace scree {

using detail::ConstraintRow;  // the solver row type (scree/solver/constraint_row.h)

namespace {
Quat frameFromAxis(const Vec3& axis) {
  // Frame whose z axis is `axis` (unit): rotation taking e_z to axis.
  return Quat::FromTwoVectors(Vec3::UnitZ(), axis);
}
Vec3 checkedAxis(const char* where, const Vec3& axis) {
  detail::requireFinite(where, "worldAxis", axis);
  if (axis.norm() < 1e-12) detail::throwInvalid(where, "worldAxis", axis, "must be non-zero");
  return axis.normalized();
}
Real wrapPi(Real a) { return std::remainder(a, 2 * M_PI); }
// A new row is a copy of the default row (constraint_row.h), as the contact rows are.
ConstraintRow& appendRow(std::vector<ConstraintRow>& rows) { return rows.emplace_back(detail::defaultConstraintRow()); }
// A [lower, upper] interval whose ends may be infinite on their own side.
void checkInterval(const char* where, Real lower, Real upper) {
  if (std::isnan(lower) || lower == INFINITY) detail::throwInvalid(where, "lower", lower, "must be < +inf");
  if (std::isnan(upper) || upper == -INFINITY) detail::throwInvalid(where, "upper", upper, "must be > -inf");
  if (lower > upper) detail::throwInvalid(where, "lower", lower, "must be <= upper");
}
}  // namespace

// ---- Joint --------------------------------------------------------------------------------------------------

Joint::Joint(RigidBodyRef a, RigidBodyRef b, const Vec3& worldPoint, const Quat& worldFrame, int numDofs, const char* type)
    : Constraint(std::move(a), std::move(b), numDofs, type) {
  const std::string where = std::string(type) + "::" + type;
  detail::requireFinite(where, "worldPoint", worldPoint);
  const Quat qf = worldFrame.normalized();
  const Transform ta = a_->getTransform();
  att_[0].point = ta.applyInverse(worldPoint);
  att_[0].rotation = ta.q.conjugate() * qf;
  if (b_) {
    const Transform tb = b_->getTransform();
    att_[1].point = tb.applyInverse(worldPoint);
    att_[1].rotation = tb.q.conjugate() * qf;
  } else {
    att_[1].point = worldPoint;
    att_[1].rotation = qf;
  }
}

Transform Joint::getFrame(int i) const {
  const RigidBody* b = getBodyAt(i);
  if (!b) return {att_[i].point, att_[i].rotation};
  const Transform t = b->getTransform();
  return {t.apply(att_[i].point), t.q * att_[i].rotation};
}

Joint::FrameState Joint::state() const {
  FrameState f;
  const Transform fa = getFrame(0), fb = getFrame(1);
  f.pA = fa.p;
  f.pB = fb.p;
  f.qA = fa.q;
  f.qB = fb.q;
  f.RA = fa.q.toRotationMatrix();
  f.RB = fb.q.toRotationMatrix();
  f.rA = f.pA - a_->getCmPosition();
  f.rB = b_ ? Vec3(f.pB - b_->getCmPosition()) : Vec3::Zero();
  return f;
}

Joint::FrameState Joint::anchors() const {
  FrameState f;
  const RigidBody* b0 = getBodyAt(0);
  const RigidBody* b1 = getBodyAt(1);
  f.pA = b0 ? b0->getTransform().apply(att_[0].point) : att_[0].point;
  f.pB = b1 ? b1->getTransform().apply(att_[1].point) : att_[1].point;
  f.rA = f.pA - a_->getCmPosition();
  f.rB = b_ ? Vec3(f.pB - b_->getCmPosition()) : Vec3::Zero();
  return f;
}

Real Joint::slidePosition() const {
  const FrameState f = state();
  return f.RB.col(2).dot(f.pA - f.pB);
}

Real Joint::slideSpeed() const {
  const FrameState f = state();
  const Vec3 u = f.RB.col(2);
  Real v = u.dot(a_->getVelocityAt(f.pA));
  if (b_) v -= u.dot(b_->getVelocityAt(f.pB));
  return v;
}

Vec3 Joint::rotationError(const FrameState& f) {
  Quat qr = f.qB.conjugate() * f.qA;
  if (qr.w() < 0) qr.coeffs() = -qr.coeffs();
  const Vec3 v = qr.vec();
  const Real s = v.norm();
  if (s < 1e-12) return 2.0 * v;
  return (2.0 * std::atan2(s, qr.w()) / s) * v;
}

void Joint::finishRow(const ConstraintContext& ctx, ConstraintRow& r, int dof, Real g, Real compliance,
                      Real damping) const {
  r.bodyA = ctx.indexA;
  r.bodyB = ctx.indexB;
  const SpookCoefficients co = spookHolonomic(ctx.h, compliance, damping);
  Real jv = r.jLinA.dot(a_->getVelocity()) + r.jAngA.dot(a_->getAngularVelocity());
  if (b_) jv += r.jLinB.dot(b_->getVelocity()) + r.jAngB.dot(b_->getAngularVelocity());
  r.rhs = -co.a * g + co.upsilon * jv;
  r.e = co.e;
  r.lambda = warm_[dof];
  r.solveType = solveType_;
  r.holonomic = true;
  r.drift = g + compliance * warm_[dof] / ctx.h;
}

void Joint::pushLinear(const ConstraintContext& ctx, std::vector<ConstraintRow>& rows, std::vector<int>& dofs, int dof,
                       const FrameState& f, const Vec3& u, Real g, Real compliance, Real damping) const {
  // Issue 18 (fixed cost of small scenes): rows are built in place in the row array (a ConstraintRow is about
  // 340 bytes; building it on the stack and copying it in was a third of chain20's row stage).
  ConstraintRow& r = appendRow(rows);
  r.jLinA = u;
  r.jAngA = f.rA.cross(u);
  r.jLinB = -u;
  r.jAngB = -f.rB.cross(u);
  r.leverA = f.rA.norm();
  r.leverB = f.rB.norm();
  finishRow(ctx, r, dof, g, compliance, damping);
  dofs.push_back(dof);
}

void Joint::pushAngular(const ConstraintContext& ctx, std::vector<ConstraintRow>& rows, std::vector<int>& dofs, int dof,
                        const Vec3& a, Real g, Real compliance, Real damping) const {
  ConstraintRow& r = appendRow(rows);
  r.jAngA = a;
  r.jAngB = -a;
  finishRow(ctx, r, dof, g, compliance, damping);
  dofs.push_back(dof);
}

void Joint::pushBending(const ConstraintContext& ctx, std::vector<ConstraintRow>& rows, std::vector<int>& dofs,
                        const FrameState& f, int firstDof) const {
  // Keep A's axis n_A orthogonal to B's x and y axes p:
  // d/dt (n_A . p) = (w_A x n_A) . p + n_A . (w_B x p) = w_A . (n_A x p) - w_B . (n_A x p).
  const Vec3 nA = f.RA.col(2);
  for (int k = 0; k < 2; ++k) {
    const Vec3 p = f.RB.col(k);
    const Vec3 c = nA.cross(p);
    ConstraintRow& r = appendRow(rows);
    r.jAngA = c;
    r.jAngB = -c;
    finishRow(ctx, r, firstDof + k, nA.dot(p), compliance_[firstDof + k], damping_[firstDof + k]);
    dofs.push_back(firstDof + k);
  }
}

// ---- controllers ---------------------------------------------------------------------------------------------

void Motor1D::setSpeed(Real v) {
  detail::requireFinite("Motor1D::setSpeed", "speed", v);
  speed_ = v;
}
void Motor1D::setForceRange(Real lower, Real upper) {
  checkInterval("Motor1D::setForceRange", lower, upper);
  lo_ = lower;
  hi_ = upper;
}
void Motor1D::setCompliance(Real c) {
  detail::requireNonNegative("Motor1D::setCompliance", "compliance", c);
  compliance_ = c;
}
void Range1D::setRange(Real lower, Real upper) {
  checkInterval("Range1D::setRange", lower, upper);
  lo_ = lower;
  hi_ = upper;
}
void Range1D::setCompliance(Real c) {
  detail::requireNonNegative("Range1D::setCompliance", "compliance", c);
  compliance_ = c;
}
void Range1D::setDamping(Real tau) {
  detail::requireNonNegative("Range1D::setDamping", "damping", tau);
  damping_ = tau;
}
void Lock1D::setPosition(Real p) {
  detail::requireFinite("Lock1D::setPosition", "position", p);
  pos_ = p;
}
void Lock1D::setCompliance(Real c) {
  detail::requireNonNegative("Lock1D::setCompliance", "compliance", c);
  compliance_ = c;
}
void Lock1D::setDamping(Real tau) {
  detail::requireNonNegative("Lock1D::setDamping", "damping", tau);
  damping_ = tau;
}

void Controlled1DJoint::addControllerRows(const ConstraintContext& ctx, std::vector<ConstraintRow>& rows,
                                          std::vector<int>& dofs, int firstDof, const Vec3& linA, const Vec3& angA,
                                          const Vec3& linB, const Vec3& angB, Real position) const {
  const Real h = ctx.h;
  auto base = [&](ConstraintRow& r) {
    r.bodyA = ctx.indexA;
    r.bodyB = ctx.indexB;
    r.jLinA = linA;
    r.jAngA = angA;
    r.jLinB = linB;
    r.jAngB = angB;
    r.solveType = solveType_;
  };
  Real speed = linA.dot(a_->getVelocity()) + angA.dot(a_->getAngularVelocity());
  if (b_) speed += linB.dot(b_->getVelocity()) + angB.dot(b_->getAngularVelocity());

  if (motor_.enabled_) {
    ConstraintRow r;
    base(r);
    r.rhs = motor_.speed_;
    r.e = spookVelocityRegularisation(h, motor_.compliance_);
    r.lo = std::isinf(motor_.lo_) ? -1e300 : motor_.lo_ * h;
    r.hi = std::isinf(motor_.hi_) ? 1e300 : motor_.hi_ * h;
    r.lambda = std::clamp(motor_.warm_, r.lo, r.hi);
    rows.push_back(r);
    dofs.push_back(firstDof);
  }
  if (range_.enabled_) {
    // Unilateral rows, active once the position is within one step of travel (plus a small margin) of a limit.
    const Real reach = std::abs(speed) * h + 1e-3;
    const SpookCoefficients co = spookHolonomic(h, range_.compliance_, range_.damping_);
    if (position - range_.lo_ < reach) {
      ConstraintRow r;
      base(r);
      const Real g = position - range_.lo_;
      r.rhs = -co.a * g + co.upsilon * speed;
      r.e = co.e;
      r.lo = 0;
      r.lambda = std::max<Real>(range_.warm_, 0);
      rows.push_back(r);
      dofs.push_back(firstDof + 1);
    } else if (range_.hi_ - position < reach) {
      ConstraintRow r;
      base(r);
      const Real g = position - range_.hi_;
      r.rhs = -co.a * g + co.upsilon * speed;
      r.e = co.e;
      r.hi = 0;
      r.lo = -1e300;
      r.lambda = std::min<Real>(range_.warm_, 0);
      rows.push_back(r);
      dofs.push_back(firstDof + 1);
    }
  }
  if (lock_.enabled_) {
    ConstraintRow r;
    base(r);
    const SpookCoefficients co = spookHolonomic(h, lock_.compliance_, lock_.damping_);
    r.rhs = -co.a * (position - lock_.pos_) + co.upsilon * speed;
    r.e = co.e;
    r.lambda = lock_.warm_;
    rows.push_back(r);
    dofs.push_back(firstDof + 2);
  }
}

void Controlled1DJoint::storeResult(const ConstraintRow* rows, const int* dofs, size_t count, Real h) {
  Constraint::storeResult(rows, dofs, count, h);
  motor_.warm_ = warm_[controllerDof_];
  range_.warm_ = warm_[controllerDof_ + 1];
  lock_.warm_ = warm_[controllerDof_ + 2];
  motor_.force_ = lastForce_[controllerDof_];
  range_.force_ = lastForce_[controllerDof_ + 1];
  lock_.force_ = lastForce_[controllerDof_ + 2];
}

// ---- BallJoint ----------------------------------------------------------------------------------------------

BallJoint::BallJoint(RigidBodyRef a, RigidBodyRef b, const Vec3& worldPoint)
    : Joint(std::move(a), std::move(b), worldPoint, Quat::Identity(), NUM_DOFS, "BallJoint") {}

void BallJoint::addRows(const ConstraintContext& ctx, std::vector<ConstraintRow>& rows, std::vector<int>& outDofs) {
  // Issue 18 (chain20's row cost): the rows need the anchors only; state()'s two frame rotations (quaternion
  // products and rotation matrices) were a third of this function's instructions.
  const FrameState f = anchors();
  const Vec3 d = f.pA - f.pB;
  for (int k = 0; k < 3; ++k) {
    const Vec3 u = Vec3::Unit(k);
    pushLinear(ctx, rows, outDofs, k, f, u, u.dot(d), compliance_[k], damping_[k]);
  }
}

// ---- Hinge --------------------------------------------------------------------------------------------------

Hinge::Hinge(RigidBodyRef a, RigidBodyRef b, const Vec3& worldPoint, const Vec3& worldAxis)
    : Controlled1DJoint(std::move(a), std::move(b), worldPoint, frameFromAxis(checkedAxis("Hinge::Hinge", worldAxis)),
                        NUM_DOFS, "Hinge") {
  controllerDof_ = MOTOR;
}

Real Hinge::getAngle() const {
  const FrameState f = state();
  // Angle of A's x axis about B's z axis, measured in B's x-y plane; unwrapped against the last value.
  const Vec3 xa = f.RA.col(0);
  const Real raw = std::atan2(f.RB.col(1).dot(xa), f.RB.col(0).dot(xa));
  lastAngle_ += wrapPi(raw - lastAngle_);
  return lastAngle_;
}

Real Hinge::getCurrentSpeed() const {
  const Vec3 n = getFrame(1).q * Vec3::UnitZ();
  Real w = n.dot(a_->getAngularVelocity());
  if (b_) w -= n.dot(b_->getAngularVelocity());
  return w;
}

void Hinge::addRows(const ConstraintContext& ctx, std::vector<ConstraintRow>& rows, std::vector<int>& outDofs) {
  const FrameState f = state();
  const Vec3 d = f.pA - f.pB;
  for (int k = 0; k < 3; ++k) {
    const Vec3 u = f.RB.col(k);
    pushLinear(ctx, rows, outDofs, k, f, u, u.dot(d), compliance_[k], damping_[k]);
  }
  pushBending(ctx, rows, outDofs, f, ROTATIONAL_1);
  const Vec3 n = f.RB.col(2);
  addControllerRows(ctx, rows, outDofs, MOTOR, Vec3::Zero(), n, Vec3::Zero(), -n, getAngle());
}

// ---- Prismatic ----------------------------------------------------------------------------------------------

Prismatic::Prismatic(RigidBodyRef a, RigidBodyRef b, const Vec3& worldPoint, const Vec3& worldAxis)
    : Controlled1DJoint(std::move(a), std::move(b), worldPoint,
                        frameFromAxis(checkedAxis("Prismatic::Prismatic", worldAxis)), NUM_DOFS, "Prismatic") {
  controllerDof_ = MOTOR;
}

Real Prismatic::getAngle() const { return slidePosition(); }
Real Prismatic::getCurrentSpeed() const { return slideSpeed(); }

void Prismatic::addRows(const ConstraintContext& ctx, std::vector<ConstraintRow>& rows, std::vector<int>& outDofs) {
  const FrameState f = state();
  const Vec3 d = f.pA - f.pB;
  for (int k = 0; k < 2; ++k) {
    const Vec3 u = f.RB.col(k);
    pushLinear(ctx, rows, outDofs, k, f, u, u.dot(d), compliance_[k], damping_[k]);
  }
  const Vec3 th = rotationError(f);
  for (int k = 0; k < 3; ++k)
    pushAngular(ctx, rows, outDofs, ROTATIONAL_1 + k, f.RB.col(k), th[k], compliance_[ROTATIONAL_1 + k],
                damping_[ROTATIONAL_1 + k]);
  const Vec3 u = f.RB.col(2);
  addControllerRows(ctx, rows, outDofs, MOTOR, u, f.rA.cross(u), -u, -f.rB.cross(u), u.dot(d));
}

// ---- CylindricalJoint -----------------------------------------------------------------------------------------

CylindricalJoint::CylindricalJoint(RigidBodyRef a, RigidBodyRef b, const Vec3& worldPoint, const Vec3& worldAxis)
    : Controlled1DJoint(std::move(a), std::move(b), worldPoint,
                        frameFromAxis(checkedAxis("CylindricalJoint::CylindricalJoint", worldAxis)), NUM_DOFS,
                        "CylindricalJoint") {
  controllerDof_ = MOTOR;
}

Real CylindricalJoint::getAngle() const { return slidePosition(); }
Real CylindricalJoint::getCurrentSpeed() const { return slideSpeed(); }

void CylindricalJoint::addRows(const ConstraintContext& ctx, std::vector<ConstraintRow>& rows,
                               std::vector<int>& outDofs) {
  const FrameState f = state();
  const Vec3 d = f.pA - f.pB;
  for (int k = 0; k < 2; ++k) {
    const Vec3 u = f.RB.col(k);
    pushLinear(ctx, rows, outDofs, k, f, u, u.dot(d), compliance_[k], damping_[k]);
  }
  pushBending(ctx, rows, outDofs, f, ROTATIONAL_1);
  const Vec3 u = f.RB.col(2);
  addControllerRows(ctx, rows, outDofs, MOTOR, u, f.rA.cross(u), -u, -f.rB.cross(u), u.dot(d));
}

// ---- DistanceJoint -----------------------------------------------------------------------------------------

DistanceJoint::DistanceJoint(RigidBodyRef a, RigidBodyRef b, const Vec3& worldPointA, const Vec3& worldPointB)
    : Joint(std::move(a), std::move(b), worldPointA, Quat::Identity(), NUM_DOFS, "DistanceJoint") {
  detail::requireFinite("DistanceJoint::DistanceJoint", "worldPointB", worldPointB);
  const Real len = (worldPointB - worldPointA).norm();
  if (!(len > 1e-9)) detail::throwInvalid("DistanceJoint::DistanceJoint", "distance", len, "points must be apart");
  length_ = len;
  localB_ = b_ ? b_->getTransform().applyInverse(worldPointB) : worldPointB;
}

void DistanceJoint::setRestLength(Real l) {
  detail::requirePositive("DistanceJoint::setRestLength", "length", l);
  length_ = l;
}

Real DistanceJoint::getCurrentLength() const {
  const Vec3 pA = a_->getTransform().apply(att_[0].point);
  const Vec3 pB = b_ ? b_->getTransform().apply(localB_) : localB_;
  return (pB - pA).norm();
}

void DistanceJoint::addRows(const ConstraintContext& ctx, std::vector<ConstraintRow>& rows, std::vector<int>& outDofs) {
  FrameState f;
  f.pA = a_->getTransform().apply(att_[0].point);
  f.pB = b_ ? b_->getTransform().apply(localB_) : localB_;
  f.rA = f.pA - a_->getCmPosition();
  f.rB = b_ ? Vec3(f.pB - b_->getCmPosition()) : Vec3::Zero();
  const Vec3 d = f.pA - f.pB;
  const Real len = d.norm();
  if (len < 1e-12) return;  // direction undefined for this step
  const Vec3 u = d / len;
  pushLinear(ctx, rows, outDofs, DISTANCE, f, u, len - length_, compliance_[0], damping_[0]);
}

// ---- Generic6DofJoint / LockJoint ------------------------------------------------------------------------------

Generic6DofJoint::Generic6DofJoint(RigidBodyRef a, RigidBodyRef b, const Vec3& worldPoint, const Quat& worldFrame)
    : Joint(std::move(a), std::move(b), worldPoint,
            (detail::requireRotation("Generic6DofJoint::Generic6DofJoint", "worldFrame", worldFrame), worldFrame),
            NUM_DOFS, "Generic6DofJoint") {
  for (int k = 0; k < NUM_DOFS; ++k) {
    modes_[k] = LOCKED;
    stiffness_[k] = 1.0 / SpookDefaults::compliance;
    dampingCoef_[k] = SpookDefaults::damping / SpookDefaults::compliance;
  }
}

void Generic6DofJoint::setMode(int dof, Mode m) {
  checkDof("setMode", dof);
  if (m != FREE && m != LOCKED && m != COMPLIANT)
    detail::throwInvalid("Generic6DofJoint::setMode", "mode", (long long)m, "must be FREE, LOCKED or COMPLIANT");
  modes_[dof] = m;
}
Generic6DofJoint::Mode Generic6DofJoint::getMode(int dof) const {
  checkDof("getMode", dof);
  return modes_[dof];
}

void Generic6DofJoint::setStiffness(int dof, Real stiffness, Real dampingCoefficient) {
  checkDof("setStiffness", dof);
  detail::requirePositive("Generic6DofJoint::setStiffness", "stiffness", stiffness);
  detail::requireNonNegative("Generic6DofJoint::setStiffness", "dampingCoefficient", dampingCoefficient);
  stiffness_[dof] = stiffness;
  dampingCoef_[dof] = dampingCoefficient;
  modes_[dof] = COMPLIANT;
}
Real Generic6DofJoint::getStiffness(int dof) const {
  checkDof("getStiffness", dof);
  return stiffness_[dof];
}
Real Generic6DofJoint::getDampingCoefficient(int dof) const {
  checkDof("getDampingCoefficient", dof);
  return dampingCoef_[dof];
}

Vec3 Generic6DofJoint::getTranslationError() const {
  const FrameState f = state();
  return f.RB.transpose() * (f.pA - f.pB);
}
Vec3 Generic6DofJoint::getRotationError() const { return rotationError(state()); }

void Generic6DofJoint::addRows(const ConstraintContext& ctx, std::vector<ConstraintRow>& rows, std::vector<int>& outDofs) {
  const FrameState f = state();
  const Vec3 d = f.pA - f.pB;
  const Vec3 th = rotationError(f);
  for (int k = 0; k < NUM_DOFS; ++k) {
    if (modes_[k] == FREE) continue;
    // LOCKED uses the constraint's compliance/damping (setCompliance/setDamping); COMPLIANT maps K, D to
    // SPOOK: compliance 1/K, damping time D/K.
    const Real eps = modes_[k] == COMPLIANT ? 1.0 / stiffness_[k] : compliance_[k];
    const Real tau = modes_[k] == COMPLIANT ? dampingCoef_[k] / stiffness_[k] : damping_[k];
    if (k < 3) {
      const Vec3 u = f.RB.col(k);
      pushLinear(ctx, rows, outDofs, k, f, u, u.dot(d), eps, tau);
    } else {
      pushAngular(ctx, rows, outDofs, k, f.RB.col(k - 3), th[k - 3], eps, tau);
    }
  }
}

LockJoint::LockJoint(RigidBodyRef a, RigidBodyRef b)
    : Generic6DofJoint(a, std::move(b), a ? a->getPosition() : Vec3::Zero(), a ? a->getRotation() : Quat::Identity()) {}

}  // namespace scree
