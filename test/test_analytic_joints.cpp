// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Joints and compliant constraints against closed-form dynamics (issue: joints, compliant constraints).
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "test_world.h"

using namespace scree;
using namespace scree::test;

namespace {
// Complete elliptic integral of the first kind via the arithmetic-geometric mean: K(k) = pi / (2 AGM(1, k')).
Real ellipticK(Real k) {
  Real a = 1, b = std::sqrt(1 - k * k);
  for (int i = 0; i < 40; ++i) {
    const Real an = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = an;
  }
  return M_PI / (2 * a);
}

// A simple pendulum: a massless rod of length L from the origin to the centre of a 1 kg bob, i.e. a
// DistanceJoint anchored at the bob's centre of mass (the bob's own inertia plays no part, exactly as in the
// closed form). Released at theta0 from the downward vertical; returns the mean period over `periods` swings,
// measured from upward zero crossings of the angle (linear interpolation between steps).
// (A hinge at 1 m from a 1 cm bob would model the same pendulum, but its rows are coupled through the bob's
// tiny spin inertia, I / (m L^2) = 4e-5: an ill-conditioned system PGS cannot solve in 16 sweeps.)
Real pendulumPeriod(Real theta0, Real h, int periods) {
  TestWorld w(h, 9.81);
  const Real L = 1.0;
  const Vec3 p0(L * std::sin(theta0), 0, -L * std::cos(theta0));
  auto bob = w.addSphere(0.01, p0, 1.0);
  auto rod = std::make_shared<DistanceJoint>(bob, nullptr, p0, Vec3::Zero());
  w.sim->add(rod);
  std::vector<Real> crossings;
  Real prev = std::atan2(bob->getPosition().x(), -bob->getPosition().z());
  while (crossings.size() < size_t(periods + 1) && w.time() < 100) {
    w.sim->stepForward();
    const Real a = std::atan2(bob->getPosition().x(), -bob->getPosition().z());
    if (prev < 0 && a >= 0) crossings.push_back(w.time() - h * a / (a - prev));
    prev = a;
  }
  REQUIRE(crossings.size() == size_t(periods + 1));
  return (crossings.back() - crossings.front()) / periods;
}
}  // namespace

TEST_SUITE("joints") {
  TEST_CASE("simple pendulum at 5 degrees swings with period 2 pi sqrt(L/g)") {
    // Tolerance 0.5 %: the finite amplitude adds theta0^2/16 = 0.048 %, the bob's own inertia 4e-5, symplectic
    // Euler's phase error at omega h = 0.031 is (omega h)^2/24 = 4e-5, and the crossing interpolation error is
    // well below h/100 over 10 periods. Compliance 1e-8 m/N stretches the 1 m rod by 1e-7 m.
    const Real g = 9.81, L = 1.0;
    const Real T = pendulumPeriod(5 * M_PI / 180, 0.01, 10);
    const Real T0 = 2 * M_PI * std::sqrt(L / g);
    MESSAGE("period " << T << " s, small-angle " << T0 << " s, rel err " << (T - T0) / T0);
    CHECK(std::abs(T - T0) / T0 < 0.005);
  }

  TEST_CASE("pendulum at 60 degrees matches the elliptic-integral period") {
    // T = 4 sqrt(L/g) K(sin(theta0/2)). Within 1 %: the discretisation errors above stay below 1e-3.
    const Real g = 9.81, L = 1.0, th = M_PI / 3;
    const Real T = pendulumPeriod(th, 0.01, 5);
    const Real Te = 4 * std::sqrt(L / g) * ellipticK(std::sin(th / 2));
    MESSAGE("period " << T << " s, elliptic " << Te << " s, rel err " << (T - Te) / Te);
    CHECK(std::abs(T - Te) / Te < 0.01);
  }

  TEST_CASE("one compliant DOF oscillates at sqrt(k/m) and decays with damping ratio c/(2 sqrt(km))") {
    const Real m = 2.0, k = 800.0;  // omega = 20 rad/s
    const Real omega = std::sqrt(k / m);
    const Real h = 0.1 / omega / 2;  // omega h = 0.05
    auto run = [&](Real c, std::vector<Real>& peaks, std::vector<Real>& peakTimes) {
      TestWorld w(h, 0.0);
      // The joint's rest state is the configuration at construction: build it at x = 0, then displace.
      auto body = w.addSphere(0.05, Vec3::Zero(), m);
      auto j = std::make_shared<Generic6DofJoint>(body, nullptr, Vec3::Zero());
      j->setStiffness(Generic6DofJoint::TRANSLATIONAL_1, k, c);
      w.sim->add(j);
      body->setPosition(Vec3(0.1, 0, 0));
      Real x0 = body->getPosition().x(), x1 = x0;
      for (int i = 0; i < int(6 * 2 * M_PI / omega / h); ++i) {
        w.sim->stepForward();
        const Real x2 = body->getPosition().x();
        if (x1 > x0 && x1 >= x2 && x1 > 0) {
          // Parabolic peak interpolation through the three samples.
          const Real den = x0 - 2 * x1 + x2;
          const Real off = den != 0 ? 0.5 * (x0 - x2) / den : 0;
          peaks.push_back(x1 - 0.25 * (x0 - x2) * off);
          peakTimes.push_back(w.time() - h + off * h);
        }
        x0 = x1;
        x1 = x2;
      }
    };
    std::vector<Real> peaks, times;
    run(0.0, peaks, times);
    REQUIRE(peaks.size() >= 4);
    const Real period = (times.back() - times.front()) / Real(times.size() - 1);
    const Real wMeasured = 2 * M_PI / period;
    MESSAGE("omega " << wMeasured << " vs " << omega);
    // 1 %: SPOOK's effective stiffness k/(1 + k h^2/(4 m)) and symplectic Euler shift omega by ~(omega h)^2/8.
    CHECK(std::abs(wMeasured - omega) / omega < 0.01);
    // Undamped: amplitude kept within 1 % over six periods (no numerical damping at d = 0).
    CHECK(peaks.back() > 0.99 * peaks.front());

    const Real zeta = 0.05, c = zeta * 2 * std::sqrt(k * m);
    std::vector<Real> dpeaks, dtimes;
    run(c, dpeaks, dtimes);
    REQUIRE(dpeaks.size() >= 3);
    // Logarithmic decrement delta = ln(A_n / A_n+1) = 2 pi zeta / sqrt(1 - zeta^2).
    const Real delta = std::log(dpeaks.front() / dpeaks.back()) / Real(dpeaks.size() - 1);
    const Real zetaMeasured = delta / std::sqrt(4 * M_PI * M_PI + delta * delta);
    MESSAGE("damping ratio " << zetaMeasured << " vs " << zeta);
    CHECK(std::abs(zetaMeasured - zeta) / zeta < 0.05);
  }

  TEST_CASE("hinge motor reaches its target speed, and stalls at its force limit") {
    const Real h = 1.0 / 60;
    TestWorld w(h, 0.0);
    auto rotor = w.addBox(Vec3(0.5, 0.1, 0.1), Vec3::Zero(), 10.0);
    auto hinge = std::make_shared<Hinge>(rotor, nullptr, Vec3::Zero(), Vec3::UnitZ());
    hinge->getMotor1D().setEnable(true);
    hinge->getMotor1D().setSpeed(2.0);
    hinge->getMotor1D().setForceRange(-100, 100);
    w.sim->add(hinge);
    w.stepSeconds(1.0);
    const Real speed = hinge->getCurrentSpeed();
    MESSAGE("motor speed " << speed << " rad/s (target 2)");
    // 1 %: the motor row's compliance 1e-10 lets the speed lag by force * 1e-10, negligible here.
    CHECK(std::abs(speed - 2.0) / 2.0 < 0.01);
    CHECK(std::abs(rotor->getAngularVelocity().z() - 2.0) < 0.02);

    // Load torque 50 N m against a 20 N m motor: it stalls (cannot hold speed) and applies exactly its limit.
    hinge->getMotor1D().setForceRange(-20, 20);
    for (int i = 0; i < 60; ++i) {
      rotor->addTorque(Vec3(0, 0, -50));
      w.sim->stepForward();
    }
    const Real motorTorque = hinge->getMotor1D().getCurrentForce();
    MESSAGE("stalled motor torque " << motorTorque << " N m, speed " << hinge->getCurrentSpeed());
    CHECK(std::abs(motorTorque - 20.0) < 0.2);
    CHECK(hinge->getCurrentSpeed() < 0.0);
  }

  TEST_CASE("prismatic range holds its limit within the compliance-predicted error") {
    const Real h = 1.0 / 60, m = 10.0, g = 9.81, eps = 1e-5;
    TestWorld w(h, g);
    auto slider = w.addBox(Vec3(0.1, 0.1, 0.1), Vec3(0, 0, 0), m);
    auto pr = std::make_shared<Prismatic>(slider, nullptr, Vec3::Zero(), Vec3::UnitZ());
    pr->getRange1D().setEnable(true);
    pr->getRange1D().setRange(-0.5, 0.5);
    pr->getRange1D().setCompliance(eps);
    w.sim->add(pr);
    w.stepSeconds(3.0);
    // At rest the range row is a spring 1/eps loaded by m g: position = lower - m g eps.
    const Real expected = -0.5 - m * g * eps;
    const Real pos = pr->getAngle();
    MESSAGE("slide position " << pos << " expected " << expected << " (deflection " << m * g * eps << " m)");
    CHECK(std::abs(pos - expected) < 0.02 * m * g * eps);
    CHECK(std::abs(pr->getRange1D().getCurrentForce() - m * g) < 0.01 * m * g);
  }

  TEST_CASE("hinge lock acts as a torsion spring K with damping D") {
    // Lock1D with compliance 1/K: a constant torque T holds the hinge at T/K.
    const Real h = 1.0 / 60, K = 500.0, T = 25.0;
    TestWorld w(h, 0.0);
    auto rotor = w.addBox(Vec3(0.5, 0.1, 0.1), Vec3::Zero(), 10.0);
    auto hinge = std::make_shared<Hinge>(rotor, nullptr, Vec3::Zero(), Vec3::UnitZ());
    hinge->getLock1D().setEnable(true);
    hinge->getLock1D().setCompliance(1.0 / K);
    hinge->getLock1D().setDamping(0.1);
    w.sim->add(hinge);
    for (int i = 0; i < 600; ++i) {
      rotor->addTorque(Vec3(0, 0, T));
      w.sim->stepForward();
    }
    MESSAGE("angle " << hinge->getAngle() << " expected " << T / K);
    CHECK(std::abs(hinge->getAngle() - T / K) < 0.01 * T / K);
  }

  TEST_CASE("distance joint keeps its length; ball joint holds a hanging body") {
    const Real h = 1.0 / 60;
    TestWorld w(h, 9.81);
    auto a = w.addSphere(0.05, Vec3(1, 0, 0), 1.0);
    auto dj = std::make_shared<DistanceJoint>(a, nullptr, Vec3(1, 0, 0), Vec3(0, 0, 0));
    w.sim->add(dj);
    auto b = w.addSphere(0.05, Vec3(3, 0, -0.5), 2.0);
    auto bj = std::make_shared<BallJoint>(b, nullptr, Vec3(3, 0, 0));
    w.sim->add(bj);
    Real worst = 0;
    for (int i = 0; i < 300; ++i) {
      w.sim->stepForward();
      worst = std::max(worst, std::abs(dj->getCurrentLength() - 1.0));
    }
    MESSAGE("distance joint worst length error " << worst << " m");
    // Released horizontally, the bob reaches v = sqrt(2 g L) = 4.4 m/s. A velocity-level row keeps the rate of
    // change of the length at zero along the current direction; over one step the direction turns by v h / L,
    // so the length grows by h^2 v^2 / L = 5.4 mm per step, which SPOOK (d = 2) removes at a rate
    // 4/(1 + 4d) = 0.44 per step: a bounded error of order 1 cm at dt 1/60. The compliance share (3 m g
    // x 1e-8 m/N) is negligible. Bound: twice the per-step drift.
    const Real vmax = std::sqrt(2 * 9.81 * 1.0);
    CHECK(worst < 2 * h * h * vmax * vmax / 1.0);
    // Ball joint static load: force along +z on the body equals m g (reported on B = world side as -m g).
    CHECK(std::abs((b->getPosition() - Vec3(3, 0, -0.5)).norm()) < 1e-3);
    const auto& f = bj->getLastForces();
    CHECK(std::abs(std::abs(f[2]) - 2.0 * 9.81) < 0.02 * 2.0 * 9.81);
  }

  TEST_CASE("chain20 with PGS: a 1 kg end mass hangs at the joints' elastic stretch, a 100 kg one comes apart "
            "and is reported") {
    // chain20 of docs/scenes.md (the scene's 10 iterations) with every joint ITERATIVE (joints default to
    // DIRECT_AND_ITERATIVE).
    struct Run {
      scenes::ChainMetrics metrics;
      size_t stepsReported = 0;  // steps whose StepReport listed separated joints
      size_t errorsLogged = 0;
    };
    auto run = [](Real ballMass, bool hanging) {
      Run r;
      Logger::setSink([&](LogLevel l, const std::string&) { r.errorsLogged += l == LogLevel::ERROR; });
      scenes::Chain20Scene s = scenes::buildChain20(ballMass, hanging);
      for (auto& j : s.joints) j->setSolveType(FrictionModel::ITERATIVE);
      scenes::ChainObserver obs(s);
      for (int i = 0; i < s.numSteps; ++i) {
        s.sim->stepForward();
        obs.observe();
        r.stepsReported += !s.sim->getLastStepReport().separatedConstraints.empty();
      }
      Logger::setSink(nullptr);
      r.metrics = obs.result();
      return r;
    };
    // 1:1, hanging at rest: the top joint carries the 20 links and the ball, 21 kg g = 206 N, and its compliance
    // 1e-8 m/N stretches it by 2.06e-6 m; the joints below carry less. Warm-started PGS converges at rest over the
    // 600 steps, so the worst error is that stretch: 1 %, as for the direct solver (test_analytic_direct.cpp).
    // Measured: equal to 4 digits.
    const Run light = run(1.0, true);
    const Real stretch = 21 * 9.81 * 1e-8;
    MESSAGE("chain20 1:1 hanging, PGS: worst joint error " << light.metrics.maxSeparation << " m (stretch "
                                                           << stretch << " m)");
    CHECK(light.metrics.finite);
    CHECK(light.metrics.maxSeparation == doctest::Approx(stretch).epsilon(0.01));
    CHECK(light.stepsReported == 0);
    CHECK(light.errorsLogged == 0);
    // 100:1: PGS at 10 sweeps does not hold it, hanging or released (no engine in docs/scenes.md does; measured
    // 1.9e11 m hanging, beyond 0.1 m from 0.18 s, and 10 m released, from 0.8 s). What is asserted is that it is
    // not silent: a chain beyond the 0.1 m threshold is listed in the step report and logged, at most once per
    // joint (measured: 21 errors, one per joint). Should PGS ever hold it, firstAbove10cm stays -1: then this
    // case, README's status table and docs/speed-accuracy.md need updating.
    for (bool hanging : {true, false}) {
      CAPTURE(hanging);
      const Run heavy = run(100.0, hanging);
      MESSAGE("chain20 100:1 " << std::string(hanging ? "hanging" : "released") << ", PGS: worst joint error "
                               << heavy.metrics.maxSeparation << " m, first > 0.1 m at "
                               << heavy.metrics.firstAbove10cm << " s, " << heavy.stepsReported << " steps reported, " << heavy.errorsLogged
                               << " errors logged");
      CHECK(heavy.metrics.firstAbove10cm >= 0);
      CHECK(heavy.stepsReported > 0);
      CHECK(heavy.errorsLogged >= 1);
      CHECK(heavy.errorsLogged <= 21);  // once per joint, not once per step
    }
  }
}
