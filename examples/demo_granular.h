// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Granular part of scree_demo: a nozzle pours particles (r = 3 cm, with rolling resistance) onto the ground at
// (-5, -5) for the first seconds, forming a conical pile. Written as a step listener so the demo only adds
// it to the simulation: it creates particles in preCollide, at run time, through GranularBodySystem.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include <scree/scree.h>

namespace scree::demo {

class GranularPile : public StepEventListener {
 public:
  /// `ground` is the material of what the pile lands on.
  GranularPile(Simulation& sim, const MaterialRef& ground, size_t maxParticles = 2000)
      : StepEventListener(PRE_COLLIDE), sim_(sim), max_(maxParticles) {
    grain_ = std::make_shared<Material>("grain");
    grain_->setDensity(2500);
    auto& mm = sim.getMaterialManager();
    for (const MaterialRef& other : {grain_, ground}) {
      auto cm = mm.getOrCreateContactMaterial(grain_, other);
      cm->setFrictionCoefficient(0.5);
      cm->setRestitution(0.0);
      cm->setRollingResistanceCoefficient(0.2);
    }
  }

  void preCollide(const TimeStamp&) override {
    GranularBodySystem& ps = sim_.getGranularBodySystem();
    if (created_ >= max_ || ++step_ % 4 != 0) return;
    ps.setMaterial(grain_);
    for (int a = -1; a <= 1 && created_ < max_; ++a)
      for (int b = -1; b <= 1 && created_ < max_; ++b) {
        const Real jitter = 0.002 * std::sin(0.7 * Real(created_));
        ps.createParticle(Vec3(-5 + a * 0.065 + jitter, -5 + b * 0.065 - jitter, 1.0), 0.03, Vec3(0, 0, -1));
        ++created_;
      }
  }

  /// The grains' material (the particle system's material from the first pour on).
  const MaterialRef& getGrainMaterial() const { return grain_; }

  /// One line: particles, pile height, kinetic energy.
  void printSummary() const {
    const GranularBodySystem& ps = sim_.getGranularBodySystem();
    Real top = 0, ke = 0;
    ps.forEachParticle([&](size_t id) {
      top = std::max(top, ps.getPosition(id).z() + ps.getRadius(id));
      ke += 0.5 * ps.getMass(id) * ps.getVelocity(id).squaredNorm();
    });
    std::printf("granular pile: %zu particles, height %.3f m, kinetic energy %.4g J\n", ps.numParticles(), top, ke);
  }

 private:
  Simulation& sim_;
  MaterialRef grain_;
  size_t max_, created_ = 0;
  long step_ = 0;
};

}  // namespace scree::demo
