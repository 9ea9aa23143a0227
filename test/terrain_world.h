// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Helpers shared by the terrain tests: a flat terrain with a soil thickness (so the ledger total is a real volume
// to be relative to), and a step loop that checks the volume ledger after every step.
#pragma once

#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <memory>

#include "test_world.h"

namespace scree::test {

/// A flat n x n terrain of the given size whose surface is at world z = 0 on `thickness` m of soil (heights =
/// thickness, geometry at z = -thickness), with the world's material.
inline TerrainRef addFlatTerrain(TestWorld& w, size_t n, Real size, Real thickness = 0.5) {
  auto hf = std::make_shared<HeightField>(n, n, size, size);
  hf->setHeights(std::vector<Real>(n * n, thickness));
  auto terrain = std::make_shared<Terrain>(hf);
  terrain->getGeometry()->setMaterial(w.material);
  terrain->getGeometry()->setPosition(Vec3(0, 0, -thickness));
  w.sim->add(terrain);
  return terrain;
}

/// Steps n times and checks after every step that the ledger total stays at its value before the first step to
/// 1e-9 relative (the ledger invariant, docs/terrain.md: no terrain operation creates or destroys soil), and at the end that the
/// incremental heightField account equals the full-grid sum (same bound). Returns the largest relative drift.
inline Real stepCheckingLedger(TestWorld& w, const Terrain& t, int n) {
  const Real total0 = t.getVolumeLedger().total();
  Real worst = 0;
  for (int i = 0; i < n; ++i) {
    w.sim->stepForward();
    const Real drift = std::abs(t.getVolumeLedger().total() - total0) / std::abs(total0);
    worst = std::max(worst, drift);
    if (drift > 1e-9) {
      FAIL_CHECK("ledger total drifted by " << drift << " (relative) at step " << i);
      return drift;
    }
  }
  const Real full = t.computeHeightFieldVolume();
  CHECK(std::abs(t.getVolumeLedger().heightField - full) <= 1e-9 * std::abs(total0));
  return worst;
}

}  // namespace scree::test

namespace scree::test {

/// A step listener running a function in pre() (forces for this step).
class LambdaStepListener : public StepEventListener {
 public:
  explicit LambdaStepListener(std::function<void(const TimeStamp&)> f) : StepEventListener(PRE_STEP), f_(std::move(f)) {}
  void pre(const TimeStamp& t) override { f_(t); }

 private:
  std::function<void(const TimeStamp&)> f_;
};

/// A plate of small spheres, one directly above each vertex (i, j) of the terrain with i0 <= i <= i1,
/// j0 <= j <= j1, on one light rigid body: each sphere's single contact point lands on its vertex, so the plate
/// loads every vertex under it with the same force (a box's contact with a height field is reduced to four
/// points at its corners and would load only those). Returns the body; its bottom touches z = 0.
inline RigidBodyRef addSpherePlate(TestWorld& w, const Terrain& t, size_t i0, size_t i1, size_t j0, size_t j1,
                                   Real radius, Real mass) {
  auto body = std::make_shared<RigidBody>("plate");
  const HeightField& hf = *t.getHeightField();
  Vec3 centre = Vec3::Zero();
  const Vec3 origin = t.getGeometry()->getPosition();
  for (size_t j = j0; j <= j1; ++j)
    for (size_t i = i0; i <= i1; ++i) centre += hf.getVertex(i, j) + origin;
  centre /= Real((i1 - i0 + 1) * (j1 - j0 + 1));
  centre.z() = 0;
  for (size_t j = j0; j <= j1; ++j)
    for (size_t i = i0; i <= i1; ++i) {
      auto g = std::make_shared<Geometry>(std::make_shared<Sphere>(radius));
      g->setMaterial(w.material);
      Vec3 at = hf.getVertex(i, j) + origin;
      at.z() = radius;
      g->setLocalPosition(at - centre);
      body->add(g);
    }
  body->setMass(mass);
  body->setPosition(centre);
  w.sim->add(body);
  return body;
}

}  // namespace scree::test
