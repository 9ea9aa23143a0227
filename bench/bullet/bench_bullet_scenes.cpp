// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The rigid reference scenes (docs/scenes.md: pyramid20, tower10, mass_ratio, chain20, slide, incline at mu 0.5
// and 0.6)
// side by side: Bullet 3.24 (Debian's double-precision build, btDiscreteDynamicsWorld with the sequential-impulse
// solver, 10 iterations, no deactivation, no damping) against Scree's default solver, in one binary and one run so
// that each ratio is measured under the same machine load.
//
// Built only when pkg-config finds `bullet-float64` (scripts/install-deps.sh --with-bullet); nothing else in Scree
// depends on Bullet. The Bullet world mirrors the Scree scene built by bench/scenes: every body of the Scree
// Simulation becomes a Bullet body with the same box shape, mass, pose and velocity (static bodies: mass 0), and
// every body carries friction sqrt(mu) so that Bullet's product combination gives the scene's mu. One benchmark
// iteration is one complete run of the scene's defined number of steps; per-step times come from a clock around
// the step call, and the counters give the median and mean ms/step. Bullet's final state is written back into the
// Scree scene's bodies so that one harness (scenes::measure*) computes both engines' metrics where the scene has a
// final-state metric (pyramid20, tower10, incline).
//
// chain20 is built for Bullet directly (docs/scenes.md: 20 links of 1 kg, ball joints as btPoint2PointConstraint,
// the 100 kg ball, collisions off); its metric is the largest joint separation at the end of the run.
#include <benchmark/benchmark.h>

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <vector>

#include "scenes/scenes.h"
#include "bullet_timing.h"

namespace {
using namespace scree;
using namespace scree::scenes;

using scree::bench::timeRun;

btVector3 bt(const Vec3& v) { return btVector3(v.x(), v.y(), v.z()); }
Vec3 sc(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }

// The Bullet mirror of a Scree rigid scene (box geometries at the body origin only).
struct BulletMirror {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btDefaultMotionState>> states;
  std::vector<std::unique_ptr<btRigidBody>> bodies;  // in the Scree Simulation's body order
  bool ok = true;

  explicit BulletMirror(const Scene& s) {
    world.setGravity(btVector3(0, 0, -SceneConstants::gravity));
    world.getSolverInfo().m_numIterations = SceneConstants::solverIterations;
    const Real friction = std::sqrt(s.mu);
    for (const RigidBodyRef& b : s.sim->getRigidBodies()) {
      const auto& geoms = b->getGeometries();
      const Box* box = geoms.size() == 1 ? dynamic_cast<const Box*>(geoms[0]->getShape().get()) : nullptr;
      if (!box) {
        ok = false;
        return;
      }
      shapes.push_back(std::make_unique<btBoxShape>(bt(box->getHalfExtents())));
      btCollisionShape* shape = shapes.back().get();
      const bool dynamic = b->getMotionControl() == RigidBody::DYNAMICS;
      const Real mass = dynamic ? b->getMass() : 0.0;
      btVector3 inertia(0, 0, 0);
      if (dynamic) shape->calculateLocalInertia(mass, inertia);
      btTransform tf;
      tf.setIdentity();
      tf.setOrigin(bt(b->getPosition()));
      const Quat q = b->getRotation();
      tf.setRotation(btQuaternion(q.x(), q.y(), q.z(), q.w()));
      states.push_back(std::make_unique<btDefaultMotionState>(tf));
      btRigidBody::btRigidBodyConstructionInfo info(mass, states.back().get(), shape, inertia);
      info.m_friction = friction;
      info.m_restitution = 0;
      bodies.push_back(std::make_unique<btRigidBody>(info));
      btRigidBody* rb = bodies.back().get();
      rb->setActivationState(DISABLE_DEACTIVATION);
      if (dynamic) {
        rb->setLinearVelocity(bt(b->getVelocity()));
        rb->setAngularVelocity(bt(b->getAngularVelocity()));
      }
      world.addRigidBody(rb);
    }
  }
  ~BulletMirror() {
    for (auto& b : bodies) world.removeRigidBody(b.get());
  }
  // Writes Bullet's final poses and velocities into the Scree scene's bodies (same order).
  void copyInto(Scene& s) const {
    const auto& sb = s.sim->getRigidBodies();
    for (size_t i = 0; i < bodies.size(); ++i) {
      if (sb[i]->getMotionControl() != RigidBody::DYNAMICS) continue;
      const btTransform& t = bodies[i]->getCenterOfMassTransform();
      const btQuaternion q = t.getRotation();
      sb[i]->setPosition(sc(t.getOrigin()));
      sb[i]->setRotation(Quat(q.w(), q.x(), q.y(), q.z()));
      sb[i]->setVelocity(sc(bodies[i]->getLinearVelocity()));
      sb[i]->setAngularVelocity(sc(bodies[i]->getAngularVelocity()));
    }
  }
};

// chain20 in Bullet: the scene's links and ball, ball joints as point-to-point constraints, no collisions.
struct BulletChain {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
  btBoxShape linkShape{btVector3(0.1, 0.025, 0.025)};
  btSphereShape ballShape{0.2};
  std::vector<std::unique_ptr<btDefaultMotionState>> states;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::vector<std::unique_ptr<btPoint2PointConstraint>> joints;

  btRigidBody* add(btCollisionShape* shape, Real mass, const btVector3& inertia, const Vec3& p) {
    btTransform tf;
    tf.setIdentity();
    tf.setOrigin(bt(p));
    states.push_back(std::make_unique<btDefaultMotionState>(tf));
    btRigidBody::btRigidBodyConstructionInfo info(mass, states.back().get(), shape, inertia);
    bodies.push_back(std::make_unique<btRigidBody>(info));
    btRigidBody* rb = bodies.back().get();
    rb->setActivationState(DISABLE_DEACTIVATION);
    world.addRigidBody(rb, 0, 0);  // no collision group, no mask: the links and the ball never collide
    return rb;
  }
  explicit BulletChain(Real ballMass) {
    world.setGravity(btVector3(0, 0, -SceneConstants::gravity));
    world.getSolverInfo().m_numIterations = SceneConstants::solverIterations;
    const Vec3 pivot(0, 0, 5), dir(1, 0, 0);
    const Real len = 0.2;
    btVector3 linkInertia;
    linkShape.calculateLocalInertia(1.0, linkInertia);
    btRigidBody* prev = nullptr;
    for (int i = 0; i < 20; ++i) {
      btRigidBody* link = add(&linkShape, 1.0, linkInertia, pivot + dir * (len * (i + 0.5)));
      if (prev)
        joints.push_back(std::make_unique<btPoint2PointConstraint>(*link, *prev, btVector3(-0.1, 0, 0),
                                                                   btVector3(0.1, 0, 0)));
      else
        joints.push_back(std::make_unique<btPoint2PointConstraint>(*link, btVector3(-0.1, 0, 0)));
      world.addConstraint(joints.back().get(), true);
      prev = link;
    }
    const Real I = 0.4 * ballMass * 0.2 * 0.2;
    btRigidBody* ball = add(&ballShape, ballMass, btVector3(I, I, I), pivot + dir * (len * 20 + 0.2));
    joints.push_back(
        std::make_unique<btPoint2PointConstraint>(*ball, *prev, btVector3(-0.2, 0, 0), btVector3(0.1, 0, 0)));
    world.addConstraint(joints.back().get(), true);
  }
  ~BulletChain() {
    for (auto& j : joints) world.removeConstraint(j.get());
    for (auto& b : bodies) world.removeRigidBody(b.get());
  }
  /// Largest distance between a joint's two anchor points, m.
  Real maxSeparation() const {
    Real worst = 0;
    for (const auto& j : joints) {
      const btVector3 a = j->getRigidBodyA().getCenterOfMassTransform() * j->getPivotInA();
      const btVector3 b = j->getRigidBodyB().getCenterOfMassTransform() * j->getPivotInB();
      worst = std::max<Real>(worst, (a - b).length());
    }
    return worst;
  }
};

void BM_Bullet_chain20(benchmark::State& state) {
  for (auto _ : state) {
    state.PauseTiming();
    auto chain = std::make_unique<BulletChain>(100.0);
    const Real dt = 1.0 / 60.0;
    state.ResumeTiming();
    const auto t = timeRun(600, [&] { chain->world.stepSimulation(dt, 1, dt); });
    state.PauseTiming();
    state.counters["median_ms_per_step"] = t.first;
    state.counters["mean_ms_per_step"] = t.second;
    state.counters["sep_final_m"] = chain->maxSeparation();
    state.ResumeTiming();
  }
}
BENCHMARK(BM_Bullet_chain20)->Iterations(1)->Repetitions(3)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Scree_chain20(benchmark::State& state) {
  for (auto _ : state) {
    state.PauseTiming();
    Chain20Scene s = buildChain20();
    ChainObserver obs(s);
    state.ResumeTiming();
    const auto t = timeRun(s.numSteps, [&] { s.step(); });
    state.PauseTiming();
    obs.observe();
    state.counters["median_ms_per_step"] = t.first;
    state.counters["mean_ms_per_step"] = t.second;
    state.counters["sep_final_m"] = obs.result().finalSeparation;
    state.ResumeTiming();
  }
}
BENCHMARK(BM_Scree_chain20)->Iterations(1)->Repetitions(3)->Unit(benchmark::kMillisecond)->UseRealTime();

template <class S>
void runScene(benchmark::State& state, const std::function<S()>& build,
              const std::function<void(benchmark::State&, const S&)>& metrics, bool bullet) {
  for (auto _ : state) {
    state.PauseTiming();
    S s = build();
    std::unique_ptr<BulletMirror> mirror;
    if (bullet) {
      mirror = std::make_unique<BulletMirror>(s);
      if (!mirror->ok) {
        state.SkipWithError("scene has a non-box body");
        return;
      }
    }
    const Real dt = s.dt;
    state.ResumeTiming();
    const auto t = bullet ? timeRun(s.numSteps, [&] { mirror->world.stepSimulation(dt, 1, dt); })
                          : timeRun(s.numSteps, [&] { s.step(); });
    state.PauseTiming();
    if (bullet) mirror->copyInto(s);
    state.counters["median_ms_per_step"] = t.first;
    state.counters["mean_ms_per_step"] = t.second;
    metrics(state, s);
    state.ResumeTiming();
  }
}

void pyramidMetrics(benchmark::State& st, const PyramidScene& s) {
  const PyramidMetrics m = measurePyramid(s);
  st.counters["drift_cm"] = m.maxDisplacement * 100;
  st.counters["stands"] = m.stands ? 1 : 0;
}
void towerMetrics(benchmark::State& st, const TowerScene& s) {
  const TowerMetrics m = measureTower(s);
  st.counters["drift_cm"] = m.maxDisplacement * 100;
}
void inclineMetrics(benchmark::State& st, const InclineScene& s) {
  st.counters["disp_m"] = measureIncline(s).displacement;
}
template <class S>
void noMetrics(benchmark::State&, const S&) {}

#define SCENE_PAIR(name, Type, builder, metric)                                                               \
  void BM_Bullet_##name(benchmark::State& st) { runScene<Type>(st, builder, metric, true); }                  \
  void BM_Scree_##name(benchmark::State& st) { runScene<Type>(st, builder, metric, false); }                  \
  BENCHMARK(BM_Bullet_##name)->Iterations(1)->Repetitions(3)->Unit(benchmark::kMillisecond)->UseRealTime();    \
  BENCHMARK(BM_Scree_##name)->Iterations(1)->Repetitions(3)->Unit(benchmark::kMillisecond)->UseRealTime();

SCENE_PAIR(pyramid20, PyramidScene, [] { return buildPyramid20(); }, pyramidMetrics)
SCENE_PAIR(tower10, TowerScene, [] { return buildTower10(); }, towerMetrics)
SCENE_PAIR(mass_ratio, MassRatioScene, [] { return buildMassRatio(); }, noMetrics<MassRatioScene>)
SCENE_PAIR(slide, SlideScene, [] { return buildSlide(); }, noMetrics<SlideScene>)
SCENE_PAIR(incline_mu05, InclineScene, [] { return buildIncline(0.5); }, inclineMetrics)
SCENE_PAIR(incline_mu06, InclineScene, [] { return buildIncline(0.6); }, inclineMetrics)

}  // namespace

BENCHMARK_MAIN();
