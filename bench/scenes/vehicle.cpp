// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scenes/vehicle.h"

namespace scree::scenes {

VehicleScene buildVehicle(const VehicleParams& p) {
  VehicleScene s;
  initScene(s, p.rigidWheels ? "vehicle_rigid" : "vehicle_tire", p.mu, p.dt, 0);
  s.params = p;
  s.sim->getSolver().setNumIterations(p.iterations);

  auto plane = std::make_shared<Geometry>(std::make_shared<Plane>(Vec3::UnitZ(), 0.0));
  plane->setMaterial(s.material);
  s.sim->add(plane);
  if (p.bump) {
    auto bump = std::make_shared<Geometry>(std::make_shared<Cylinder>(p.bumpRadius, p.track + 1.0));
    bump->setMaterial(s.material);
    bump->setPosition(Vec3(p.bumpX, 0, p.bumpHeight - p.bumpRadius));
    s.sim->add(bump);
  }

  const Real r = p.tireRadius;
  s.chassis = std::make_shared<RigidBody>("chassis");
  auto box = std::make_shared<Geometry>(std::make_shared<Box>(p.chassisHalfExtents));
  box->setMaterial(s.material);
  s.chassis->add(box);
  s.chassis->setMass(p.chassisMass);
  s.chassis->setPosition(Vec3(0, 0, r + p.clearance + p.chassisHalfExtents.z()));
  s.sim->add(s.chassis);

  const Real xs[2] = {0.5 * p.wheelBase, -0.5 * p.wheelBase};
  const Real ys[2] = {0.5 * p.track, -0.5 * p.track};
  for (Real x : xs)
    for (Real y : ys) {
      const Vec3 c(x, y, r);
      auto tire = std::make_shared<RigidBody>("tire");
      auto geom = std::make_shared<Geometry>(std::make_shared<Cylinder>(r, p.tireWidth));
      geom->setMaterial(s.material);
      tire->add(geom);
      tire->setMass(p.rigidWheels ? p.tireMass + p.rimMass : p.tireMass);
      tire->setPosition(c);
      s.sim->add(tire);
      s.tires.push_back(tire);

      RigidBodyRef driven = tire;
      if (!p.rigidWheels) {
        auto rim = std::make_shared<RigidBody>("rim");
        const Real m = p.rimMass, rr = p.rimRadius;
        rim->setMass(m);
        rim->setInertiaTensor(Vec3(0.25 * m * rr * rr, 0.5 * m * rr * rr, 0.25 * m * rr * rr).asDiagonal());
        rim->setPosition(c);
        s.sim->add(rim);
        s.rims.push_back(rim);
        auto model = std::make_shared<TwoBodyTireModel>(tire, r, rim, p.rimRadius);
        s.sim->add(model);
        s.tireModels.push_back(model);
        driven = rim;
      }
      auto axle = std::make_shared<Hinge>(driven, s.chassis, c, Vec3::UnitY());
      Motor1D& motor = axle->getMotor1D();
      motor.setEnable(true);
      motor.setSpeed(p.speed / r);
      motor.setForceRange(-p.maxTorque, p.maxTorque);
      s.sim->add(axle);
      s.axles.push_back(axle);
    }
  return s;
}

}  // namespace scree::scenes
