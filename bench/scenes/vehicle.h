// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Four-wheeled vehicle on TwoBodyTireModel tires (issue 6), shared by the tire tests, bench/bench_tire.cpp
// and the demo. Not one of docs/scenes.md's reference scenes; it uses the scene conventions (z up, g 9.81, one
// scene material, explicit contact material).
//
// chassis (box) --Hinge with Motor1D, axle y--> rim (mass only) --TwoBodyTireModel--> tire (Cylinder, axis y)
// The ground is a static plane z = 0 (cylinder-plane is an analytic pair); an optional bump is a static
// cylinder lying across the path. With rigidWheels the tire body is hinged to the chassis directly (no rim, no
// tire model): the reference for the tire's overhead.
#pragma once

#include <vector>

#include "scenes/scenes.h"

namespace scree::scenes {

struct VehicleParams {
  Real chassisMass = 400;                  ///< kg
  Vec3 chassisHalfExtents{1.2, 0.6, 0.15};  ///< m
  Real wheelBase = 2.0;                    ///< axle to axle, m
  Real track = 1.5;                        ///< wheel centre to wheel centre across, m
  Real tireRadius = 0.35, tireWidth = 0.2, tireMass = 15;  ///< m, m, kg
  Real rimRadius = 0.22, rimMass = 10;
  Real clearance = 0.2;                    ///< chassis bottom above the wheel centres, m
  Real speed = 0;                          ///< motor target ground speed, m/s (motor speed = speed / radius)
  Real maxTorque = 400;                    ///< motor torque limit per wheel, N m
  bool rigidWheels = false;
  bool bump = false;
  Real bumpX = 3.0, bumpHeight = 0.08, bumpRadius = 0.3;  ///< bump across the path at x, m
  Real mu = 0.8;
  /// 1/400 s keeps the PGS wheel chains tight (parked sag error ~1e-7); at 1/60 the vehicle still runs stably,
  /// with parked sag -0.2 % and 1.85 instead of 2 m/s 5 s into the bump drive.
  Real dt = 1.0 / 400;
  int iterations = 20;
};

struct VehicleScene : Scene {
  VehicleParams params;
  RigidBodyRef chassis;
  std::vector<RigidBodyRef> rims, tires;        ///< front left, front right, rear left, rear right
  std::vector<HingeRef> axles;
  std::vector<TwoBodyTireModelRef> tireModels;  ///< empty with rigidWheels
};

/// Builds the vehicle at rest with its tires just touching the ground (undeformed).
VehicleScene buildVehicle(const VehicleParams& p = {});

}  // namespace scree::scenes
