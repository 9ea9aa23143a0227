// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The two matrix forms of the DIRECT solver (solver/include/scree/solver/direct.h) side by side: the Schur
// complement A = G M^-1 G^T + E (CHOLMOD LL^T) and the quasi-definite KKT [M -G^T; -G -E] (CHOLMOD LDL^T), on
// chains, stacks and particle lumps. One benchmark iteration = one Simulation::stepForward() (the whole step, as
// a user pays it); counters: direct rows, factorisations and pivots per step, the share of the step spent in
// numeric factorisations, and whether AUTO picks this form. docs/speed-accuracy.md records which form wins.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

#include "scenes/scenes.h"

namespace {
using namespace scree;
using namespace scree::scenes;

// An n-link version of chain20 (same links and 100 kg ball, hanging at rest or released from horizontal).
std::unique_ptr<Scene> chain(int links, bool hanging) {
  auto s = std::make_unique<Chain20Scene>();
  initScene(*s, "chain", 0.5, 1.0 / 60.0, 600);
  const Real len = 0.2;
  const Vec3 pivot(0, 0, 5);
  const Vec3 dir = hanging ? Vec3(0, 0, -1) : Vec3(1, 0, 0);
  const Vec3 half = hanging ? Vec3(0.025, 0.025, 0.1) : Vec3(0.1, 0.025, 0.025);
  RigidBodyRef prev;
  for (int i = 0; i < links; ++i) {
    auto link = addBox(*s, half, 1.0, pivot + dir * (len * (i + 0.5)));
    for (auto& g : link->getGeometries()) g->setEnableCollisions(false);
    s->sim->add(std::make_shared<BallJoint>(link, prev, pivot + dir * (len * i)));
    prev = link;
  }
  auto geom = std::make_shared<Geometry>(std::make_shared<Sphere>(0.2));
  geom->setEnableCollisions(false);
  auto ball = std::make_shared<RigidBody>("ball");
  ball->add(geom);
  ball->setMass(100.0);
  ball->setPosition(pivot + dir * (len * links + 0.2));
  s->sim->add(ball);
  s->sim->add(std::make_shared<BallJoint>(ball, prev, pivot + dir * (len * links)));
  return s;
}

std::unique_ptr<Scene> stack(bool pyramid) {
  if (pyramid) {
    auto s = std::make_unique<PyramidScene>(buildPyramid20());
    s->contactMaterial->setSolveType(FrictionModel::DIRECT);
    return s;
  }
  auto s = std::make_unique<TowerScene>(buildTower10());
  s->contactMaterial->setSolveType(FrictionModel::DIRECT);
  return s;
}

// A glued lump (the manual's DIRECT particle mode: infinite friction and adhesion, zero adhesive overlap) of
// k x k x k spheres (r = 0.05) on a cubic lattice, touching, resting on the ground.
std::unique_ptr<Scene> lump(int k) {
  auto s = std::make_unique<Scene>();
  initScene(*s, "lump", 0.5, 1.0 / 60.0, 600);
  addGround(*s);
  auto glue = std::make_shared<Material>("glue");
  auto cm = s->sim->getMaterialManager().getOrCreateContactMaterial(glue, glue);
  cm->setFrictionCoefficient(std::numeric_limits<Real>::infinity());
  cm->setAdhesion(std::numeric_limits<Real>::infinity(), 0.0);
  cm->setSolveType(FrictionModel::DIRECT);
  s->sim->getMaterialManager().getOrCreateContactMaterial(glue, s->material)->setSolveType(FrictionModel::DIRECT);
  const Real r = 0.05;
  for (int x = 0; x < k; ++x)
    for (int y = 0; y < k; ++y)
      for (int z = 0; z < k; ++z) {
        auto g = std::make_shared<Geometry>(std::make_shared<Sphere>(r));
        g->setMaterial(glue);
        auto b = std::make_shared<RigidBody>();
        b->add(g);
        b->setPosition(Vec3(2 * r * x, 2 * r * y, r + 2 * r * z));
        s->sim->add(b);
      }
  return s;
}

void runForm(benchmark::State& state, std::unique_ptr<Scene> (*build)(int, bool), int a, bool b) {
  using Clock = std::chrono::steady_clock;
  const auto form = Solver::DirectForm(state.range(0));
  auto s = build(a, b);
  s->sim->getSolver().setDirectForm(form);
  for (int i = 0; i < 30; ++i) s->step();  // settle, first analysis
  double factor = 0, total = 0;
  size_t rows = 0, facts = 0, pivots = 0, steps = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    s->step();
    total += std::chrono::duration<double>(Clock::now() - t0).count();
    const SolverStats& st = s->sim->getSolver().getStats();
    factor += st.factorisationTime;
    rows += st.numDirectRows;
    facts += st.numFactorisations;
    pivots += st.numPivots;
    ++steps;
  }
  const double n = double(std::max<size_t>(steps, 1));
  state.counters["ms_per_step"] = total * 1e3 / n;
  state.counters["direct_rows"] = double(rows) / n;
  state.counters["factorisations"] = double(facts) / n;
  state.counters["pivots"] = double(pivots) / n;
  state.counters["factor_share"] = total > 0 ? factor / total : 0;
  // Which form AUTO takes on this scene now.
  s->sim->getSolver().setDirectForm(Solver::AUTO);
  s->step();
  state.counters["auto_picks_this"] = s->sim->getSolver().getStats().directForm == int(form) ? 1 : 0;
}

std::unique_ptr<Scene> chainCase(int links, bool hanging) { return chain(links, hanging); }
std::unique_ptr<Scene> stackCase(int, bool pyramid) { return stack(pyramid); }
std::unique_ptr<Scene> lumpCase(int k, bool) { return lump(k); }

void chain20Hanging(benchmark::State& st) { runForm(st, chainCase, 20, true); }
void chain20Released(benchmark::State& st) { runForm(st, chainCase, 20, false); }
void chain100Hanging(benchmark::State& st) { runForm(st, chainCase, 100, true); }
void tower10(benchmark::State& st) { runForm(st, stackCase, 0, false); }
void pyramid20(benchmark::State& st) { runForm(st, stackCase, 0, true); }
void lump4(benchmark::State& st) { runForm(st, lumpCase, 4, false); }
void lump8(benchmark::State& st) { runForm(st, lumpCase, 8, false); }

// What the post-step position projection (Solver::setUsePositionProjection) costs: chain20 with DIRECT joints,
// args {hanging 1 / released 0, projection on 1 / off 0}, 600 steps (10 s) from the start, so the released case
// covers the whip where the projection works. Counters: mean ms per step, projection factorisations per step,
// worst joint separation.
void projection(benchmark::State& state) {
  using Clock = std::chrono::steady_clock;
  auto s = chain(20, state.range(0) != 0);
  s->sim->getSolver().setUsePositionProjection(state.range(1) != 0);
  for (const auto& c : s->sim->getConstraints()) c->setSolveType(FrictionModel::DIRECT);
  double total = 0, worst = 0;
  size_t proj = 0, steps = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    s->step();
    total += std::chrono::duration<double>(Clock::now() - t0).count();
    proj += s->sim->getSolver().getStats().numProjectionIterations;
    ++steps;
    for (const auto& c : s->sim->getConstraints())
      if (auto* j = dynamic_cast<const Joint*>(c.get())) worst = std::max(worst, (j->getFrame(0).p - j->getFrame(1).p).norm());
  }
  const double n = double(std::max<size_t>(steps, 1));
  state.counters["ms_per_step"] = total * 1e3 / n;
  state.counters["projections_per_step"] = double(proj) / n;
  state.counters["worst_separation_m"] = worst;
}
BENCHMARK(projection)
    ->Args({1, 1})
    ->Args({1, 0})
    ->Args({0, 1})
    ->Args({0, 0})
    ->Iterations(600)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Arg: 1 = SCHUR, 2 = KKT.
#define FORMS(fn) BENCHMARK(fn)->Arg(Solver::SCHUR)->Arg(Solver::KKT)->Unit(benchmark::kMillisecond)->UseRealTime()
FORMS(chain20Hanging);
FORMS(chain20Released);
FORMS(chain100Hanging);
FORMS(tower10);
FORMS(pyramid20);
FORMS(lump4);
FORMS(lump8);
}  // namespace

BENCHMARK_MAIN();
