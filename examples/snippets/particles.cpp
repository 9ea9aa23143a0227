// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Granular particles: a block of 1,000 sand grains dropped onto the ground (docs/particles.md).
#include <cstdio>
#include <scree/scree.h>
using namespace scree;

int main() {
  Simulation sim;
  auto ground = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(1, 1, 0.1)));
  ground->setPosition(Vec3(0, 0, -0.1));
  sim.add(ground);

  GranularBodySystem& particles = sim.getGranularBodySystem();
  auto sand = std::make_shared<Material>("sand");
  sand->setDensity(2600);
  sand->setRestitution(0);
  sand->setRollingResistanceCoefficient(0.1);  // without it round grains roll away instead of heaping
  particles.setMaterial(sand);                  // for the particles created from now on
  for (int k = 0; k < 10; ++k)
    for (int j = 0; j < 10; ++j)
      for (int i = 0; i < 10; ++i)
        particles.createParticle(Vec3(0.021 * i - 0.1, 0.021 * j - 0.1, 0.05 + 0.021 * k), 0.01);

  setNumThreads(1);  // threads of the parallel stages (default: OpenMP's); results are identical for any count
  for (int i = 0; i < 120; ++i) sim.stepForward();

  Real top = 0;
  particles.forEachParticle([&](size_t id) { top = std::max(top, particles.getPosition(id).z()); });
  std::printf("%zu particles, highest centre at %.3f m after 2 s\n", particles.numParticles(), top);
}
