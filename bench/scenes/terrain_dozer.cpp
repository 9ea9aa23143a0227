// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scenes/terrain_dozer.h"

#include <algorithm>
#include <cmath>

namespace scree::scenes {

int TerrainDozerScene::phaseSteps(size_t k) const { return int(std::lround(phases[k].seconds / params.dt)); }

int TerrainDozerScene::totalSteps() const {
  int n = 0;
  for (size_t k = 0; k < phases.size(); ++k) n += phaseSteps(k);
  return n;
}

size_t TerrainDozerScene::currentPhase() const {
  int n = stepIndex;
  for (size_t k = 0; k < phases.size(); ++k) {
    if (n < phaseSteps(k)) return k;
    n -= phaseSteps(k);
  }
  return phases.size();
}

void TerrainDozerScene::step() {
  const size_t k = currentPhase();
  const Real v = k < phases.size() ? phases[k].speed : 0;
  const bool lifted = k >= phases.size() || phases[k].lifted;
  Vec3 p = blade->getPosition();
  p.y() = 0;
  p.z() = 0.5 * params.bladeHeight + (lifted ? params.restLift : -params.depth);
  blade->setPosition(p);
  blade->setRotation(Quat::Identity());
  blade->setVelocity(Vec3(v, 0, 0));
  blade->setAngularVelocity(Vec3::Zero());
  sim->stepForward();
  ++stepIndex;
}

namespace {
/// Vertex index range [i0, i1] x [j0, j1] of the region 1.5 m ahead of the blade's front, |y| < 0.4 width.
struct Region {
  size_t i0, i1, j0, j1;
};
Region aheadOfBlade(const TerrainDozerScene& s) {
  const TerrainDozerParams& p = s.params;
  const Real half = 0.5 * p.cell * Real(p.n - 1);
  const Real front = s.blade->getPosition().x() + 0.5 * p.bladeThickness;
  auto clampIdx = [&](Real x) {
    return size_t(std::clamp<Real>(std::floor((x + half) / p.cell), 0, Real(p.n - 1)));
  };
  const Real yHalf = 0.4 * p.bladeWidth;
  return {clampIdx(front) + 1, clampIdx(front + 1.5), clampIdx(-yHalf) + 1, clampIdx(yHalf)};
}
}  // namespace

Real TerrainDozerScene::bermHeight() const {
  const Region r = aheadOfBlade(*this);
  Real sum = 0;
  int rows = 0;
  for (size_t j = r.j0; j <= r.j1; ++j) {
    Real top = 0;
    for (size_t i = r.i0; i <= r.i1; ++i) top = std::max(top, field->getHeight(i, j) - params.thickness);
    sum += top;
    ++rows;
  }
  return rows ? sum / rows : 0;
}

Real TerrainDozerScene::bermSlope() const {
  const Region r = aheadOfBlade(*this);
  Real worst = 0;
  for (size_t j = r.j0; j <= r.j1; ++j)
    for (size_t i = r.i0; i <= r.i1; ++i)
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          if (di == 0 && dj == 0) continue;
          const size_t a = i + size_t(di), b = j + size_t(dj);  // wraps to huge when negative: skipped below
          if (a >= params.n || b >= params.n) continue;
          const Real dist = params.cell * std::hypot(Real(di), Real(dj));
          worst = std::max(worst, std::atan(std::abs(field->getHeight(i, j) - field->getHeight(a, b)) / dist));
        }
  return worst;
}

TerrainDozerScene buildTerrainDozer(const TerrainDozerParams& p) {
  TerrainDozerScene s;
  s.params = p;
  initScene(s, "terrain_dozer", p.mu, p.dt, 0);
  s.contactMaterial->setYoungsModulus(p.youngsModulus);
  const Real size = p.cell * Real(p.n - 1);
  s.field = std::make_shared<HeightField>(p.n, p.n, size, size);
  s.field->setHeights(std::vector<Real>(p.n * p.n, p.thickness));
  s.terrain = std::make_shared<Terrain>(s.field);
  s.terrain->getGeometry()->setMaterial(s.material);
  s.terrain->getGeometry()->setPosition(Vec3(0, 0, -p.thickness));
  s.sim->add(s.terrain);
  s.terrain->setEnableDynamicHeightField(p.dynamicHeightField);
  // The blade only translates: the angular cut-off out of reach, as in the deform test.
  s.terrain->setDynamicHeightFieldCutOffAngularVelocity(1e9);

  const Vec3 half(0.5 * p.bladeThickness, 0.5 * p.bladeWidth, 0.5 * p.bladeHeight);
  s.blade = addBox(s, half, 1000, Vec3(p.startX, 0, half.z() - p.depth));
  s.blade->getGeometries().front()->getPropertyContainer().addPropertyBool(Terrain::DeformerProperty, false);
  s.phases = {{"push", p.pushSeconds, p.speed, false}, {"rest", p.restSeconds, 0, true}};
  s.numSteps = s.totalSteps();
  return s;
}

}  // namespace scree::scenes
