// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Simulation: membership (bodies, geometries, constraints, listeners, settings) and stepForward, the step as a
// sequence of named, timed stages. The stages live in the files step_stages.h lists; the state they share is
// SimulationState (simulation_state.h).
#include "scree/solver/simulation.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
#endif

#include "body_access.h"
#include "scree/core/errors.h"
#include "simulation_state.h"
#include "step_stages.h"

namespace scree {

using detail::BodyAccess;

Simulation::Simulation() : s_(std::make_unique<detail::SimulationState>()) {}
Simulation::~Simulation() {
  // Models may own themselves through their items (a tire model is its own constraint): let them go.
  for (auto& model : s_->models) {
    model->owned_.clear();
    model->sim_ = nullptr;
  }
  for (auto& b : s_->bodies) BodyAccess::simIndex(*b) = -1;
}

// ---- membership --------------------------------------------------------------------------------------------

void Simulation::add(RigidBodyRef body) {
  detail::requireNonNull("Simulation::add", "rigidBody", body.get());
  int& idx = BodyAccess::simIndex(*body);
  if (idx >= 0) {
    if (size_t(idx) < s_->bodies.size() && s_->bodies[idx] == body) return;
    throw std::invalid_argument("Simulation::add: rigidBody \"" + body->getName() +
                                "\" is invalid (already in another simulation)");
  }
  idx = int(s_->bodies.size());
  s_->bodies.push_back(body);
  s_->registered.emplace_back();
  for (const GeometryRef& g : body->getGeometries()) {
    s_->space.add(g);
    s_->registered.back().push_back(g.get());
  }
}

bool Simulation::remove(const RigidBodyRef& body) {
  if (!body) return false;
  int idx = BodyAccess::simIndex(*body);
  if (idx < 0 || size_t(idx) >= s_->bodies.size() || s_->bodies[idx] != body) return false;
  for (Geometry* g : s_->registered[idx]) {
    for (const GeometryRef& ref : s_->space.getGeometries())
      if (ref.get() == g) {
        GeometryRef keep = ref;
        s_->space.remove(keep);
        break;
      }
  }
  const size_t last = s_->bodies.size() - 1;
  if (size_t(idx) != last) {
    s_->bodies[idx] = s_->bodies[last];
    s_->registered[idx] = std::move(s_->registered[last]);
    BodyAccess::simIndex(*s_->bodies[idx]) = idx;
  }
  s_->bodies.pop_back();
  s_->registered.pop_back();
  BodyAccess::simIndex(*body) = -1;
  // Forget event state involving the body's geometries.
  auto& pp = s_->prevPairs;
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
  if (s_->space.contains(geometry.get())) return;
  s_->space.add(geometry);
  s_->staticGeoms.push_back(std::move(geometry));
}

bool Simulation::remove(const GeometryRef& geometry) {
  auto it = std::find(s_->staticGeoms.begin(), s_->staticGeoms.end(), geometry);
  if (it == s_->staticGeoms.end()) return false;
  s_->space.remove(geometry);
  s_->staticGeoms.erase(it);
  auto& pp = s_->prevPairs;
  pp.erase(std::remove_if(pp.begin(), pp.end(),
                          [&](const auto& e) {
                            return e.second.first == geometry.get() || e.second.second == geometry.get();
                          }),
           pp.end());
  return true;
}

void Simulation::add(ConstraintRef c) {
  detail::requireNonNull("Simulation::add", "constraint", c.get());
  if (std::find(s_->constraints.begin(), s_->constraints.end(), c) != s_->constraints.end()) return;
  s_->constraints.push_back(c);
  if (!c->getEnableCollisions() && c->getBodyAt(1))
    s_->space.setEnableCollisions(c->getBodyAt(0), c->getBodyAt(1), false);
  c->addNotification(*this);
}

bool Simulation::remove(const ConstraintRef& c) {
  auto it = std::find(s_->constraints.begin(), s_->constraints.end(), c);
  if (it == s_->constraints.end()) return false;
  c->removeNotification(*this);
  s_->constraints.erase(it);
  s_->reportedSeparated.erase(c.get());
  // Re-enable the pair unless another constraint still joins the same bodies without collisions.
  bool stillJoined = false;
  for (const auto& o : s_->constraints)
    if (!o->getEnableCollisions() &&
        ((o->getBodyAt(0) == c->getBodyAt(0) && o->getBodyAt(1) == c->getBodyAt(1)) ||
         (o->getBodyAt(0) == c->getBodyAt(1) && o->getBodyAt(1) == c->getBodyAt(0))))
      stillJoined = true;
  if (!stillJoined && c->getBodyAt(1)) s_->space.setEnableCollisions(c->getBodyAt(0), c->getBodyAt(1), true);
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

void Simulation::add(StepEventListenerRef l) { addListener(s_->stepListeners, std::move(l), this, "stepEventListener"); }
bool Simulation::remove(const StepEventListenerRef& l) { return removeListener(s_->stepListeners, l); }
void Simulation::add(ContactEventListenerRef l) {
  addListener(s_->contactListeners, std::move(l), this, "contactEventListener");
}
bool Simulation::remove(const ContactEventListenerRef& l) { return removeListener(s_->contactListeners, l); }

void Simulation::setTimeStep(Real h) {
  detail::requirePositive("Simulation::setTimeStep", "timeStep", h);
  s_->h = h;
}
void Simulation::setUniformGravity(const Vec3& g) {
  detail::requireFinite("Simulation::setUniformGravity", "gravity", g);
  s_->gravity = g;
}
void Simulation::setEnableCollisions(const std::string& a, const std::string& b, bool enable) {
  s_->space.setEnablePair(Geometry::groupId(a), Geometry::groupId(b), enable);
}

void Simulation::setEnableCollisions(uint32_t group1, uint32_t group2, bool enable) {
  s_->space.setEnablePair(group1, group2, enable);
}

const std::vector<RigidBodyRef>& Simulation::getRigidBodies() const { return s_->bodies; }
const std::vector<ConstraintRef>& Simulation::getConstraints() const { return s_->constraints; }
const std::vector<GeometryRef>& Simulation::getStaticGeometries() const { return s_->staticGeoms; }
const std::vector<StepEventListenerRef>& Simulation::getStepEventListeners() const { return s_->stepListeners; }
const std::vector<ContactEventListenerRef>& Simulation::getContactEventListeners() const { return s_->contactListeners; }
const std::vector<ModelRef>& Simulation::getModels() const { return s_->models; }
Real Simulation::getTimeStep() const { return s_->h; }
Vec3 Simulation::getUniformGravity() const { return s_->gravity; }
Real Simulation::getTimeStamp() const { return s_->time; }
MaterialManager& Simulation::getMaterialManager() { return s_->materials; }
Solver& Simulation::getSolver() { return s_->solver; }
GranularBodySystem& Simulation::getGranularBodySystem() { return s_->granular; }
const GranularBodySystem& Simulation::getGranularBodySystem() const { return s_->granular; }
const std::vector<GeometryContact>& Simulation::getContacts() const { return s_->contacts; }
const std::vector<ParticleContact>& Simulation::getParticleParticleContacts() const {
  return s_->particleCollider.getParticleParticleContacts();
}
const std::vector<ParticleContact>& Simulation::getParticleGeometryContacts() const {
  return s_->particleCollider.getParticleGeometryContacts();
}
const StepStats& Simulation::getStepStats() const { return s_->stats; }
const StepReport& Simulation::getLastStepReport() const { return s_->report; }

StepTimings Simulation::getTimings() const {
  const StepStats& t = s_->stats;
  const double ms = 1e3;
  StepTimings r;
  r.preCollide = t.preCollide * ms;
  r.syncGeometries = t.syncGeometries * ms;
  r.collideGeometries = t.collideGeometries * ms;
  r.collideParticles = t.collideParticles * ms;
  r.resolveMaterials = t.resolveMaterials * ms;
  r.contactEvents = t.contactEvents * ms;
  r.pre = t.pre * ms;
  r.applyForces = t.applyForces * ms;
  r.contactRows = t.contactRows * ms;
  r.constraintRows = t.constraintRows * ms;
  r.particleRows = t.particleRows * ms;
  r.solve = t.solve * ms;
  r.integrateMotion = t.integrateMotion * ms;
  r.storeResults = t.storeResults * ms;
  r.projectPositions = t.projectPositions * ms;
  r.checkFinite = t.checkFinite * ms;
  r.post = t.post * ms;
  r.compactParticles = t.compactParticles * ms;
  r.total = t.total * ms;
  return r;
}

// ---- the step ----------------------------------------------------------------------------------------------

namespace {
// DESIGN (issue 18, fixed cost of small scenes; docs/benchmarks.md "Small scenes against Bullet"): the stage
// boundaries read a tick counter, the step's two ends the steady clock. On x86-64 the ticks are the time-stamp
// counter (rdtsc: constant and non-stop on current CPUs; the kernel's own clock source reads it too): a
// steady_clock read goes through the vDSO's clock_gettime (counter read, scaling, sequence lock) and cost about
// 26 ns against 10 ns for rdtsc on this virtual machine; the 12 boundary reads of a rigid step were about 6 % of
// a two-box step (mass_ratio). A stage's seconds are the step's steady-clock seconds times the stage's share of the step's
// ticks, so the stages add up to `total` exactly and no tick rate has to be calibrated. Elsewhere the ticks are
// the steady clock's own.
using Clock = std::chrono::steady_clock;
inline uint64_t stageTicks() {
#if defined(__x86_64__) || defined(__i386__)
  return __rdtsc();
#else
  return uint64_t(Clock::now().time_since_epoch().count());
#endif
}
}  // namespace

void Simulation::stepForward() {
  using namespace detail;
  SimulationState& s = *s_;
  StepStats& t = s.stats;
  s.report = StepReport{};
  // One tick read per stage boundary: each stage's time runs from the end of the previous one. A stage that had
  // nothing to do (no step listeners, no particles, no constraints) reads nothing and reports 0: its few
  // nanoseconds of checks go to the next stage. Clock reads were 11 % of a one-box step (slide: 20 reads of
  // about 25 ns in a 4.6 us step; docs/solver-internals.md "Fixed cost of small rigid scenes").
  // The stages' tick counts, in stage order, are kept in `ticks` and turned into seconds at the end of the step.
  double* const slots[] = {&t.preCollide,   &t.syncGeometries,  &t.collideGeometries, &t.collideParticles,
                           &t.resolveMaterials, &t.contactEvents, &t.pre,             &t.applyForces,
                           &t.contactRows,  &t.constraintRows,  &t.particleRows,      &t.solve,
                           &t.integrateMotion, &t.storeResults,  &t.projectPositions,  &t.checkFinite,
                           &t.post,         &t.compactParticles};
  constexpr int kStages = int(sizeof(slots) / sizeof(slots[0]));
  uint64_t ticks[kStages] = {};
  int stage = 0;
  const auto start = Clock::now();
  uint64_t last = stageTicks();
  uint64_t allTicks = 0;
  auto mark = [&]() {
    const uint64_t now = stageTicks();
    // A thread moved to a core whose counter lags would see time run backwards: count that stage as 0 (the
    // shares below stay within [0, total] and still add up to it).
    ticks[stage] = now > last ? now - last : 0;
    allTicks += ticks[stage];
    last = now;
  };
  auto timed = [&](auto&& run) {
    run();
    mark();
    ++stage;
  };
  // Idle tests are evaluated before their stage runs (a listener may add listeners or constraints).
  auto timedUnlessIdle = [&](bool idle, auto&& run) {
    run();
    if (!idle) mark();
    ++stage;
  };
  // The order of these calls is the order of `slots`.
  timedUnlessIdle(s.stepListeners.empty(), [&] { runStepListeners(s, StepEventListener::PRE_COLLIDE); });
  timed([&] { syncGeometries(s); });
  timed([&] { collideGeometries(s); });
  // collideParticles decides whether this is a granular step (s.granularStep); the later particle stages
  // do nothing without one.
  collideParticles(s);
  if (s.granularStep) mark();  // otherwise its checks count to the next stage
  ++stage;
  const bool noParticles = !s.granularStep;
  timed([&] { resolveContactMaterials(s); });
  timed([&] { runContactEvents(s); });
  timedUnlessIdle(s.stepListeners.empty(), [&] { runStepListeners(s, StepEventListener::PRE_STEP); });
  timed([&] { applyForces(s); });
  timed([&] { buildContactRows(s); });
  timedUnlessIdle(s.constraints.empty(), [&] { buildConstraintRows(s); });
  timedUnlessIdle(noParticles, [&] { buildParticleRows(s); });
  timed([&] { solve(s); });
  timed([&] { integrateMotion(s); });
  timed([&] { storeResults(s); });
  endPartitionedWork(s);  // its few nanoseconds count to the next stage
  timedUnlessIdle(s.ranges.empty(), [&] { projectPositions(s); });
  timed([&] { checkFinite(s); });
  s.time += s.h;
  timedUnlessIdle(s.stepListeners.empty(), [&] { runStepListeners(s, StepEventListener::POST_STEP); });
  timedUnlessIdle(noParticles, [&] { endParticleDeferral(s); });
  const auto end = Clock::now();
  t.total = std::chrono::duration<double>(end - start).count();
  const double perTick = allTicks > 0 ? t.total / double(allTicks) : 0.0;
  for (int k = 0; k < kStages; ++k) *slots[k] = double(ticks[k]) * perTick;
  t.collide = t.syncGeometries + t.collideGeometries + t.collideParticles + t.resolveMaterials;
  t.rows = t.applyForces + t.contactRows + t.constraintRows + t.particleRows;
  t.integrate = t.integrateMotion + t.storeResults + t.projectPositions + t.checkFinite;
}

void Simulation::stepTo(Real time) {
  detail::requireFinite("Simulation::stepTo", "time", time);
  while (s_->time < time - 0.5 * s_->h) stepForward();
}

}  // namespace scree
