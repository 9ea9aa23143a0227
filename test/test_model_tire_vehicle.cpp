// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// A four-wheeled vehicle on TwoBodyTireModel tires (issue 6; scene in bench/scenes/vehicle.h): static sag
// per tire, driving on flat ground, and over a bump.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "scenes/vehicle.h"
#include "test_world.h"

using namespace scree;
using namespace scree::scenes;

TEST_SUITE("tire") {
  TEST_CASE("a four-wheeled vehicle settles to its static sag: each tire deflects (chassis + rims) g / 4k") {
    // The vehicle is symmetric (centre of mass above the centre of the wheel base), so each tire model carries
    // a quarter of the chassis and rim weight. With the motors holding (speed 0) and 2 s of settling (radial
    // damping ratio ~0.35 with a quarter of the 440 kg), the residual transient is < 1e-6. 2 % bound; the
    // measured error is ~1e-7 relative.
    VehicleParams p;
    VehicleScene s = buildVehicle(p);
    for (int i = 0; i < int(2.0 / p.dt); ++i) s.step();
    const Real load = (p.chassisMass + 4 * p.rimMass) * SceneConstants::gravity / 4;
    for (size_t i = 0; i < 4; ++i) {
      CAPTURE(i);
      const auto& m = s.tireModels[i];
      const Real expect = load / m->getStiffness(TwoBodyTireModel::RADIAL);
      MESSAGE("tire " << i << ": sag " << m->getRadialDeflection() << " m, expected " << expect << ", rel err "
                      << (m->getRadialDeflection() - expect) / expect);
      CHECK(std::abs(m->getRadialDeflection() - expect) / expect < 0.02);
      CHECK(std::abs(m->getForce(TwoBodyTireModel::RADIAL) - load) / load < 0.02);
    }
    CHECK(scenes::allFinite(*s.sim));
  }

  TEST_CASE("the vehicle drives at the motors' speed, rolls without slip and climbs a bump") {
    // Motor target 2 m/s with 400 N m per wheel: the front tires spin up at once and slip (the load moves to
    // the rear), the vehicle accelerates at ~0.65 g and runs at the target speed after ~0.6 s. Over the 8 cm bump the front tires' deflection peaks above the static
    // sag and the vehicle keeps going. v = omega r within 1 %: the tire radius shrinks by the contact overlap
    // only (~1e-5 m of 0.35 m).
    VehicleParams p;
    p.speed = 2.0;
    p.bump = true;
    p.bumpX = 5.0;  // reached after ~1.6 s
    VehicleScene s = buildVehicle(p);
    Real peak = 0;
    const Real staticSag = (p.chassisMass + 4 * p.rimMass) * SceneConstants::gravity / 4 / 3.5e5;
    for (int i = 0; i < int(1.0 / p.dt); ++i) s.step();
    const Real v = s.chassis->getVelocity().x();
    const Real omega = s.tires[0]->getAngularVelocity().y();
    MESSAGE("flat: v " << v << " m/s, omega r " << omega * p.tireRadius);
    CHECK(std::abs(v - p.speed) / p.speed < 0.01);
    CHECK(std::abs(omega * p.tireRadius - v) / v < 0.01);
    for (int i = 0; i < int(4.0 / p.dt); ++i) {
      s.step();
      peak = std::max(peak, s.tireModels[0]->getRadialDeflection());
    }
    MESSAGE("bump: front-left peak deflection " << peak << " m, static " << staticSag << "; chassis x "
                                                << s.chassis->getPosition().x());
    CHECK(peak > 1.5 * staticSag);
    CHECK(s.chassis->getPosition().x() > p.bumpX + p.wheelBase);  // both axles over the bump
    CHECK(std::abs(s.chassis->getVelocity().x() - p.speed) / p.speed < 0.05);
    CHECK(scenes::allFinite(*s.sim));
  }
}
