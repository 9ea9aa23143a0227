// Simulation: the step pipeline. The only solver file that includes collide headers.
#include "scree/solver/simulation.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_set>

#include "body_access.h"
#include "granular_stage.h"
#include "integrator.h"
#include "rolling_radius.h"
#include "scree/collide/narrowphase.h"
#include "scree/core/errors.h"
#include "scree/core/logger.h"
#include "scree/solver/direct.h"
#include "scree/solver/pgs.h"
#include "scree/solver/spook.h"

namespace scree {

using detail::BodyAccess;

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

uint64_t pairKeyOf(const GeometryContact& c) {
  return (uint64_t(c.geometry(0)->getId()) << 32) | c.geometry(1)->getId();
}
bool touching(const GeometryContact& c) {
  for (const ContactPoint& p : c.points())
    if (p.depth >= 0) return true;
  return false;
}
}  // namespace

struct Simulation::Impl {
  // Per body (index = position in bodies_): solver state, start-of-step velocities, last finite pose.
  std::vector<SolverBodyState> sb;
  std::vector<Vec3> vStart, wStart;
  std::vector<Vec3> savedX;
  std::vector<Quat> savedQ;
  std::vector<std::vector<Geometry*>> registered;  // geometries of each body known to the space

  std::vector<ConstraintRow> rows;
  // Contact point -> its rows.
  struct PointRows {
    uint32_t contact, point;
    int32_t normal, t1;  // t1 = -1: no friction rows; t2 = t1 + 1
    Vec3 tangent1, tangent2;
    Real impactSpeed;
  };
  std::vector<PointRows> pointRows;
  // Row range and solver bodies of each solved contact and constraint (for shock propagation).
  struct ContactRange {
    int32_t ia, ib;
    uint32_t begin, count;
    bool joint;
  };
  std::vector<ContactRange> contactRanges;
  std::vector<int> level;            // support level per body: 0 static/kinematic, 1 touches those, ...
  std::vector<std::vector<uint32_t>> adjacency;
  std::vector<PgsSolver::ShockRange> shock;
  std::vector<uint32_t> frontier;                 // scratch of buildShockOrder
  std::vector<std::pair<int, uint32_t>> order;    // scratch of buildShockOrder
  struct ConstraintRange {
    Constraint* c;
    uint32_t begin, count;
  };
  std::vector<ConstraintRange> ranges;
  std::vector<int> rowDofs;

  // Warm-start cache, sorted by (pair, feature).
  struct CacheEntry {
    uint64_t pair;
    uint32_t feature;
    Real normal;
    Vec3 friction;
    Real impactSpeed;
    bool operator<(const CacheEntry& o) const { return pair != o.pair ? pair < o.pair : feature < o.feature; }
  };
  std::vector<CacheEntry> cache, nextCache;
  // Touching pairs of the last step (sorted) with their geometries, for impact/separation events.
  std::vector<std::pair<uint64_t, std::pair<Geometry*, Geometry*>>> prevPairs, curPairs;
  bool warnedSolveType = false;
  // Particle path (granular_stage.h); granularStep: the particle system is in this step (destroys deferred).
  detail::GranularStage granular;
  bool granularStep = false;
  DirectSolver direct;
  std::vector<uint32_t> directSet, iterSet;
  std::vector<Real> geomK;
  bool pureIterative = false;  // some row is only in the iterative set
  bool nonIterativeRows = false;  // buildRows made a row whose solve type is not ITERATIVE
  // Post-step position projection (projectPositions): its own direct solver, so each keeps its cached analysis.
  DirectSolver projector;
  std::vector<ConstraintRow> projRows;
  std::vector<int> projDofs;
  std::vector<uint32_t> projSet;
  std::vector<SolverBodyState> projBodies;
  std::unordered_set<const Constraint*> reportedSeparated;  // separated constraints already logged

  const CacheEntry* find(uint64_t pair, uint32_t feature) const {
    CacheEntry key{pair, feature, 0, Vec3::Zero(), 0};
    auto it = std::lower_bound(cache.begin(), cache.end(), key);
    if (it != cache.end() && it->pair == pair && it->feature == feature) return &*it;
    return nullptr;
  }
};

Simulation::Simulation() : impl_(std::make_unique<Impl>()) {}
Simulation::~Simulation() {
  // Models may own themselves through their items (a tire model is its own constraint): let them go.
  for (auto& model : models_) {
    model->owned_.clear();
    model->sim_ = nullptr;
  }
  for (auto& b : bodies_) BodyAccess::simIndex(*b) = -1;
}

// ---- membership --------------------------------------------------------------------------------------------

void Simulation::add(RigidBodyRef body) {
  detail::requireNonNull("Simulation::add", "rigidBody", body.get());
  int& idx = BodyAccess::simIndex(*body);
  if (idx >= 0) {
    if (size_t(idx) < bodies_.size() && bodies_[idx] == body) return;
    throw std::invalid_argument("Simulation::add: rigidBody \"" + body->getName() +
                                "\" is invalid (already in another simulation)");
  }
  idx = int(bodies_.size());
  bodies_.push_back(body);
  impl_->registered.emplace_back();
  for (const GeometryRef& g : body->getGeometries()) {
    space_.add(g);
    impl_->registered.back().push_back(g.get());
  }
}

bool Simulation::remove(const RigidBodyRef& body) {
  if (!body) return false;
  int idx = BodyAccess::simIndex(*body);
  if (idx < 0 || size_t(idx) >= bodies_.size() || bodies_[idx] != body) return false;
  for (Geometry* g : impl_->registered[idx]) {
    for (const GeometryRef& ref : space_.getGeometries())
      if (ref.get() == g) {
        GeometryRef keep = ref;
        space_.remove(keep);
        break;
      }
  }
  const size_t last = bodies_.size() - 1;
  if (size_t(idx) != last) {
    bodies_[idx] = bodies_[last];
    impl_->registered[idx] = std::move(impl_->registered[last]);
    BodyAccess::simIndex(*bodies_[idx]) = idx;
  }
  bodies_.pop_back();
  impl_->registered.pop_back();
  BodyAccess::simIndex(*body) = -1;
  // Forget event state involving the body's geometries.
  auto& pp = impl_->prevPairs;
  pp.erase(std::remove_if(pp.begin(), pp.end(),
                          [&](const auto& e) {
                            return e.second.first->getRigidBody() == body.get() ||
                                   e.second.second->getRigidBody() == body.get();
                          }),
           pp.end());
  return true;
}

void Simulation::add(GeometryRef geometry) {
  detail::requireNonNull("Simulation::add", "geometry", geometry.get());
  if (geometry->getRigidBody() != nullptr)
    throw std::invalid_argument("Simulation::add: geometry \"" + geometry->getName() +
                                "\" is invalid (it belongs to a body: add the body instead)");
  if (space_.contains(geometry.get())) return;
  space_.add(geometry);
  staticGeoms_.push_back(std::move(geometry));
}

bool Simulation::remove(const GeometryRef& geometry) {
  auto it = std::find(staticGeoms_.begin(), staticGeoms_.end(), geometry);
  if (it == staticGeoms_.end()) return false;
  space_.remove(geometry);
  staticGeoms_.erase(it);
  auto& pp = impl_->prevPairs;
  pp.erase(std::remove_if(pp.begin(), pp.end(),
                          [&](const auto& e) {
                            return e.second.first == geometry.get() || e.second.second == geometry.get();
                          }),
           pp.end());
  return true;
}

void Simulation::add(ConstraintRef c) {
  detail::requireNonNull("Simulation::add", "constraint", c.get());
  if (std::find(constraints_.begin(), constraints_.end(), c) != constraints_.end()) return;
  constraints_.push_back(c);
  if (!c->getEnableCollisions() && c->getBodyAt(1))
    space_.setEnableCollisions(c->getBodyAt(0), c->getBodyAt(1), false);
  c->addNotification(*this);
}

bool Simulation::remove(const ConstraintRef& c) {
  auto it = std::find(constraints_.begin(), constraints_.end(), c);
  if (it == constraints_.end()) return false;
  c->removeNotification(*this);
  constraints_.erase(it);
  impl_->reportedSeparated.erase(c.get());
  // Re-enable the pair unless another constraint still joins the same bodies without collisions.
  bool stillJoined = false;
  for (const auto& o : constraints_)
    if (!o->getEnableCollisions() &&
        ((o->getBodyAt(0) == c->getBodyAt(0) && o->getBodyAt(1) == c->getBodyAt(1)) ||
         (o->getBodyAt(0) == c->getBodyAt(1) && o->getBodyAt(1) == c->getBodyAt(0))))
      stillJoined = true;
  if (!stillJoined && c->getBodyAt(1)) space_.setEnableCollisions(c->getBodyAt(0), c->getBodyAt(1), true);
  return true;
}

namespace {
// Listener lists: add once (the listener learns its simulation), remove (it forgets it).
template <class Ref>
void addListener(std::vector<Ref>& list, Ref l, Simulation* sim, const char* param) {
  detail::requireNonNull("Simulation::add", param, l.get());
  if (std::find(list.begin(), list.end(), l) != list.end()) return;
  l->setSimulation(sim);
  list.push_back(std::move(l));
}
template <class Ref>
bool removeListener(std::vector<Ref>& list, const Ref& l) {
  auto it = std::find(list.begin(), list.end(), l);
  if (it == list.end()) return false;
  (*it)->setSimulation(nullptr);
  list.erase(it);
  return true;
}
}  // namespace

void Simulation::add(StepEventListenerRef l) { addListener(stepListeners_, std::move(l), this, "stepEventListener"); }
bool Simulation::remove(const StepEventListenerRef& l) { return removeListener(stepListeners_, l); }
void Simulation::add(ContactEventListenerRef l) {
  addListener(contactListeners_, std::move(l), this, "contactEventListener");
}
bool Simulation::remove(const ContactEventListenerRef& l) { return removeListener(contactListeners_, l); }

void Simulation::setTimeStep(Real h) {
  detail::requirePositive("Simulation::setTimeStep", "timeStep", h);
  h_ = h;
}
void Simulation::setUniformGravity(const Vec3& g) {
  detail::requireFinite("Simulation::setUniformGravity", "gravity", g);
  gravity_ = g;
}
void Simulation::setEnableCollisions(const std::string& a, const std::string& b, bool enable) {
  space_.setEnablePair(Geometry::groupId(a), Geometry::groupId(b), enable);
}

int Simulation::solverIndex(const RigidBody* b) const {
  if (!b) return -1;
  const int i = BodyAccess::simIndex(const_cast<RigidBody&>(*b));
  return (i >= 0 && size_t(i) < bodies_.size() && bodies_[i].get() == b) ? i : -1;
}

// ---- the step ----------------------------------------------------------------------------------------------

void Simulation::stepForward() {
  const auto t0 = Clock::now();
  report_ = StepReport{};
  auto timed = [](double& slot, auto&& fn) {
    const auto s = Clock::now();
    fn();
    slot = since(s);
  };
  timed(stats_.preCollide, [&] { runPreCollide(); });
  timed(stats_.collide, [&] { runCollide(); });
  timed(stats_.contactEvents, [&] { runContactEvents(); });
  timed(stats_.pre, [&] { runPre(); });
  timed(stats_.rows, [&] { buildRows(); });
  timed(stats_.solve, [&] { solve(); });
  timed(stats_.integrate, [&] {
    integrate();
    storeContactResults();
    projectPositions();
    checkFinite();
  });
  time_ += h_;
  timed(stats_.post, [&] { runPost(); });
  stats_.total = since(t0);
}

void Simulation::stepTo(Real time) {
  detail::requireFinite("Simulation::stepTo", "time", time);
  while (time_ < time - 0.5 * h_) stepForward();
}

void Simulation::runPreCollide() {
  for (auto& l : stepListeners_)
    if (l->getMask() & StepEventListener::PRE_COLLIDE) l->preCollide(time_);
}

void Simulation::runCollide() {
  // Pick up geometries added to or removed from bodies since the last step.
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const auto& geoms = bodies_[i]->getGeometries();
    auto& reg = impl_->registered[i];
    bool same = geoms.size() == reg.size();
    for (size_t k = 0; same && k < geoms.size(); ++k) same = geoms[k].get() == reg[k];
    if (same) continue;
    for (Geometry* g : reg) {
      bool kept = false;
      for (const auto& ng : geoms) kept |= ng.get() == g;
      if (!kept)
        for (const GeometryRef& ref : space_.getGeometries())
          if (ref.get() == g) {
            GeometryRef keep = ref;
            space_.remove(keep);
            break;
          }
    }
    for (const auto& ng : geoms)
      if (!space_.contains(ng.get())) space_.add(ng);
    reg.clear();
    for (const auto& ng : geoms) reg.push_back(ng.get());
  }
  space_.collide(h_, contacts_);
  stats_.numBroadphasePairs = space_.getNumBroadphasePairs();

  // Resolve contact parameters per pair.
  for (GeometryContact& c : contacts_) {
    const Material* m0 = c.geometry(0)->getMaterial().get();
    const Material* m1 = c.geometry(1)->getMaterial().get();
    const FrictionModel* fm = nullptr;
    materials_.resolve(m0, m1, c.material(), &fm);
    c.setFrictionModel(fm);
  }

  // Particles: their own grid against each other and every geometry. Destroys are deferred from here to the
  // end of the step so that dense indices held by the contacts stay valid through the listeners.
  impl_->granularStep = impl_->granular.active(granular_);
  if (impl_->granularStep) {
    impl_->granular.collide(granular_, space_.getGeometries(), h_);
    granular_.beginDeferral();
  }
}

const std::vector<ParticleContact>& Simulation::getParticleParticleContacts() const {
  return impl_->granular.particleParticleContacts();
}
const std::vector<ParticleContact>& Simulation::getParticleGeometryContacts() const {
  return impl_->granular.particleGeometryContacts();
}

void Simulation::runContactEvents() {
  auto& cur = impl_->curPairs;
  auto& prev = impl_->prevPairs;
  cur.clear();
  bool anyRemoved = false;
  for (GeometryContact& c : contacts_) {
    if (!touching(c)) {
      // Speculative only: solved (so nothing tunnels), but no events; sensors ignore it.
      if (c.isSensor()) c.setEnable(false);
      continue;
    }
    const uint64_t key = pairKeyOf(c);
    auto it = std::lower_bound(prev.begin(), prev.end(), key, [](const auto& e, uint64_t k) { return e.first < k; });
    const bool impact = !(it != prev.end() && it->first == key);
    c.setImpact(impact);
    cur.push_back({key, {c.geometry(0), c.geometry(1)}});
    for (auto& l : contactListeners_) {
      const int want = impact ? ContactEventListener::IMPACT : ContactEventListener::CONTACT;
      if (!(l->getMask() & want) || !l->matches(c.geometry(0), c.geometry(1))) continue;
      const auto policy = impact ? l->impact(time_, c) : l->contact(time_, c);
      if (policy == ContactEventListener::REMOVE_CONTACT) {
        c.setEnable(false);
        c.points().clear();
        anyRemoved = true;
        break;
      }
    }
  }
  // Separation: touching last step, not now (cur is sorted because contacts are).
  bool wantSeparation = false;
  for (auto& l : contactListeners_) wantSeparation |= (l->getMask() & ContactEventListener::SEPARATION) != 0;
  if (wantSeparation) {
    size_t j = 0;
    for (const auto& e : prev) {
      while (j < cur.size() && cur[j].first < e.first) ++j;
      if (j < cur.size() && cur[j].first == e.first) continue;
      for (auto& l : contactListeners_)
        if ((l->getMask() & ContactEventListener::SEPARATION) && l->matches(e.second.first, e.second.second))
          l->separation(time_, e.second.first, e.second.second);
    }
  }
  std::swap(prev, cur);
  if (anyRemoved)
    contacts_.erase(std::remove_if(contacts_.begin(), contacts_.end(),
                                   [](const GeometryContact& c) { return c.points().empty(); }),
                    contacts_.end());
}

void Simulation::runPre() {
  for (auto& l : stepListeners_)
    if (l->getMask() & StepEventListener::PRE_STEP) l->pre(time_);
}

void Simulation::buildRows() {
  Impl& m = *impl_;
  const size_t nb = bodies_.size();
  m.sb.resize(nb);
  m.vStart.resize(nb);
  m.wStart.resize(nb);
  m.savedX.resize(nb);
  m.savedQ.resize(nb);
  const Real h = h_;

  // External forces and damping give the free velocities (v + h M^-1 f); gyroscopic effects are handled by
  // the rotation integrator (integrator.h).
  size_t numDynamic = 0;
  for (size_t i = 0; i < nb; ++i) {
    RigidBody& b = *bodies_[i];
    SolverBodyState& s = m.sb[i];
    m.vStart[i] = b.getVelocity();
    m.wStart[i] = b.getAngularVelocity();
    m.savedX[i] = BodyAccess::cm(b);
    m.savedQ[i] = BodyAccess::rotation(b);
    if (b.getMotionControl() == RigidBody::DYNAMICS) {
      ++numDynamic;
      s.invMass = b.getInvMass();
      s.invInertia = b.getInvInertiaWorld();
      s.v = (b.getVelocity() + h * (gravity_ + b.getForce() * s.invMass)) / (1.0 + h * b.getLinearVelocityDamping());
      s.w = (b.getAngularVelocity() + h * (s.invInertia * b.getTorque())) / (1.0 + h * b.getAngularVelocityDamping());
    } else {
      s.invMass = 0;
      s.invInertia.setZero();
      s.v = b.getMotionControl() == RigidBody::KINEMATICS ? b.getVelocity() : Vec3::Zero();
      s.w = b.getMotionControl() == RigidBody::KINEMATICS ? b.getAngularVelocity() : Vec3::Zero();
    }
  }

  m.rows.clear();
  m.pointRows.clear();
  m.contactRanges.clear();
  const Real threshold = solver_.getRestitutionThreshold();
  const Real maxRecovery = solver_.getMaxPenetrationRecoverySpeed();
  const bool warm = solver_.getUseWarmStarting();
  size_t numPoints = 0, numWarm = 0, numSolvedContacts = 0;
  bool nonIterative = false;

  for (uint32_t ci = 0; ci < contacts_.size(); ++ci) {
    GeometryContact& c = contacts_[ci];
    if (!c.isEnabled() || c.isSensor()) continue;
    const int ia = solverIndex(c.rigidBody(0)), ib = solverIndex(c.rigidBody(1));
    const bool dynA = ia >= 0 && m.sb[ia].invMass > 0, dynB = ib >= 0 && m.sb[ib].invMass > 0;
    if (!dynA && !dynB) continue;
    const SurfaceParameters& mat = c.material();
    const FrictionModel* fm = c.frictionModel();
    const FrictionModel::Type ftype = fm ? fm->getType() : FrictionModel::ITERATIVE_PROJECTED_CONE;
    if (fm && fm->getSolveType() != FrictionModel::ITERATIVE) nonIterative = true;
    const uint64_t pair = pairKeyOf(c);
    const Vec3 xa = ia >= 0 ? BodyAccess::cm(*bodies_[ia]) : Vec3::Zero();
    const Vec3 xb = ib >= 0 ? BodyAccess::cm(*bodies_[ib]) : Vec3::Zero();
    const Vec3 va0 = ia >= 0 ? m.vStart[ia] : Vec3::Zero(), wa0 = ia >= 0 ? m.wStart[ia] : Vec3::Zero();
    const Vec3 vb0 = ib >= 0 ? m.vStart[ib] : Vec3::Zero(), wb0 = ib >= 0 ? m.wStart[ib] : Vec3::Zero();

    // Rolling resistance: resisting torque about the tangents bounded by coefficient * r_eff * normal force,
    // r_eff the harmonic combination of the rolling radii (the single radius against a flat shape).
    Real rollMu = 0;
    if (mat.getRollingResistanceCoefficient() > 0) {
      const Real r0 = detail::rollingRadius(c.geometry(0)), r1 = detail::rollingRadius(c.geometry(1));
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
    const int32_t base = int32_t(m.rows.size());
    int32_t nextFriction = base;
    int32_t nextNormal = base + int32_t(nFriction);
    m.rows.resize(m.rows.size() + nFriction + nActive);
    m.contactRanges.push_back({ia, ib, uint32_t(base), nFriction + nActive, false});
    // Weight-based normal impulse estimate for box friction on new contacts: the lighter dynamic body's weight.
    const Real massA = dynA ? 1.0 / m.sb[ia].invMass : 0, massB = dynB ? 1.0 / m.sb[ib].invMass : 0;
    const Real weightImpulse =
        ((dynA && dynB) ? std::min(massA, massB) : std::max(massA, massB)) * gravity_.norm() * h / Real(nActive);

    for (uint32_t pi = 0; pi < pts.size(); ++pi) {
      ContactPoint& p = pts[pi];
      if (!p.enabled) continue;
      ++numPoints;
      const Vec3& n = p.normal;
      const Vec3 ra = p.point - xa, rb = p.point - xb;
      const Impl::CacheEntry* ce = warm ? m.find(pair, p.featureId) : nullptr;
      if (ce) ++numWarm;

      // Row along direction d through the contact point: J = [d, ra x d, -d, -(rb x d)].
      auto pointRow = [&](ConstraintRow& row, const Vec3& d) {
        row = ConstraintRow{};
        row.bodyA = ia;
        row.bodyB = ib;
        row.jLinA = d;
        row.jAngA = ra.cross(d);
        row.jLinB = -d;
        row.jAngB = -rb.cross(d);
      };

      // --- normal row ---
      ConstraintRow& r = m.rows[nextNormal];
      pointRow(r, n);
      r.solveType = fm ? fm->getSolveType() : FrictionModel::ITERATIVE;
      const Real vn0 = r.jLinA.dot(va0) + r.jAngA.dot(wa0) + r.jLinB.dot(vb0) + r.jAngB.dot(wb0);
      Real impactSpeed = 0;
      const Real adhesiveForce = mat.getAdhesiveForce();
      const Real rest = p.restitution >= 0 ? p.restitution : mat.getRestitution();
      const Real remembered = ce ? ce->impactSpeed : 0;
      if (p.depth < 0 && adhesiveForce <= 0) {
        // Speculative: allow the approach to close the gap within this step, no force before that.
        r.rhs = p.depth / h;
        r.e = 0;
        r.lo = 0;
        const Real vnFree = r.jLinA.dot(ia >= 0 ? m.sb[ia].v : Vec3::Zero()) +
                            r.jAngA.dot(ia >= 0 ? m.sb[ia].w : Vec3::Zero()) +
                            r.jLinB.dot(ib >= 0 ? m.sb[ib].v : Vec3::Zero()) +
                            r.jAngB.dot(ib >= 0 ? m.sb[ib].w : Vec3::Zero());
        if (remembered > threshold) {
          // Last step closed the gap at the remembered speed: the surfaces touch now, bounce from here.
          r.rhs = std::max(r.rhs, rest * remembered);
        } else if (vnFree * h < p.depth && -vnFree > threshold) {
          // The free motion closes the gap this step: the row stops the body exactly at the surface. Remember the
          // approach speed so next step's impact stage uses the true speed, not the clamped one.
          impactSpeed = -vnFree;
        }
      } else {
        const Real E = p.youngsModulus > 0 ? p.youngsModulus : mat.getYoungsModulus();
        const Real tau = p.damping >= 0 ? p.damping : mat.getDamping();
        // Adhesion: the contact's adhesive force is shared by its points; while the pair is in contact (points
        // within the contact margin) the row may pull with up to that force towards the rest overlap.
        const Real adhF = adhesiveForce / Real(nActive), adhO = mat.getAdhesiveOverlap();
        const SpookCoefficients co = spookHolonomic(h, 1.0 / E, tau);
        // g is the constraint violation: negative when the overlap exceeds the rest overlap.
        const Real g = (adhF > 0 ? adhO : 0.0) - p.depth;
        Real bias = -co.a * g;
        if (maxRecovery > 0) bias = std::min(bias, maxRecovery);
        r.rhs = bias + co.upsilon * vn0;
        r.e = co.e;
        r.lo = adhF > 0 ? (std::isinf(adhF) ? -1e300 : -adhF * h) : 0.0;
        // Impact stage: an approach faster than the threshold (now, or remembered from a speculative step)
        // gets the Newtonian target v_n+ = e * approach speed instead of the soft spring.
        const Real approach = std::max(remembered, -vn0);
        if (approach > threshold) r.rhs = std::max(r.rhs, rest * approach);
      }
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
          ConstraintRow& f = m.rows[nextFriction + k];
          pointRow(f, t);
          f.rhs = p.surfaceVelocity.dot(t);
          f.e = eVisc;
          f.mu = mu;
          f.solveType = r.solveType;
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
          ConstraintRow& f = m.rows[nextFriction + k];
          f = ConstraintRow{};
          f.bodyA = ia;
          f.bodyB = ib;
          f.jAngA = t;
          f.jAngB = -t;
          f.mu = rollMu;
          f.normalRow = nextNormal;
          f.solveType = r.solveType;
          f.friction = true;
          if (k == 0) f.pairedRow = nextFriction + 1;
        }
        nextFriction += 2;
      }
      m.pointRows.push_back({ci, pi, nextNormal, t1Index, t1, t2, impactSpeed});
      ++nextNormal;
    }
  }

  // Constraints (joints, models).
  const Real errorThreshold = solver_.getConstraintErrorThreshold();
  m.ranges.clear();
  m.rowDofs.assign(m.rows.size(), -1);
  for (auto& c : constraints_) {
    if (!c->getEnable()) continue;
    ConstraintContext ctx;
    ctx.h = h;
    ctx.indexA = solverIndex(c->getBodyAt(0));
    ctx.indexB = solverIndex(c->getBodyAt(1));
    const bool dynA = ctx.indexA >= 0 && m.sb[ctx.indexA].invMass > 0;
    const bool dynB = ctx.indexB >= 0 && m.sb[ctx.indexB].invMass > 0;
    if (!dynA && !dynB) continue;
    const uint32_t begin = uint32_t(m.rows.size());
    c->addRows(ctx, m.rows, m.rowDofs);
    if (c->getSolveType() != FrictionModel::ITERATIVE) nonIterative = true;
    // A joint that came apart: its rows' drift (position error beyond the elastic stretch of the last force)
    // is known here for free. Reported in the step report and logged once per constraint.
    Real drift = 0;
    for (size_t k = begin; k < m.rows.size(); ++k)
      if (m.rows[k].holonomic) drift = std::max(drift, std::abs(m.rows[k].drift));
    if (!(drift <= errorThreshold)) reportSeparated(*c, drift);
    m.ranges.push_back({c.get(), begin, uint32_t(m.rows.size() - begin)});
    // Joints couple bodies for support levels too (a chain hanging from the world is supported link by link).
    m.contactRanges.push_back({ctx.indexA, ctx.indexB, begin, uint32_t(m.rows.size() - begin), true});
  }
  m.nonIterativeRows = nonIterative;
  if (nonIterative && !m.warnedSolveType && !DirectSolver::available()) {
    m.warnedSolveType = true;
    Logger::warningOnce("scree.solveType.direct",
                        "DIRECT / SPLIT / DIRECT_AND_ITERATIVE solve types need SuiteSparse (built without "
                        "SCREE_WITH_SUITESPARSE): those rows are solved by the iterative PGS solver");
  }

  SolverStats& st = solver_.stats();
  st.numBodies = numDynamic;
  st.numContacts = numSolvedContacts;
  st.numContactPoints = numPoints;
  st.numRows = m.rows.size();
  st.numWarmStarted = numWarm;
  stats_.numContacts = contacts_.size();
  stats_.numContactPoints = numPoints;

  if (m.granularStep) {
    m.granular.buildRows(granular_, materials_, solver_, m.sb, [this](const RigidBody* b) { return solverIndex(b); },
                         gravity_, h);
    stats_.numParticleContacts = m.granular.numUnits();
  }
}

void Simulation::solve() {
  Impl& m = *impl_;
  SolverStats& st = solver_.stats();
  st.numDirectRows = st.numIterativeRows = st.numFactorisations = st.numPivots = st.numSymbolicAnalyses = 0;
  st.complementarityResidual = 0;
  st.factorisationTime = 0;
  st.directFallback = false;
  const bool particles = m.granularStep && m.granular.hasUnits();
  if (m.rows.empty() && !particles) {
    st.numIterations = 0;
    st.lastResidual = 0;
    return;
  }
  // Particle contacts whose contact material is not ITERATIVE (the manual's DIRECT particle mode,
  // granular_stage.h) become rows on solver bodies appended to m.sb, so they are classified, solved (one
  // DirectSolver call with the rigid direct set) and counted like rigid rows; finishDirect removes them again.
  const bool particleDirect = particles && m.granular.hasDirectUnits();
  if (particleDirect) {
    m.granular.prepare(granular_, m.sb);  // warm start first: the appended bodies copy these velocities
    m.granular.appendDirectRows(granular_, m.rows, m.sb);
  }
  // Direct set (DESIGN.md §2 step 7): DIRECT rows; SPLIT and DIRECT_AND_ITERATIVE rows except friction. PGS
  // sweeps the rest, and DIRECT_AND_ITERATIVE rows too (after their direct solve). Other particle contacts are
  // solved by the particle stage's parallel Gauss–Seidel.
  m.directSet.clear();
  m.iterSet.clear();
  bool split = false;
  m.pureIterative = false;
  // Scenes whose rows are all ITERATIVE skip the classification (no direct set).
  if (DirectSolver::available() && (m.nonIterativeRows || particleDirect))
    for (uint32_t i = 0; i < m.rows.size(); ++i) {
      const ConstraintRow& r = m.rows[i];
      const auto t = r.solveType;
      const bool direct = t == FrictionModel::DIRECT || (t != FrictionModel::ITERATIVE && !r.friction);
      if (direct) m.directSet.push_back(i);
      if (!direct || t == FrictionModel::DIRECT_AND_ITERATIVE) m.iterSet.push_back(i);
      m.pureIterative |= !direct;
      split |= t == FrictionModel::SPLIT && r.friction;
    }
  if (!m.directSet.empty()) addGeometricStiffness();
  const int iterations = solver_.getNumIterations();
  if (!m.rows.empty()) PgsSolver::prepare(m.rows, m.sb);
  if (particleDirect) m.granular.loadDirectImpulses(m.rows);
  else if (particles) m.granular.prepare(granular_, m.sb);
  if (!m.directSet.empty()) {
    // Rigid rows through the hybrid direct/iterative solve, then the particles against its result.
    solveHybrid(split);
    if (particleDirect) {
      m.granular.finishDirect(granular_, m.rows, m.sb);
      // The particle rows are gone again: keep the direct set valid for the position projection (ascending).
      while (!m.directSet.empty() && m.directSet.back() >= m.rows.size()) m.directSet.pop_back();
    }
    Real residual = st.lastResidual;
    if (particles && m.granular.hasIterativeUnits()) {
      for (int it = 0; it < iterations; ++it)
        residual = std::max(residual, m.granular.sweep(granular_, m.sb, it % 2 == 1));
      if (solver_.getUseShockPropagation() && gravity_.squaredNorm() > 0)
        m.granular.shockPass(granular_, m.sb, -gravity_.normalized(), 2);
    }
    st.lastResidual = residual;
    return;
  }
  st.numIterativeRows = m.rows.size();
  Real residual = 0;
  if (particles && m.granular.coupled() && !m.rows.empty()) {
    // Particles touch dynamic bodies: interleave one rigid sweep and one particle sweep per iteration so that
    // each side sees the other's impulses.
    for (int it = 0; it < iterations; ++it) {
      residual = PgsSolver::iterate(m.rows, m.sb, 1);
      residual = std::max(residual, m.granular.sweep(granular_, m.sb, it % 2 == 1));
    }
  } else {
    if (!m.rows.empty()) residual = PgsSolver::iterate(m.rows, m.sb, iterations);
    if (particles)
      for (int it = 0; it < iterations; ++it) residual = std::max(residual, m.granular.sweep(granular_, m.sb, it % 2 == 1));
  }
  if (particles && solver_.getUseShockPropagation() && gravity_.squaredNorm() > 0)
    m.granular.shockPass(granular_, m.sb, -gravity_.normalized(), 2);
  st.lastResidual = residual;
  st.numIterations = size_t(iterations);
  if (!m.rows.empty() && solver_.getUseShockPropagation() && !m.contactRanges.empty()) {
    buildShockOrder();
    PgsSolver::shockPass(m.rows, m.sb, m.shock, solver_.getNumShockIterations());
  }
}

void Simulation::addGeometricStiffness() {
  // A row's direction turns with its body: a joint carrying force f at lever r has a geometric stiffness |f| |r|
  // about the body's rotation axes that the step's linearised rows miss. With links much lighter than the load
  // it carries, that stiffness makes the linearised step unstable once h^2 |f| |r| exceeds the link's inertia
  // (the chain whips: 40 rad/s within 0.5 s for chain20 at dt 1/60). Following Andrews, Teichmann & Kry
  // (2017, "Geometric stiffness for real-time constrained multibody dynamics"), its diagonal approximation,
  // h^2 sum |lambda/h| |r| per body (last step's impulses), is added to the inertia seen by the solve. It damps
  // the unresolved fast rotation only; it vanishes as h^2 and leaves static loads and masses unchanged. Applied to
  // bodies of direct-set joint rows (Solver::setUseGeometricStiffness).
  Impl& m = *impl_;
  if (!solver_.getUseGeometricStiffness() || !computeGeometricStiffness()) return;
  for (size_t b = 0; b < m.sb.size(); ++b) {
    if (!(m.geomK[b] > 0) || !(m.sb[b].invMass > 0)) continue;
    const Mat3 I = m.sb[b].invInertia.inverse() + (h_ * h_ * m.geomK[b]) * Mat3::Identity();
    m.sb[b].invInertia = I.inverse();
  }
}

bool Simulation::computeGeometricStiffness() {
  // m.geomK[b] = sum over direct-set rows on b of |lambda / h| |r| (N m / rad), from the rows' current impulses.
  Impl& m = *impl_;
  m.geomK.assign(m.sb.size(), 0.0);
  bool any = false;
  for (uint32_t i : m.directSet) {
    const ConstraintRow& r = m.rows[i];
    const Real f = std::abs(r.lambda) / h_;
    if (r.bodyA >= 0 && r.leverA > 0) m.geomK[r.bodyA] += f * r.leverA, any = true;
    if (r.bodyB >= 0 && r.leverB > 0) m.geomK[r.bodyB] += f * r.leverB, any = true;
  }
  return any;
}

void Simulation::solveHybrid(bool finalDirect) {
  // Hybrid (DESIGN.md §4): direct solve of the direct set with the iterative rows' impulses held, then PGS sweeps
  // over the iterative set with the direct impulses held, numHybridRounds times; SPLIT friction ends with one
  // more direct solve of the normals. Shock propagation visits only couplings whose rows are all iterative.
  Impl& m = *impl_;
  SolverStats& st = solver_.stats();
  st.numDirectRows = m.directSet.size();
  st.numIterativeRows = m.pureIterative ? m.iterSet.size() : 0;
  DirectSolver::Settings ds;
  ds.form = solver_.getDirectForm();
  ds.maxPivots = solver_.getMaxPivots();
  auto direct = [&] {
    const DirectSolver::Result r = m.direct.solve(m.rows, m.directSet, m.sb, ds);
    st.numFactorisations += size_t(r.factorisations);
    st.numPivots += size_t(r.pivots);
    st.numSymbolicAnalyses += size_t(r.symbolicAnalyses);
    st.factorisationTime += r.factorSeconds;
    st.directForm = int(r.form);
    st.complementarityResidual = r.residual;
    if (!r.converged) {
      st.directFallback = true;
      Logger::warningOnce("scree.direct.fallback",
                          "DIRECT solver: no solution within the pivot cap (Solver::setMaxPivots) or the matrix "
                          "was not definite; the direct rows of such steps are finished by PGS "
                          "(SolverStats::directFallback)");
      st.complementarityResidual = PgsSolver::iterate(m.rows, m.sb, solver_.getNumIterations(), m.directSet);
    }
  };
  // Without rows that only PGS solves, there is nothing to alternate with: one direct solve.
  if (!m.pureIterative) m.iterSet.clear();
  const int rounds = m.iterSet.empty() ? 1 : solver_.getNumHybridRounds();
  const int sweeps = std::max(1, (solver_.getNumIterations() + rounds - 1) / rounds);
  st.numIterations = 0;
  st.lastResidual = 0;
  for (int round = 0; round < rounds; ++round) {
    direct();
    if (m.iterSet.empty()) break;
    st.lastResidual = PgsSolver::iterate(m.rows, m.sb, sweeps, m.iterSet);
    st.numIterations += size_t(sweeps);
  }
  if (!m.iterSet.empty() && solver_.getUseShockPropagation() && !m.contactRanges.empty()) {
    buildShockOrder();
    auto& sh = m.shock;
    sh.erase(std::remove_if(sh.begin(), sh.end(),
                            [&](const PgsSolver::ShockRange& r) {
                              for (uint32_t i = r.begin; i < r.begin + r.count; ++i)
                                if (m.rows[i].solveType != FrictionModel::ITERATIVE) return true;
                              return false;
                            }),
             sh.end());
    if (!sh.empty()) PgsSolver::shockPass(m.rows, m.sb, sh, solver_.getNumShockIterations());
  }
  if (finalDirect) direct();
}

void Simulation::buildShockOrder() {
  // Support levels by breadth-first search over the graph of contacts and constraints from non-dynamic bodies,
  // body-less geometries and the world (level 0). Couplings between different levels freeze the lower body in
  // the shock pass and are visited in increasing lower level; couplings within one level are left to the
  // sweeps.
  Impl& m = *impl_;
  const size_t nb = bodies_.size();
  const int kUnreached = 1 << 30;
  m.level.assign(nb, kUnreached);
  if (m.adjacency.size() < nb) m.adjacency.resize(nb);
  for (size_t i = 0; i < nb; ++i) m.adjacency[i].clear();
  auto& frontier = m.frontier;
  frontier.clear();
  for (uint32_t k = 0; k < m.contactRanges.size(); ++k) {
    const auto& c = m.contactRanges[k];
    if (c.ia >= 0) m.adjacency[c.ia].push_back(k);
    if (c.ib >= 0) m.adjacency[c.ib].push_back(k);
  }
  for (size_t i = 0; i < nb; ++i)
    if (m.sb[i].invMass == 0) {
      m.level[i] = 0;
      frontier.push_back(uint32_t(i));
    }
  for (const auto& c : m.contactRanges) {
    // A dynamic body touching a body-less (static) geometry, or jointed to the world, is at level 1.
    if (c.ia < 0 && c.ib >= 0 && m.level[c.ib] > 1) { m.level[c.ib] = 1; frontier.push_back(uint32_t(c.ib)); }
    if (c.ib < 0 && c.ia >= 0 && m.level[c.ia] > 1) { m.level[c.ia] = 1; frontier.push_back(uint32_t(c.ia)); }
  }
  // frontier may hold level-0 and level-1 seeds; process in level order.
  std::stable_sort(frontier.begin(), frontier.end(), [&](uint32_t x, uint32_t y) { return m.level[x] < m.level[y]; });
  for (size_t head = 0; head < frontier.size(); ++head) {
    const uint32_t b = frontier[head];
    for (uint32_t k : m.adjacency[b]) {
      const auto& c = m.contactRanges[k];
      const int other = c.ia == int32_t(b) ? c.ib : c.ia;
      if (other >= 0 && m.level[other] > m.level[b] + 1) {
        m.level[other] = m.level[b] + 1;
        frontier.push_back(uint32_t(other));
      }
    }
  }
  m.shock.clear();
  auto& order = m.order;
  order.clear();
  for (uint32_t k = 0; k < m.contactRanges.size(); ++k) {
    const auto& c = m.contactRanges[k];
    const int la = c.ia >= 0 ? m.level[c.ia] : 0, lb = c.ib >= 0 ? m.level[c.ib] : 0;
    if (la == lb) continue;
    if (c.joint && c.ia >= 0 && c.ib >= 0) {
      // A joint only propagates support from a body at least as heavy as the one it holds: freezing a light
      // link under a heavy load would force the light link's velocity error onto the load.
      const Real invLow = la < lb ? m.sb[c.ia].invMass : m.sb[c.ib].invMass;
      const Real invHigh = la < lb ? m.sb[c.ib].invMass : m.sb[c.ia].invMass;
      if (invLow > invHigh) continue;
    }
    order.push_back({std::min(la, lb), k});
  }
  std::stable_sort(order.begin(), order.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  for (const auto& [lvl, k] : order) {
    const auto& c = m.contactRanges[k];
    const int la = c.ia >= 0 ? m.level[c.ia] : 0, lb = c.ib >= 0 ? m.level[c.ib] : 0;
    m.shock.push_back({c.begin, c.count, la < lb ? 0 : 1});
  }
}

void Simulation::integrate() {
  Impl& m = *impl_;
  const Real h = h_;
  for (size_t i = 0; i < bodies_.size(); ++i) {
    RigidBody& b = *bodies_[i];
    switch (b.getMotionControl()) {
      case RigidBody::STATIC: break;
      case RigidBody::KINEMATICS:
        BodyAccess::cm(b) += h * b.getVelocity();
        BodyAccess::rotation(b) = (detail::expRotation(b.getAngularVelocity(), h) * BodyAccess::rotation(b)).normalized();
        break;
      case RigidBody::DYNAMICS:
        BodyAccess::velocity(b) = m.sb[i].v;
        BodyAccess::angularVelocity(b) = m.sb[i].w;
        BodyAccess::cm(b) += h * m.sb[i].v;
        detail::integrateRotation(b, h);
        break;
    }
    b.clearForces();
  }
  if (m.granularStep) {
    const size_t before = report_.messages.size();
    m.granular.integrate(granular_, h, report_.nonFiniteParticles, report_.messages, time_);
    for (size_t k = before; k < report_.messages.size(); ++k) Logger::error(report_.messages[k]);
  }
}

void Simulation::storeContactResults() {
  Impl& m = *impl_;
  const Real invH = 1.0 / h_;
  m.nextCache.clear();
  for (const Impl::PointRows& pr : m.pointRows) {
    GeometryContact& c = contacts_[pr.contact];
    ContactPoint& p = c.points()[pr.point];
    const Real ln = m.rows[pr.normal].lambda;
    Vec3 ft = Vec3::Zero();
    if (pr.t1 >= 0) ft = m.rows[pr.t1].lambda * pr.tangent1 + m.rows[pr.t1 + 1].lambda * pr.tangent2;
    p.normalImpulse = ln;
    p.frictionImpulse = ft;
    p.normalForce = ln * invH;
    p.frictionForce = ft * invH;
    p.impactSpeed = pr.impactSpeed;
    m.nextCache.push_back({pairKeyOf(c), p.featureId, ln, ft, pr.impactSpeed});
  }
  std::sort(m.nextCache.begin(), m.nextCache.end());
  std::swap(m.cache, m.nextCache);
  for (const auto& r : m.ranges) r.c->storeResult(m.rows.data() + r.begin, m.rowDofs.data() + r.begin, r.count, h_);
  if (m.granularStep) {
    m.granular.storeResults(granular_, h_);
    granular_.endDeferral();
  }
}

void Simulation::projectPositions() {
  // Post-stabilisation (Cline & Pai 2003, "Post-stabilization for rigid body simulation with contact and
  // constraints"): SPOOK's rows are linearised at the start of the step, so a joint whose links turn fast
  // drifts by about (omega h)^2 |r| / 2 per step, and the damped position feedback removes that only over the
  // next steps. At a large step with light links whipping under a heavy load (chain20 at dt 1/60) the drift
  // reaches centimetres. Here the rigid holonomic rows of direct-set joints are rebuilt at the integrated
  // positions, and the drift (the position error beyond the elastic stretch of the solved force, see
  // ConstraintRow::drift) that exceeds the tolerance (Solver::setPositionProjectionTolerance) is removed by the
  // smallest displacement in the mass metric: dx = M^-1 G^T mu with G M^-1 G^T mu = -excess (rows within the
  // tolerance: 0), one direct factorisation per Newton iteration, the pattern (and so CHOLMOD's symbolic
  // analysis) kept across steps. Velocities are not changed: the step's momenta and the forces the joints
  // report stay those of the solve. Drift within the tolerance stays with SPOOK's feedback, which keeps the
  // energy (see Solver::setUsePositionProjection). Compliant rows (regularisation >= 1 % of the mass term,
  // springs the step resolves: tire modes, soft joints) and bounded rows are left to SPOOK. Joints within the
  // tolerance (a resting chain, a pendulum) cost one rebuild of their rows and no factorisation.
  Impl& m = *impl_;
  SolverStats& st = solver_.stats();
  st.numProjectionIterations = 0;
  st.projectionDrift = st.projectionResidual = 0;
  if (!solver_.getUsePositionProjection() || m.directSet.empty() || m.ranges.empty()) return;
  bool any = false;
  for (const auto& r : m.ranges) any |= r.c->getSolveType() != FrictionModel::ITERATIVE;
  if (!any) return;
  const Real tolerance = solver_.getPositionProjectionTolerance();
  constexpr Real kRigid = 1e-2;      // e / (J M^-1 J^T) below this: a rigid row
  // The metric: the bodies' masses, and inertias plus the joints' geometric stiffness h^2 sum |f| |r| (see
  // addGeometricStiffness, this step's impulses). With the bare inertia the smallest-norm correction of a taut
  // chain bends its light links (a shortening that is second order in their rotation), so Newton stalls and the
  // rotations it applies feed energy into the whip; the tension term makes those rotations as costly as the
  // force they turn against, and two iterations reach 1e-13 m on chain20 at dt 1/60.
  const size_t nb = bodies_.size();
  m.projBodies.resize(nb);
  const bool tension = computeGeometricStiffness();
  for (size_t i = 0; i < nb; ++i) {
    const RigidBody& b = *bodies_[i];
    SolverBodyState& s = m.projBodies[i];
    s.v.setZero();
    s.w.setZero();
    const bool dyn = b.getMotionControl() == RigidBody::DYNAMICS;
    s.invMass = dyn ? b.getInvMass() : 0;
    s.invInertia = dyn ? b.getInvInertiaWorld() : Mat3::Zero();
    if (dyn && tension && m.geomK[i] > 0)
      s.invInertia = (s.invInertia.inverse() + (h_ * h_ * m.geomK[i]) * Mat3::Identity()).inverse();
  }
  auto massTerm = [&](const ConstraintRow& r) {
    Real k = 0;
    if (r.bodyA >= 0) {
      const SolverBodyState& s = m.projBodies[r.bodyA];
      k += s.invMass * r.jLinA.squaredNorm() + r.jAngA.dot(s.invInertia * r.jAngA);
    }
    if (r.bodyB >= 0) {
      const SolverBodyState& s = m.projBodies[r.bodyB];
      k += s.invMass * r.jLinB.squaredNorm() + r.jAngB.dot(s.invInertia * r.jAngB);
    }
    return k;
  };
  const int maxIterations = solver_.getNumProjectionIterations();
  for (int it = 0;; ++it) {
    m.projRows.clear();
    m.projDofs.clear();
    for (const auto& range : m.ranges) {
      Constraint* c = range.c;
      if (c->getSolveType() == FrictionModel::ITERATIVE || !c->getEnable()) continue;
      ConstraintContext ctx;
      ctx.h = h_;
      ctx.indexA = solverIndex(c->getBodyAt(0));
      ctx.indexB = solverIndex(c->getBodyAt(1));
      const size_t begin = m.projRows.size();
      c->addRows(ctx, m.projRows, m.projDofs);
      size_t keep = begin;
      for (size_t k = begin; k < m.projRows.size(); ++k) {
        ConstraintRow r = m.projRows[k];
        if (!r.holonomic || r.lo > -1e299 || r.hi < 1e299 || !std::isfinite(r.drift)) continue;
        const Real kd = massTerm(r);
        if (!(kd > 0) || !(r.e < kRigid * kd)) continue;
        // Pull back only what exceeds the tolerance; rows within it are held where they are.
        r.rhs = -(r.drift - std::clamp(r.drift, -tolerance, tolerance));
        r.e = 0;
        r.lambda = 0;
        r.normalRow = -1;
        r.pairedRow = -1;
        r.solveType = FrictionModel::DIRECT;
        m.projRows[keep++] = r;
      }
      m.projRows.resize(keep);
    }
    Real worst = 0, excess = 0;
    for (const ConstraintRow& r : m.projRows) {
      worst = std::max(worst, std::abs(r.drift));
      excess = std::max(excess, std::abs(r.rhs));
    }
    if (it == 0) st.projectionDrift = worst;
    else st.projectionResidual = excess;
    if (excess <= 1e-3 * tolerance || it == maxIterations) break;
    PgsSolver::prepare(m.projRows, m.projBodies);
    m.projSet.resize(m.projRows.size());
    for (uint32_t k = 0; k < m.projSet.size(); ++k) m.projSet[k] = k;
    DirectSolver::Settings ds;
    ds.form = solver_.getDirectForm();
    const DirectSolver::Result res = m.projector.solve(m.projRows, m.projSet, m.projBodies, ds);
    ++st.numProjectionIterations;
    if (!res.converged) break;
    // The solve's "velocities" are the displacements (linear, and rotation vector) of the bodies.
    for (size_t i = 0; i < nb; ++i) {
      SolverBodyState& s = m.projBodies[i];
      if (!(s.invMass > 0)) continue;
      RigidBody& b = *bodies_[i];
      BodyAccess::cm(b) += s.v;
      BodyAccess::rotation(b) = (detail::expRotation(s.w, 1.0) * BodyAccess::rotation(b)).normalized();
      s.v.setZero();
      s.w.setZero();
    }
  }
}

void Simulation::reportSeparated(const Constraint& c, Real drift) {
  Impl& m = *impl_;
  report_.separatedConstraints.push_back(&c);
  if (!m.reportedSeparated.insert(&c).second) return;
  static const char* kTypes[] = {"DIRECT", "ITERATIVE", "DIRECT_AND_ITERATIVE", "SPLIT"};
  const int t = int(c.getSolveType());
  std::ostringstream msg;
  msg << c.getTypeName() << " \"" << c.getName() << "\" came apart at t = " << time_ << " s: position error "
      << drift << " (m or rad) beyond its elastic stretch, above Solver::getConstraintErrorThreshold() = "
      << solver_.getConstraintErrorThreshold() << "; solve type " << (t >= 0 && t < 4 ? kTypes[t] : "?")
      << (c.getSolveType() == FrictionModel::ITERATIVE
              ? " (PGS cannot hold heavy loads on light links: use DIRECT or DIRECT_AND_ITERATIVE)"
              : " (try a smaller time step)")
      << ". Reported once per constraint; StepReport::separatedConstraints lists it every step.";
  report_.messages.push_back(msg.str());
  Logger::error(msg.str());
}

void Simulation::checkFinite() {
  Impl& m = *impl_;
  for (size_t i = 0; i < bodies_.size(); ++i) {
    RigidBody& b = *bodies_[i];
    if (b.getMotionControl() == RigidBody::STATIC) continue;
    if (BodyAccess::cm(b).allFinite() && BodyAccess::rotation(b).coeffs().allFinite() &&
        BodyAccess::velocity(b).allFinite() && BodyAccess::angularVelocity(b).allFinite())
      continue;
    std::ostringstream msg;
    msg << "RigidBody \"" << b.getName() << "\" (id " << b.getId() << ") has a non-finite state after the step at t = "
        << time_ << " s; restored its last finite pose and stopped it";
    BodyAccess::cm(b) = m.savedX[i];
    BodyAccess::rotation(b) = m.savedQ[i];
    BodyAccess::velocity(b).setZero();
    BodyAccess::angularVelocity(b).setZero();
    report_.nonFiniteBodies.push_back(b.getId());
    report_.messages.push_back(msg.str());
    Logger::error(msg.str());
  }
}

void Simulation::runPost() {
  for (auto& l : stepListeners_)
    if (l->getMask() & StepEventListener::POST_STEP) l->post(time_);
}

}  // namespace scree
