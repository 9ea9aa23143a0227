// Contact rows stage (layout and warm start: contact_rows.h; the normal-row law: contact_law.h), and the
// particle rows stage, which hands this step's particle contacts to the particle stage (granular_stage.h).
#include "contact_rows.h"

#include <cmath>

#include "contact_law.h"
#include "rolling_radius.h"
#include "step_stages.h"

namespace scree::detail {

void buildContactRows(SimulationState& s) {
  const Real h = s.h;
  const Solver& solver = s.solver;
  s.rows.clear();
  s.pointRows.clear();
  s.couplings.clear();
  const ContactLawSettings law{h, solver.getRestitutionThreshold(), solver.getMaxPenetrationRecoverySpeed()};
  const bool warm = solver.getUseWarmStarting();
  size_t numPoints = 0, numWarm = 0, numSolvedContacts = 0;
  bool nonIterative = false;
  const Vec3 zero = Vec3::Zero();

  for (uint32_t ci = 0; ci < s.contacts.size(); ++ci) {
    GeometryContact& c = s.contacts[ci];
    if (!c.isEnabled() || c.isSensor()) continue;
    const int ia = s.solverIndex(c.rigidBody(0)), ib = s.solverIndex(c.rigidBody(1));
    const bool dynA = ia >= 0 && s.sb[ia].invMass > 0, dynB = ib >= 0 && s.sb[ib].invMass > 0;
    if (!dynA && !dynB) continue;
    const SurfaceParameters& mat = c.material();
    const FrictionModel* fm = c.frictionModel();
    const FrictionModel::Type ftype = fm ? fm->getType() : FrictionModel::ITERATIVE_PROJECTED_CONE;
    const FrictionModel::SolveType solveType = fm ? fm->getSolveType() : FrictionModel::ITERATIVE;
    if (solveType != FrictionModel::ITERATIVE) nonIterative = true;
    const uint64_t pair = contactPairKey(c);
    const Vec3 xa = ia >= 0 ? BodyAccess::cm(*s.bodies[ia]) : zero;
    const Vec3 xb = ib >= 0 ? BodyAccess::cm(*s.bodies[ib]) : zero;
    // Start-of-step and free (after forces) velocities of both sides.
    const Vec3 va0 = ia >= 0 ? s.vStart[ia] : zero, wa0 = ia >= 0 ? s.wStart[ia] : zero;
    const Vec3 vb0 = ib >= 0 ? s.vStart[ib] : zero, wb0 = ib >= 0 ? s.wStart[ib] : zero;
    const Vec3 vaF = ia >= 0 ? s.sb[ia].v : zero, waF = ia >= 0 ? s.sb[ia].w : zero;
    const Vec3 vbF = ib >= 0 ? s.sb[ib].v : zero, wbF = ib >= 0 ? s.sb[ib].w : zero;

    // Rolling resistance: resisting torque about the tangents bounded by coefficient * r_eff * normal force,
    // r_eff the harmonic combination of the rolling radii (the single radius against a flat shape).
    Real rollMu = 0;
    if (mat.getRollingResistanceCoefficient() > 0) {
      const Real r0 = rollingRadius(c.geometry(0)), r1 = rollingRadius(c.geometry(1));
      const Real reff = (r0 > 0 && r1 > 0) ? r0 * r1 / (r0 + r1) : std::max(r0, r1);
      rollMu = mat.getRollingResistanceCoefficient() * reff;
    }
    // Count active points to lay out rows: [friction and rolling rows of all points][normal rows].
    auto& pts = c.points();
    uint32_t nActive = 0, nFriction = 0;
    for (const ContactPoint& p : pts) {
      if (!p.enabled) continue;
      ++nActive;
      const Real mu = p.frictionCoefficient >= 0 ? p.frictionCoefficient : mat.getFrictionCoefficient();
      if (mu > 0) nFriction += 2;
      if (rollMu > 0) nFriction += 2;
    }
    if (nActive == 0) continue;
    ++numSolvedContacts;
    const int32_t base = int32_t(s.rows.size());
    int32_t nextFriction = base;
    int32_t nextNormal = base + int32_t(nFriction);
    s.rows.resize(s.rows.size() + nFriction + nActive);
    s.couplings.push_back({ia, ib, uint32_t(base), nFriction + nActive, false});
    // Weight-based normal impulse estimate for box friction on new contacts: the lighter dynamic body's weight.
    const Real massA = dynA ? 1.0 / s.sb[ia].invMass : 0, massB = dynB ? 1.0 / s.sb[ib].invMass : 0;
    const Real weightImpulse =
        ((dynA && dynB) ? std::min(massA, massB) : std::max(massA, massB)) * s.gravity.norm() * h / Real(nActive);

    for (uint32_t pi = 0; pi < pts.size(); ++pi) {
      ContactPoint& p = pts[pi];
      if (!p.enabled) continue;
      ++numPoints;
      const Vec3& n = p.normal;
      const Vec3 ra = p.point - xa, rb = p.point - xb;
      const WarmStartCache::Entry* ce = warm ? s.warmStart.find(pair, p.featureId, p.point) : nullptr;
      if (ce) ++numWarm;

      // --- normal row (contact_law.h) ---
      ConstraintRow& r = s.rows[nextNormal];
      r = pointRow(ia, ib, ra, rb, n);
      r.solveType = solveType;
      const Real E = p.youngsModulus > 0 ? p.youngsModulus : mat.getYoungsModulus();
      const Real tau = p.damping >= 0 ? p.damping : mat.getDamping();
      NormalContactState cs;
      cs.depth = p.depth;
      cs.vn0 = r.jLinA.dot(va0) + r.jAngA.dot(wa0) + r.jLinB.dot(vb0) + r.jAngB.dot(wb0);
      cs.vnFree = r.jLinA.dot(vaF) + r.jAngA.dot(waF) + r.jLinB.dot(vbF) + r.jAngB.dot(wbF);
      cs.rememberedImpact = ce ? ce->impactSpeed : 0;
      // Adhesion: the contact's adhesive force is shared by its points; while the pair is in contact (points
      // within the contact margin) the row may pull with up to that force towards the rest overlap.
      cs.adhesiveForce = mat.getAdhesiveForce() / Real(nActive);
      cs.adhesiveOverlap = mat.getAdhesiveOverlap();
      cs.restitution = p.restitution >= 0 ? p.restitution : mat.getRestitution();
      const NormalRowCoefficients nr = contactNormalRow(law, contactSpook(h, E, tau), cs);
      r.rhs = nr.rhs;
      r.e = nr.e;
      r.lo = nr.lo;
      r.hi = 1e300;
      r.lambda = ce ? std::max(ce->normal, r.lo) : 0.0;

      // --- friction rows ---
      const Real mu = p.frictionCoefficient >= 0 ? p.frictionCoefficient : mat.getFrictionCoefficient();
      int32_t t1Index = -1;
      Vec3 t1, t2;
      orthonormalBasis(n, t1, t2);
      if (p.frictionDirection != Vec3::Zero()) {
        // A listener's primary direction (e.g. a tire's rolling direction): its tangential part, if any.
        const Vec3 d = p.frictionDirection - n.dot(p.frictionDirection) * n;
        const Real len = d.norm();
        if (len > 1e-9 * p.frictionDirection.norm()) {
          t1 = d / len;
          t2 = n.cross(t1);
        }
      }
      if (mu > 0) {
        t1Index = nextFriction;
        const Real eVisc = spookVelocityRegularisation(h, mat.getSurfaceViscosity());
        const Real lnEst = ce && ce->normal > 0 ? ce->normal : weightImpulse;
        for (int k = 0; k < 2; ++k) {
          const Vec3& t = k == 0 ? t1 : t2;
          ConstraintRow& f = s.rows[nextFriction + k];
          f = pointRow(ia, ib, ra, rb, t);
          f.rhs = p.surfaceVelocity.dot(t);
          f.e = eVisc;
          f.mu = mu;
          f.solveType = solveType;
          f.friction = true;
          f.lambda = ce ? ce->friction.dot(t) : 0.0;
          switch (ftype) {
            case FrictionModel::BOX: {
              const Real lim = std::isinf(mu) ? 1e300 : mu * lnEst;
              f.lo = -lim;
              f.hi = lim;
              f.lambda = std::clamp(f.lambda, f.lo, f.hi);
              break;
            }
            case FrictionModel::SCALED_BOX: f.normalRow = nextNormal; break;
            case FrictionModel::ITERATIVE_PROJECTED_CONE:
              f.normalRow = nextNormal;
              if (k == 0) f.pairedRow = nextFriction + 1;
              break;
          }
        }
        nextFriction += 2;
      }
      if (rollMu > 0) {
        // Two angular rows on the relative rotation about the tangents, solved as a disc like the cone.
        for (int k = 0; k < 2; ++k) {
          const Vec3& t = k == 0 ? t1 : t2;
          ConstraintRow& f = s.rows[nextFriction + k];
          f = ConstraintRow{};
          f.bodyA = ia;
          f.bodyB = ib;
          f.jAngA = t;
          f.jAngB = -t;
          f.mu = rollMu;
          f.normalRow = nextNormal;
          f.solveType = solveType;
          f.friction = true;
          if (k == 0) f.pairedRow = nextFriction + 1;
        }
        nextFriction += 2;
      }
      s.pointRows.push_back({ci, pi, nextNormal, t1Index, t1, t2, nr.impactSpeed});
      ++nextNormal;
    }
  }
  s.nonIterativeRows = nonIterative;

  SolverStats& st = s.solverStats();
  st.numContacts = numSolvedContacts;
  st.numContactPoints = numPoints;
  st.numWarmStarted = numWarm;
  s.stats.numContacts = s.contacts.size();
  s.stats.numContactPoints = numPoints;
}

void buildParticleRows(SimulationState& s) {
  if (!s.granularStep) return;
  const ParticleContactLists lists{&s.particleCollider.getParticleParticleContacts(),
                                   &s.particleCollider.getParticleGeometryContacts(), &s.particleGeometrySides,
                                   s.particleCollider.getCellSize()};
  s.particles.buildRows(s.granular, lists, s.materials, s.solver, s.sb,
                        [&s](const RigidBody* b) { return s.solverIndex(b); }, s.gravity, s.h);
  s.stats.numParticleContacts = s.particles.numUnits();
}

}  // namespace scree::detail
