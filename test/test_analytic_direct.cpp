// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// DIRECT solver (solver/include/scree/solver/direct.h, Simulation's hybrid solve) against closed-form values and
// against converged PGS. In a build without SuiteSparse the cases that need the direct solver are skipped
// (test_build.h) and the PGS half of the chain-report case still runs.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "test_world.h"

using namespace scree;

namespace {
constexpr Real kG = 9.81;

scenes::ChainMetrics runChain(bool hanging, FrictionModel::SolveType t, Real dt, int steps, int iterations,
                              Real compliance = -1, bool projection = true, Real* worstDrift = nullptr) {
  scenes::Chain20Scene s = scenes::buildChain20(100.0, hanging);
  s.sim->setTimeStep(dt);
  s.sim->getSolver().setNumIterations(iterations);
  s.sim->getSolver().setUsePositionProjection(projection);
  for (auto& j : s.joints) {
    j->setSolveType(t);
    if (compliance > 0) j->setCompliance(compliance);
  }
  scenes::ChainObserver obs(s);
  for (int i = 0; i < steps; ++i) {
    s.sim->stepForward();
    obs.observe();
    if (worstDrift) *worstDrift = std::max(*worstDrift, s.sim->getSolver().getStats().projectionDrift);
  }
  return obs.result();
}

void setSolveType(scenes::Scene& s, FrictionModel::SolveType t) { s.contactMaterial->setSolveType(t); }

// Largest depth per contact pair (geometry ids) of the last step, for the two contacts of the mass-ratio stack.
Real maxDepthBetween(const Simulation& sim, const RigidBody* a, const RigidBody* b) {
  Real d = 0;
  for (const GeometryContact& c : sim.getContacts()) {
    const RigidBody* x = c.rigidBody(0);
    const RigidBody* y = c.rigidBody(1);
    if (!((x == a && y == b) || (x == b && y == a))) continue;
    for (const ContactPoint& p : c.points()) d = std::max(d, p.depth);
  }
  return d;
}
}  // namespace

TEST_CASE("chain20 (100:1) hanging at rest: DIRECT joint error is the joint's elastic stretch" *
          test::needsDirectSolver()) {
  // The top joint carries the whole chain: (20 x 1 kg + 100 kg) g = 1177.2 N; with the default compliance
  // 1e-8 m/N SPOOK settles it at the stretch F eps = 1.1772e-5 m (docs/design.md §3: lambda/h = -g/eps at rest). The
  // direct solve is exact up to round-off, so the worst error over the 600 steps equals that stretch; 1 %
  // covers the other joints' smaller stretch never exceeding the top one and the transient of the first steps.
  const Real topForce = (20 * 1.0 + 100.0) * kG;
  const auto direct = runChain(true, FrictionModel::DIRECT, 1.0 / 60, 600, 10);
  CHECK(direct.finite);
  CHECK(direct.maxSeparation == doctest::Approx(topForce * 1e-8).epsilon(0.01).scale(0));
  // The bound 1e-5 m is below that physical stretch; with a stiffer joint (1e-9 m/N) the error is
  // 1.18e-6 m, below it.
  const auto stiff = runChain(true, FrictionModel::DIRECT, 1.0 / 60, 600, 10, 1e-9);
  CHECK(stiff.maxSeparation == doctest::Approx(topForce * 1e-9).epsilon(0.01).scale(0));
  CHECK(stiff.maxSeparation < 1e-5);
  // PGS at the default iteration count (Solver: 16) and at the scene's 10.
  const auto pgs16 = runChain(true, FrictionModel::ITERATIVE, 1.0 / 60, 600, 16);
  const auto pgs10 = runChain(true, FrictionModel::ITERATIVE, 1.0 / 60, 600, 10);
  std::printf("chain20 hanging: DIRECT %.4e m (stretch %.4e), PGS 16 it %.3e m, PGS 10 it %.3e m\n",
              direct.maxSeparation, topForce * 1e-8, pgs16.maxSeparation, pgs10.maxSeparation);
  CHECK(pgs16.maxSeparation > 100 * direct.maxSeparation);
  CHECK(pgs10.maxSeparation > 100 * direct.maxSeparation);
}

TEST_CASE("chain20 (100:1) released from horizontal: DIRECT stays connected where PGS comes apart" *
          test::needsDirectSolver()) {
  // The bound is the 5 mm. Where it comes from with DIRECT: SPOOK's rows are linearised at the start of
  // the step, so the links drift by ~(omega h)^2 |r| / 2 per step; at dt 1/60 the light links whip under the
  // 100 kg ball faster than the step resolves and the drift reaches centimetres. The post-step projection
  // (Solver::setUsePositionProjection, default on) pulls every rigid joint's drift back to its tolerance
  // (2 mm) with two Newton steps, so the separation is at most the tolerance plus the joints' elastic stretch
  // F eps (peak tension ~1e5 N in the whip: 1e-3 m), below 5 mm. Measured 2.9 mm at 1/60, 3.5 mm at 1/600.
  Real driftOn = 0;
  const auto direct = runChain(false, FrictionModel::DIRECT, 1.0 / 60, 600, 10, -1, true, &driftOn);
  const auto fine = runChain(false, FrictionModel::DIRECT, 1.0 / 600, 6000, 10);
  // Without the projection the same solve drifts by centimetres (6.5 cm): the projection is what holds it.
  const auto unprojected = runChain(false, FrictionModel::DIRECT, 1.0 / 60, 600, 10, -1, false);
  // PGS (10 iterations) separates by metres (every engine in docs/scenes.md explodes); its rows are ITERATIVE,
  // so the projection does not touch them.
  const auto pgs = runChain(false, FrictionModel::ITERATIVE, 1.0 / 60, 600, 10);
  std::printf("chain20 released: DIRECT dt 1/60 %.3e m (drift before projection up to %.3e m, unprojected "
              "%.3e m), dt 1/600 %.3e m; PGS dt 1/60 %.3e m\n",
              direct.maxSeparation, driftOn, unprojected.maxSeparation, fine.maxSeparation, pgs.maxSeparation);
  CHECK(direct.finite);
  CHECK(fine.finite);
  CHECK(direct.maxSeparation < 5e-3);
  CHECK(fine.maxSeparation < 5e-3);
  CHECK(driftOn > 2e-3);  // the projection had work to do
  CHECK(unprojected.maxSeparation > 5 * direct.maxSeparation);
  CHECK(pgs.maxSeparation > 5 * direct.maxSeparation);
}

TEST_CASE("the position projection leaves motion within its tolerance to SPOOK" * test::needsDirectSolver()) {
  // A 60 degree pendulum of a 1 kg bob on a 1 m DIRECT DistanceJoint at h = 0.01 s: SPOOK's lag a_c h tau / 2
  // (a_c <= 9.8 m/s^2, tau = 2/60 s) is ~1.6 mm, inside the 2 mm tolerance, so the projection never moves it and
  // the run is bit-identical to one without the projection. With a 0.1 mm tolerance it projects every step and
  // damps the swing (documented on Solver::setUsePositionProjection): the energy then falls measurably.
  auto run = [](bool projection, Real tol, Real* energyLoss, size_t* projected) {
    test::TestWorld w(0.01, 9.81);
    w.sim->getSolver().setUsePositionProjection(projection);
    w.sim->getSolver().setPositionProjectionTolerance(tol);
    const Vec3 p0(std::sin(M_PI / 3), 0, -std::cos(M_PI / 3));
    auto bob = w.addSphere(0.01, p0, 1.0);
    auto rod = std::make_shared<DistanceJoint>(bob, nullptr, p0, Vec3::Zero());
    rod->setSolveType(FrictionModel::DIRECT);
    w.sim->add(rod);
    auto energy = [&] { return 0.5 * bob->getVelocity().squaredNorm() + kG * bob->getPosition().z(); };
    const Real e0 = energy();
    *projected = 0;
    for (int i = 0; i < 500; ++i) {
      w.sim->stepForward();
      *projected += w.sim->getSolver().getStats().numProjectionIterations;
    }
    *energyLoss = e0 - energy();
    return bob->getPosition();
  };
  Real lossOff = 0, lossOn = 0, lossTight = 0;
  size_t nOff = 0, nOn = 0, nTight = 0;
  const Vec3 off = run(false, 2e-3, &lossOff, &nOff);
  const Vec3 on = run(true, 2e-3, &lossOn, &nOn);
  run(true, 1e-4, &lossTight, &nTight);
  std::printf("pendulum 60 deg: energy loss over 5 s: projection off %.4f J, on (2 mm) %.4f J, on (0.1 mm) %.4f J "
              "(%zu projections)\n", lossOff, lossOn, lossTight, nTight);
  CHECK(nOn == 0);
  CHECK((on - off).norm() == 0.0);
  CHECK(nTight > 100);
  CHECK(lossTight > lossOff + 0.1);  // 5 s at (omega h)^2 ~ 1e-3 per step of ~5 J: ~0.5 J
}

TEST_CASE("the position projection corrects rigid rows to its tolerance and leaves compliant ones to SPOOK" *
          test::needsDirectSolver()) {
  // A 1 kg box on a DIRECT Hinge to the world (axis z through its centre), no gravity, set 0.05 m along the axis
  // from its anchor and tilted 0.05 rad about x. Rigid rows (the default compliance): one step's SPOOK correction
  // (about 4/9 of the error at the default damping) leaves some 0.03 m and 0.03 rad, so the projection pulls back
  // what exceeds the tolerance and ends with the error AT the tolerance: the axial offset (row TRANSLATIONAL_3)
  // and the tilt's sine (the bending row n_A . y; the hinge frame in the world is the identity for axis z) equal
  // 2 mm, up to the Newton stop (1e-3 of the tolerance) and the rows' elastic stretch (compliance 1e-10 times
  // about 1 N s over h: 1e-8). The axial row is linear in the displacement, so one Newton step lands on the
  // tolerance; the tilt's sine is not: turned back by d ~ 0.026 rad from ~0.028, it falls below the linearised
  // target by about d^2 sin(theta) / 2 < 0.03^3 / 2 = 1.35e-5, inside the tolerance, where Newton stops. The
  // linear rows are classified by their mass terms alone, the bending rows
  // (no linear part) by the full metric with the inertia: both paths are crossed. Compliant rows (compliance 1,
  // far above 1 % of the mass term) are not projected at all: the step is bit for bit the one without it.
  constexpr Real kTol = 2e-3, kOffset = 0.05, kTilt = 0.05;
  struct Result {
    Vec3 position;
    Quat rotation;
    size_t projections;
    Real drift;
  };
  auto run = [&](bool projection, Real compliance) {
    test::TestWorld w(1.0 / 60.0, 0.0);
    w.sim->getSolver().setUsePositionProjection(projection);
    w.sim->getSolver().setPositionProjectionTolerance(kTol);
    auto box = w.addBox(Vec3(0.1, 0.2, 0.3), Vec3::Zero(), 1.0);
    auto hinge = std::make_shared<Hinge>(box, nullptr, Vec3::Zero(), Vec3::UnitZ());
    hinge->setSolveType(FrictionModel::DIRECT);
    if (compliance > 0) hinge->setCompliance(compliance);
    w.sim->add(hinge);
    box->setPosition(Vec3(0, 0, kOffset));
    box->setRotation(Quat(Eigen::AngleAxis<Real>(kTilt, Vec3::UnitX())));
    w.sim->stepForward();
    const SolverStats& st = w.sim->getSolver().getStats();
    return Result{box->getPosition(), box->getRotation(), st.numProjectionIterations, st.projectionDrift};
  };
  const Result rigid = run(true, -1);
  const Real axial = rigid.position.z();
  const Real tiltSine = -(rigid.rotation * Vec3::UnitZ()).y();
  std::printf("projection of a hinge: %zu Newton iterations, drift before %.4f, after: axial %.7f m, tilt sine %.7f\n",
              rigid.projections, rigid.drift, axial, tiltSine);
  CHECK(rigid.projections >= 1);
  CHECK(rigid.drift > 10 * kTol);
  CHECK(std::abs(axial - kTol) <= 1e-3 * kTol + 1e-7);
  CHECK(tiltSine <= kTol * (1 + 1e-3) + 1e-7);
  CHECK(tiltSine >= kTol - 1.35e-5);
  CHECK(std::abs(rigid.position.x()) <= 1e-9);
  CHECK(std::abs(rigid.position.y()) <= 1e-9);

  const Result soft = run(true, 1.0), softOff = run(false, 1.0);
  CHECK(soft.projections == 0);
  CHECK(soft.drift == 0.0);  // no row kept, so none reported
  CHECK((soft.position - softOff.position).norm() == 0.0);
  CHECK(soft.rotation.coeffs() == softOff.rotation.coeffs());
  CHECK(soft.position.z() > 10 * kTol);  // the compliant joint's error was there to be projected
}

TEST_CASE("a PGS chain that comes apart is reported, not silent") {
  // chain20 hanging with PGS at 10 iterations diverges to ~1e11 m while staying finite. The step report names
  // the joints whose error beyond the elastic stretch exceeds the threshold (0.1 m), and each is logged once as
  // an error naming the joint and its solve type. DIRECT keeps every joint at its 1.2e-5 m stretch: no report.
  std::vector<std::string> errors;
  Logger::setSink([&](LogLevel l, const std::string& msg) {
    if (l == LogLevel::ERROR) errors.push_back(msg);
  });
  // Without the direct solver (SCREE_WITH_SUITESPARSE off) only the PGS half runs.
  for (auto t : test::availableSolveTypes({FrictionModel::ITERATIVE, FrictionModel::DIRECT})) {
    errors.clear();
    scenes::Chain20Scene s = scenes::buildChain20(100.0, true);
    s.sim->getSolver().setNumIterations(10);
    for (auto& j : s.joints) j->setSolveType(t);
    s.joints.front()->setName("pivot");
    size_t firstReported = 0, maxListed = 0;
    for (int i = 0; i < 600; ++i) {
      s.sim->stepForward();
      const auto& rep = s.sim->getLastStepReport();
      if (!rep.separatedConstraints.empty() && firstReported == 0) firstReported = size_t(i);
      maxListed = std::max(maxListed, rep.separatedConstraints.size());
    }
    std::printf("%s hanging chain: first report at step %zu, up to %zu joints listed, %zu errors logged\n",
                t == FrictionModel::DIRECT ? "DIRECT" : "PGS", firstReported, maxListed, errors.size());
    if (t == FrictionModel::ITERATIVE) {
      CHECK(maxListed > 0);
      CHECK(!s.sim->getLastStepReport().ok());
      CHECK(errors.size() <= s.joints.size());  // once per constraint, not once per step
      REQUIRE(!errors.empty());
      CHECK(errors.front().find("BallJoint") != std::string::npos);
      CHECK(errors.front().find("ITERATIVE") != std::string::npos);
    } else {
      CHECK(maxListed == 0);
      CHECK(errors.empty());
      CHECK(s.sim->getLastStepReport().ok());
    }
  }
  Logger::setSink(nullptr);
}

TEST_CASE("1000 kg box on a 1 kg box: DIRECT penetrations are the compliance-predicted ones" *
          test::needsDirectSolver()) {
  // Each interface carries the weight above it over 4 corner points with stiffness E per point (the scene's
  // contact material: two default 4e8 N/m materials in series, 2e8 N/m): at rest SPOOK settles at depth
  // F / (4 E). Upper: 1000 g / 8e8 = 1.2263e-5 m, lower: 1001 g / 8e8 = 1.2275e-5 m. After 2 s (27 damping
  // times of 0.075 s) the transient is gone; 1 % (measured to 5 digits).
  scenes::MassRatioScene s = scenes::buildMassRatio();
  setSolveType(s, FrictionModel::DIRECT);
  for (int i = 0; i < 120; ++i) s.step();
  const Real E = s.contactMaterial->getYoungsModulus();
  const Real upper = maxDepthBetween(*s.sim, s.heavy.get(), s.light.get());
  const Real lower = maxDepthBetween(*s.sim, s.light.get(), s.ground.get());
  std::printf("mass_ratio DIRECT: upper depth %.5e (predicted %.5e), lower %.5e (%.5e), pivots %zu\n", upper,
              1000 * kG / (4 * E), lower, 1001 * kG / (4 * E), s.sim->getSolver().getStats().numPivots);
  CHECK(upper == doctest::Approx(1000 * kG / (4 * E)).epsilon(0.01).scale(0));
  CHECK(lower == doctest::Approx(1001 * kG / (4 * E)).epsilon(0.01).scale(0));
  CHECK(!scenes::massRatioSqueezed(s));
  CHECK(s.sim->getSolver().getStats().complementarityResidual < 1e-9);
  CHECK(s.sim->getSolver().getStats().numDirectRows > 0);
}

TEST_CASE("a few boxes: DIRECT and PGS with 2000 iterations agree on contact forces" * test::needsDirectSolver()) {
  // A 2-box stack (the top one off centre) and a box beside it. Both worlds run the same 59 steps with PGS (2000
  // sweeps, no shock propagation, which changes the solution), so they are bit-identical; the last step is
  // solved by PGS in one and by DIRECT in the other, from the same state and warm start. Compared: each contact's
  // resultant normal and friction force (1 % of the contact's normal force). Not compared: how a 4-point
  // manifold shares that force among its points. That split lies in the near-null space of G M^-1 G^T (a rigid
  // box cannot tell its corners apart), held only by E ~ 1e-6 of the diagonal, so PGS moves along it by ~1e-6
  // per sweep and keeps the warm start's split (measured: points differ by 17 % while resultants agree).
  auto build = [](bool directLast) {
    auto w = std::make_unique<test::TestWorld>();
    w->addGround();
    w->addBox(Vec3(0.5, 0.5, 0.5), Vec3(0, 0, 0.5), 1.0);
    w->addBox(Vec3(0.4, 0.4, 0.4), Vec3(0.1, 0, 1.4), 2.0);
    w->addBox(Vec3(0.3, 0.3, 0.3), Vec3(2, 0, 0.3), 0.5);
    w->contactMaterial->setSolveType(FrictionModel::ITERATIVE);
    w->sim->getSolver().setNumIterations(2000);
    w->sim->getSolver().setUseShockPropagation(false);
    for (int i = 0; i < 59; ++i) w->sim->stepForward();
    if (directLast) w->contactMaterial->setSolveType(FrictionModel::DIRECT);
    w->sim->stepForward();
    return w;
  };
  auto direct = build(true);
  auto pgs = build(false);
  CHECK(direct->sim->getSolver().getStats().numDirectRows == 36);
  const auto& cd = direct->sim->getContacts();
  const auto& cp = pgs->sim->getContacts();
  REQUIRE(cd.size() == cp.size());
  CHECK(cd.size() == 3);
  Real worstN = 0, worstF = 0;
  for (size_t i = 0; i < cd.size(); ++i) {
    REQUIRE(cd[i].points().size() == cp[i].points().size());
    Real nd = 0, np = 0;
    Vec3 fd = Vec3::Zero(), fp = Vec3::Zero();
    for (size_t k = 0; k < cd[i].points().size(); ++k) {
      nd += cd[i].points()[k].normalForce;
      np += cp[i].points()[k].normalForce;
      fd += cd[i].points()[k].frictionForce;
      fp += cp[i].points()[k].frictionForce;
    }
    worstN = std::max(worstN, std::abs(nd - np) / np);
    worstF = std::max(worstF, (fd - fp).norm() / np);
  }
  std::printf("DIRECT vs PGS 2000 (same state): worst relative difference of contact resultants: normal %.3e, "
              "friction %.3e of the normal\n",
              worstN, worstF);
  CHECK(worstN < 0.01);
  CHECK(worstF < 0.01);
}

TEST_CASE("a lump of spheres with infinite friction and adhesion falls and lands as one body" *
          test::needsDirectSolver()) {
  // The manual's DIRECT particle mode: friction and adhesion infinite, adhesive overlap zero. Among the lump's
  // spheres every row is an equality (no bound), so while it falls each step is one factorisation and no pivot.
  // Landing (restitution 0: the impact stage stops it within a step) loads the inter-sphere springs with at
  // most m v / h ~ 1e2 N, i.e. 1e2 / 4e8 = 2.5e-7 m; bound on the relative displacement 1e-6 m.
  test::TestWorld w;
  w.addGround();
  auto glue = w.addGlueMaterial(FrictionModel::DIRECT);
  // A tetrahedron of touching spheres (r = 0.05), base 2 cm above the ground.
  const Real r = 0.05, d = 2 * r;
  const Vec3 base(0, 0, r + 0.02);
  const Vec3 pos[4] = {base, base + Vec3(d, 0, 0), base + Vec3(d / 2, d * std::sqrt(3.0) / 2, 0),
                       base + Vec3(d / 2, d * std::sqrt(3.0) / 6, d * std::sqrt(2.0 / 3.0))};
  std::vector<RigidBodyRef> s;
  for (const Vec3& p : pos) {
    auto g = std::make_shared<Geometry>(std::make_shared<Sphere>(r));
    g->setMaterial(glue);
    auto b = std::make_shared<RigidBody>();
    b->add(g);
    b->setPosition(p);
    w.sim->add(b);
    s.push_back(b);
  }
  auto spread = [&] {
    Real worst = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        worst = std::max(worst, std::abs((s[i]->getPosition() - s[j]->getPosition()).norm() - d));
    return worst;
  };
  w.sim->stepForward();
  const auto& st = w.sim->getSolver().getStats();
  CHECK(st.numDirectRows == 6 * 3);  // 6 pairs, normal + 2 friction rows each, no ground contact yet
  CHECK(st.numFactorisations == 1);
  CHECK(st.numPivots == 0);
  Real worst = 0;
  for (int i = 0; i < 120; ++i) {
    w.sim->stepForward();
    worst = std::max(worst, spread());
  }
  std::printf("lump: worst relative displacement %.3e m, base height %.5f m\n", worst, s[0]->getPosition().z());
  CHECK(worst < 1e-6);
  CHECK(s[0]->getPosition().z() == doctest::Approx(r).epsilon(1e-3).scale(0));  // landed
}

TEST_CASE("the symbolic analysis is reused while the sparsity pattern holds" * test::needsDirectSolver()) {
  // A hanging chain keeps its rows and pattern every step: one analysis on the first step, none after.
  scenes::Chain20Scene s = scenes::buildChain20(100.0, true);
  s.step();
  CHECK(s.sim->getSolver().getStats().numSymbolicAnalyses == 1);
  for (int i = 0; i < 5; ++i) {
    s.step();
    CHECK(s.sim->getSolver().getStats().numSymbolicAnalyses == 0);
    CHECK(s.sim->getSolver().getStats().numFactorisations == 1);
  }
  // Both forms solve the same system: the mass-ratio stack with DIRECT contacts ends in the same state to
  // round-off amplified over 60 steps (1e-9 m; the penetrations are 6e-6 m).
  Vec3 heavy[2];
  int k = 0;
  for (Solver::DirectForm f : {Solver::SCHUR, Solver::KKT}) {
    scenes::MassRatioScene m = scenes::buildMassRatio();
    setSolveType(m, FrictionModel::DIRECT);
    m.sim->getSolver().setDirectForm(f);
    for (int i = 0; i < 60; ++i) m.step();
    CHECK(m.sim->getSolver().getStats().directForm == int(f));
    heavy[k++] = m.heavy->getPosition();
  }
  CHECK((heavy[0] - heavy[1]).norm() < 1e-9);
}

TEST_CASE("a box sliding at 5 m/s with mu 0.3 and DIRECT contacts stops at v^2/(2 mu g) in both forms" *
          test::needsDirectSolver()) {
  // While the box slides, its friction rows sit at their bounds: the direct solve holds them there and solves
  // the free rows with the held lines of the matrix cleared. The discrete-exact stop (test_analytic_friction.cpp)
  // is 4.2056 m, -0.98 % of v0^2 / (2 mu g) = 4.2474 m; 2 % allows that floor and one step of stop time. Both
  // forms solve the same system, so they end within round-off of each other (1e-9 m over the 2 s run).
  Real distance[2];
  int k = 0;
  for (Solver::DirectForm f : {Solver::SCHUR, Solver::KKT}) {
    scenes::SlideScene s = scenes::buildSlide(0.3, 5.0);
    setSolveType(s, FrictionModel::DIRECT);
    s.sim->getSolver().setDirectForm(f);
    const Real x0 = s.box->getPosition().x();
    size_t pivots = 0;
    for (int i = 0; i < 120; ++i) {
      s.step();
      pivots += s.sim->getSolver().getStats().numPivots;
      CHECK(s.sim->getSolver().getStats().directForm == int(f));
    }
    distance[k] = s.box->getPosition().x() - x0;
    MESSAGE("slide DIRECT form " << int(f) << ": distance " << distance[k] << " m (analytic "
                                 << s.analyticDistance() << "), pivots " << pivots);
    CHECK(pivots > 0);  // rows were held at their bounds
    CHECK(std::abs(distance[k] / s.analyticDistance() - 1) < 0.02);
    CHECK(std::abs(s.box->getPosition().y()) < 1e-3);
    ++k;
  }
  CHECK(std::abs(distance[0] - distance[1]) < 1e-9);
}
