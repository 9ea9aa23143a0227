// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// External consumer of the Scree package: a 1 m box dropped onto a static ground box must come to rest on it.
// Exit status 0 only when, after 1 s, the box's centre is at z = 0.5 m (ground top z = 0, half extent 0.5 m)
// within 1 mm and it has (almost) stopped.
#include <cmath>
#include <cstdio>
#include <memory>

#include <scree/scree.h>

int main() {
  using namespace scree;

  Simulation sim;
  sim.setTimeStep(1.0 / 60.0);

  // Ground: a static body with a 10 m x 10 m x 1 m box whose top face is at z = 0.
  auto ground = std::make_shared<RigidBody>("ground");
  ground->setMotionControl(RigidBody::STATIC);
  ground->add(std::make_shared<Geometry>(std::make_shared<Box>(Vec3(5.0, 5.0, 0.5))));
  ground->setPosition(Vec3(0.0, 0.0, -0.5));
  sim.add(ground);

  // A 1 m cube (1000 kg at the default density) released 0.1 m above the ground.
  auto material = std::make_shared<Material>("crate");
  material->setDensity(1000.0);
  auto boxGeometry = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.5, 0.5, 0.5)));
  boxGeometry->setMaterial(material);
  auto box = std::make_shared<RigidBody>("box");
  box->add(boxGeometry);
  box->setPosition(Vec3(0.0, 0.0, 0.6));
  sim.add(box);

  const int steps = static_cast<int>(std::lround(1.0 / sim.getTimeStep()));
  for (int i = 0; i < steps; ++i) sim.stepForward();

  const Vec3 p = box->getPosition();
  const Real speed = box->getVelocity().norm();
  const Real error = std::abs(p.z() - 0.5);
  std::printf("%s\n", getConfigurationString());
  std::printf("t = %.3f s  box at (%.6f, %.6f, %.6f) m  |v| = %.2e m/s  |z - 0.5| = %.2e m  contacts = %zu\n",
              sim.getTimeStamp(), p.x(), p.y(), p.z(), speed, error, sim.getContacts().size());

  const bool ok = std::isfinite(p.z()) && error <= 1e-3 && speed <= 1e-2;
  std::printf("%s\n", ok ? "OK: the box rests on the ground" : "FAIL: the box is not resting at z = 0.5 m");
  return ok ? 0 : 1;
}
