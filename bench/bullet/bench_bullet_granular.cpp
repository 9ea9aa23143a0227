// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// spheres10k_jitter side by side: Bullet 3.24 (Debian's double-precision build, btDiscreteDynamicsWorld with the
// sequential-impulse solver, 10 iterations, default settings otherwise) against Scree's GranularBodySystem on 1
// and 2 threads, in one binary so that both are measured under the same machine load.
//
// Built only when pkg-config finds `bullet-float64` (Debian: apt-get install libbullet-dev); nothing else in
// Scree depends on Bullet. Both engines start from the same 10,000 positions (taken from Scree's scene builder,
// docs/scenes.md lattice with splitmix64 jitter), same radius, mass, inertia 0.4 m r^2, mu 0.5, restitution 0,
// ground box top at z = 0 and four 0.2 m walls with inner faces at +-1 m, dt 1/100, 300 steps. Each benchmark
// iteration is one complete run; per-step times come from a clock around the step call, and the counters give
// the median and mean ms/step. Bullet's final state is written into the Scree scene's particle arrays so that
// one harness (scenes::measureParticles) computes the penetration, kinetic energy and escape metrics of both.
#include <benchmark/benchmark.h>

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <vector>

#include "scenes/particle_scenes.h"
#include "bullet_timing.h"

namespace {
using namespace scree;
using namespace scree::scenes;

using scree::bench::timeRun;

void report(benchmark::State& state, const ParticleScene& s, std::pair<double, double> t) {
  const ParticleMetrics m = measureParticles(s);
  state.counters["median_ms_per_step"] = t.first;
  state.counters["mean_ms_per_step"] = t.second;
  state.counters["max_pen_mm"] = m.maxPenetration * 1e3;
  state.counters["max_pen_pct_r"] = 100 * m.maxPenetration / s.params.radius;
  state.counters["kinetic_J"] = m.kineticEnergy;
  state.counters["escaped"] = double(m.escaped);
}

btVector3 bt(const Vec3& v) { return btVector3(v.x(), v.y(), v.z()); }

// The Bullet world of the scene, built from the Scree scene's initial particle state.
struct BulletWorld {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btDefaultMotionState>> states;
  std::vector<std::unique_ptr<btRigidBody>> bodies;  // spheres first, in particle id order
  size_t numSpheres = 0;

  btRigidBody* addBody(btCollisionShape* shape, Real mass, const btVector3& inertia, const Vec3& p, Real mu) {
    btTransform tf;
    tf.setIdentity();
    tf.setOrigin(bt(p));
    states.push_back(std::make_unique<btDefaultMotionState>(tf));
    btRigidBody::btRigidBodyConstructionInfo info(mass, states.back().get(), shape, inertia);
    info.m_friction = mu;
    info.m_restitution = 0;
    bodies.push_back(std::make_unique<btRigidBody>(info));
    world.addRigidBody(bodies.back().get());
    return bodies.back().get();
  }

  explicit BulletWorld(const ParticleScene& s) {
    const SphereLatticeParams& p = s.params;
    world.setGravity(btVector3(0, 0, -SceneConstants::gravity));
    world.getSolverInfo().m_numIterations = SceneConstants::solverIterations;
    const GranularBodySystem& ps = s.particles();
    shapes.push_back(std::make_unique<btSphereShape>(p.radius));
    btCollisionShape* sphere = shapes.back().get();
    for (size_t id : ps.getParticleIds()) {
      const Real m = ps.getMass(id), I = 0.4 * m * p.radius * p.radius;
      btRigidBody* b = addBody(sphere, m, btVector3(I, I, I), ps.getPosition(id), p.mu);
      b->setLinearVelocity(bt(ps.getVelocity(id)));
      ++numSpheres;
    }
    const Real g = SceneConstants::groundHalfExtent;
    shapes.push_back(std::make_unique<btBoxShape>(btVector3(g, g, 0.5)));
    addBody(shapes.back().get(), 0, btVector3(0, 0, 0), Vec3(0, 0, -0.5), p.mu);
    const Real half = s.wallInner + p.wallThickness, t = p.wallThickness / 2, hz = p.wallHeight / 2;
    shapes.push_back(std::make_unique<btBoxShape>(btVector3(t, half, hz)));
    for (Real sx : {1.0, -1.0}) addBody(shapes.back().get(), 0, btVector3(0, 0, 0), Vec3(sx * (s.wallInner + t), 0, hz), p.mu);
    shapes.push_back(std::make_unique<btBoxShape>(btVector3(half, t, hz)));
    for (Real sy : {1.0, -1.0}) addBody(shapes.back().get(), 0, btVector3(0, 0, 0), Vec3(0, sy * (s.wallInner + t), hz), p.mu);
  }
  ~BulletWorld() {
    for (auto& b : bodies) world.removeRigidBody(b.get());
  }

  // Writes the spheres' final state into the Scree scene's particles (same id order as at construction).
  void copyInto(ParticleScene& s) const {
    GranularBodySystem& ps = s.particles();
    const std::vector<size_t> ids = ps.getParticleIds();
    for (size_t i = 0; i < numSpheres; ++i) {
      const btRigidBody& b = *bodies[i];
      const btVector3 x = b.getCenterOfMassPosition(), v = b.getLinearVelocity(), w = b.getAngularVelocity();
      ps.setPosition(ids[i], Vec3(x.x(), x.y(), x.z()));
      ps.setVelocity(ids[i], Vec3(v.x(), v.y(), v.z()));
      ps.setAngularVelocity(ids[i], Vec3(w.x(), w.y(), w.z()));
    }
  }
};

void BM_Bullet_Spheres10kJitter(benchmark::State& state) {
  for (auto _ : state) {
    state.PauseTiming();
    ParticleScene s = buildParticles10kJitter();
    auto world = std::make_unique<BulletWorld>(s);
    const Real dt = s.params.dt;
    state.ResumeTiming();
    const auto t = timeRun(s.numSteps, [&] { world->world.stepSimulation(dt, 1, dt); });
    state.PauseTiming();
    world->copyInto(s);
    report(state, s, t);
    state.ResumeTiming();
  }
}
BENCHMARK(BM_Bullet_Spheres10kJitter)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Scree_Spheres10kJitter(benchmark::State& state) {
  setNumThreads(int(state.range(0)));
  for (auto _ : state) {
    state.PauseTiming();
    ParticleScene s = buildParticles10kJitter();
    state.ResumeTiming();
    const auto t = timeRun(s.numSteps, [&] { s.step(); });
    state.PauseTiming();
    report(state, s, t);
    state.ResumeTiming();
  }
  state.counters["threads"] = double(state.range(0));
  setNumThreads(0);
}
BENCHMARK(BM_Scree_Spheres10kJitter)->Arg(1)->Arg(2)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
