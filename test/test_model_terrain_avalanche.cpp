// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Terrain avalanches and the angle of repose (terrain.h, "Dynamic height field: avalanches and the angle of
// repose"; manual 25.1.2.15, 25.1.2.19, 25.1.2.20): avalancheAll on a tall column and a random rough field ends
// with every 8-neighbour pair within repose, the volume exact and the heap's flanks at the angle of repose;
// the per-step pass (decay 0.5 and 0, arming, life time, extent); wetness; locked borders with and without
// avalanche mass loss; merged particles arm avalanches.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "terrain_world.h"

using namespace scree;
using namespace scree::test;

namespace {

constexpr Real kPi = 3.14159265358979323846;

/// Largest excess of any 8-neighbour pair over the repose difference tan(theta(hi)) ell (theta of the higher
/// vertex, as the avalanche uses it), m. skipBorderPairs: leave out pairs with a border vertex.
Real worstReposeExcess(const Terrain& t, bool skipBorderPairs = false) {
  const HeightField& hf = *t.getHeightField();
  const size_t nx = hf.getResolutionX(), ny = hf.getResolutionY();
  const Real dx = hf.getCellSizeX(), dy = hf.getCellSizeY();
  Real worst = -1e300;
  for (size_t y = 0; y < ny; ++y)
    for (size_t x = 0; x < nx; ++x)
      for (int oy = -1; oy <= 1; ++oy)
        for (int ox = -1; ox <= 1; ++ox) {
          if (ox == 0 && oy == 0) continue;
          const long long xn = (long long)x + ox, yn = (long long)y + oy;
          if (xn < 0 || yn < 0 || xn >= (long long)nx || yn >= (long long)ny) continue;
          if (skipBorderPairs && (t.isBorderVertex(x, y) || t.isBorderVertex(size_t(xn), size_t(yn)))) continue;
          const Real ha = hf.getHeight(x, y), hb = hf.getHeight(size_t(xn), size_t(yn));
          if (ha < hb) continue;  // each pair from its higher end
          const Real ell = std::hypot(ox * dx, oy * dy);
          worst = std::max(worst, (ha - hb) - std::tan(t.computeAngleOfRepose(x, y)) * ell);
        }
  return worst;
}

std::vector<Real> heights(const Terrain& t) { return t.getHeightField()->getHeights(); }

/// A flat n x n terrain (cell 0.1 m, 0.5 m of soil) with the dynamic height field on, extent 0, decay 0.5.
TerrainRef addAvalancheTerrain(TestWorld& w, size_t n) {
  TerrainRef t = addFlatTerrain(w, n, 0.1 * Real(n - 1), 0.5);
  t->setEnableDynamicHeightField(true);
  t->setAvalancheVertexDistanceExtent(0);
  t->setAvalancheDecayPercent(0.5);
  return t;
}

/// A kinematic bucket as in test_model_terrain_dig.cpp: a bottom plate (the shovel; forward +x to its front
/// edge, up +z) and a back plate.
RigidBodyRef addBucket(TestWorld& w, const Vec3& at) {
  auto body = std::make_shared<RigidBody>("bucket");
  auto blade = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.2, 0.15, 0.01)), "blade");
  blade->setMaterial(w.material);
  blade->getPropertyContainer().addPropertyVec3(Terrain::ShovelUpProperty, Vec3(0, 0, 0.02));
  blade->getPropertyContainer().addPropertyVec3(Terrain::ShovelForwardProperty, Vec3(0.2, 0, 0));
  body->add(blade);
  auto back = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.01, 0.15, 0.1)), "back");
  back->setMaterial(w.material);
  back->setLocalPosition(Vec3(-0.21, 0, 0.09));
  body->add(back);
  body->setMotionControl(RigidBody::KINEMATICS);
  body->setPosition(at);
  w.sim->add(body);
  return body;
}

}  // namespace

TEST_SUITE("terrain avalanche") {
  TEST_CASE("avalancheAll: a tall column becomes a heap whose flanks stand at atan(mu); volume exact") {
    TestWorld w;  // the world's material: friction 0.5, no angle of repose set
    const size_t n = 65, c = 32;
    TerrainRef t = addFlatTerrain(w, n, 6.4, 0.5);  // s = 0.1 m
    // theta = atan(mu) exactly when the material's angle is 0 (here the terrain's default material, unmapped).
    const Real mu = w.material->getFrictionCoefficient();
    CHECK(t->computeAngleOfRepose(10, 20) == std::atan(mu));
    t->getDataInterface().add(w.material, 0);  // registered with angle 0: the same
    CHECK(t->computeAngleOfRepose(10, 20) == std::atan(mu));
    const Real T = mu, s = 0.1;
    t->getHeightField()->setHeight(c, c, 400.5);  // 4 m^3 of soil on one vertex
    const Real v0 = t->computeHeightFieldVolume();
    const TerrainAvalancheStats st = t->avalancheAll();
    MESSAGE("column: " << st.passes << " passes, " << st.moves << " moves, converged " << st.converged);
    CHECK(st.converged);
    // Every neighbour difference within tan(theta) ell (ell = s, s sqrt2) [1e-9 m].
    const Real worstExcess = worstReposeExcess(*t);
    MESSAGE("worst neighbour difference over the repose difference: " << worstExcess << " m; volume error "
                                                                      << (t->computeHeightFieldVolume() - v0) / v0);
    CHECK(worstExcess <= 1e-9);
    // Volume conserved [1e-12 relative], and the ledger's incremental account follows the grid.
    CHECK(std::abs(t->computeHeightFieldVolume() - v0) <= 1e-12 * v0);
    CHECK(std::abs(t->getVolumeLedger().heightField - v0) <= 1e-12 * v0);
    // The heap's slope along the 8 rays from the apex: a least-squares line through the flank. Left out: the
    // partly filled toe (below 10 % of the heap's height) and the apex cap (above 60 %): the relaxation stops
    // when every pair is within repose, not at it, and the column's last splits among its 8 neighbours leave a
    // cap a few cells wide whose diagonals stand 3-12 % flatter (the MESSAGE gives the 10-90 % fit too).
    const HeightField& hf = *t->getHeightField();
    const Real peak = hf.getHeight(c, c) - 0.5;
    CHECK(peak > 0.5);  // a real heap (about 0.9 m)
    const int dirs[8][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, -1}, {1, -1}, {-1, 1}};
    auto worstSlopeBetween = [&](Real lo, Real hi) {
      Real worst = 0;
      for (const auto& d : dirs) {
        Real sr = 0, sh = 0, srr = 0, srh = 0;
        int m = 0;
        for (int k = 0; k < 32; ++k) {
          const Real h = hf.getHeight(size_t(int(c) + k * d[0]), size_t(int(c) + k * d[1])) - 0.5;
          if (!(h > lo * peak && h < hi * peak)) continue;
          const Real r = k * s * std::hypot(Real(d[0]), Real(d[1]));
          sr += r, sh += h, srr += r * r, srh += r * h, ++m;
        }
        REQUIRE(m >= 6);
        const Real slope = -(m * srh - sr * sh) / (m * srr - sr * sr);
        worst = std::max(worst, std::abs(slope / T - 1));
      }
      return worst;
    };
    const Real worstSlope = worstSlopeBetween(0.1, 0.6);
    MESSAGE("heap height " << peak << " m; flank slopes (10-60 % of the height) within " << worstSlope
                           << " (relative) of tan(theta); 10-90 %: " << worstSlopeBetween(0.1, 0.9));
    CHECK(worstSlope <= 0.01);
    // The heap's angle is the angle of repose [1 %].
    CHECK(std::abs(std::atan(T * (1 - worstSlope)) / std::atan(T) - 1) <= 0.01);
  }

  TEST_CASE("avalancheAll: a random rough field with a set angle; edges and corners conserve volume, not height") {
    TestWorld w;
    const size_t n = 33;
    TerrainRef t = addFlatTerrain(w, n, 3.2, 0.5);
    const Real theta = 0.6;  // rad, set: friction is not used
    t->getDataInterface().add(w.material, 0, 0.0, 0.0, theta);
    CHECK(t->computeAngleOfRepose(0, 0) == theta);
    std::mt19937 rng(17);
    std::uniform_real_distribution<Real> u(0.0, 1.0);
    std::vector<Real> h(n * n);
    for (Real& v : h) v = 0.5 + u(rng);  // neighbours up to 1 m apart: 14 x tan(theta) s
    t->getHeightField()->setHeights(h);
    const Real v0 = t->computeHeightFieldVolume();
    const Real total0 = t->getVolumeLedger().total();
    const TerrainAvalancheStats st = t->avalancheAll();
    MESSAGE("rough field: " << st.passes << " passes, " << st.moves << " moves");
    CHECK(st.converged);
    CHECK(worstReposeExcess(*t) <= 1e-9);
    CHECK(std::abs(t->computeHeightFieldVolume() - v0) <= 1e-12 * v0);
    CHECK(std::abs(t->getVolumeLedger().total() - total0) <= 1e-12 * total0);
    // The plain height sum is not conserved (edge and corner vertices hold 1/2 and 1/4 of the area): the
    // check above is about volume.
    Real sum0 = 0, sum1 = 0;
    for (Real v : h) sum0 += v;
    for (Real v : heights(*t)) sum1 += v;
    CHECK(std::abs(sum1 - sum0) > 1e-6 * sum0);
    // A second call finds nothing to do.
    const TerrainAvalancheStats again = t->avalancheAll();
    CHECK(again.moves == 0);
    CHECK(again.passes == 1);
  }

  TEST_CASE("decay 0.5 brings a single two-vertex step to the repose difference in one step, also at an edge") {
    TestWorld w;
    TerrainRef t = addAvalancheTerrain(w, 11);
    const Real T = 0.5, s = 0.1;  // mu = 0.5
    HeightField& hf = *t->getHeightField();
    // The step is small enough (excess 2 x the repose difference) that A, having received, stays within repose
    // of its other neighbours: the pass makes exactly one move.
    SUBCASE("inside: equal areas, each vertex moves half the excess") {
      hf.setHeight(5, 5, 0.65);  // B, 0.15 m = 3 tan(theta) s above its neighbours
      const std::vector<Real> h0 = heights(*t);
      const Real v0 = t->getVolumeLedger().total();
      CHECK(t->armAvalanche(4, 5) == 1);  // A only: B is its one neighbour out of repose
      w.sim->stepForward();
      CHECK(std::abs((hf.getHeight(5, 5) - hf.getHeight(4, 5)) - T * s) <= 1e-12);
      CHECK(std::abs((h0[5 * 11 + 5] - hf.getHeight(5, 5)) - (hf.getHeight(4, 5) - h0[5 * 11 + 4])) <= 1e-12);
      CHECK(std::abs(t->getVolumeLedger().total() - v0) <= 1e-12 * v0);
      size_t changed = 0;
      for (size_t v = 0; v < h0.size(); ++v) changed += hf.getHeights()[v] != h0[v];
      CHECK(changed == 2);
      CHECK(t->getLastStepAvalancheStats().moves == 1);
    }
    SUBCASE("at an edge: the edge vertex has half the area and rises twice as far; the volume is exact") {
      hf.setHeight(1, 5, 0.6);  // B inside, A = (0, 5) on the edge
      const std::vector<Real> h0 = heights(*t);
      const Real v0 = t->computeHeightFieldVolume();
      t->armAvalanche(0, 5);
      w.sim->stepForward();
      CHECK(std::abs((hf.getHeight(1, 5) - hf.getHeight(0, 5)) - T * s) <= 1e-12);
      const Real dA = hf.getHeight(0, 5) - h0[5 * 11 + 0], dB = h0[5 * 11 + 1] - hf.getHeight(1, 5);
      CHECK(std::abs(dA - 2 * dB) <= 1e-12);
      CHECK(std::abs(t->getVertexArea(0, 5) * dA - t->getVertexArea(1, 5) * dB) <= 1e-12 * v0);
      CHECK(std::abs(t->computeHeightFieldVolume() - v0) <= 1e-12 * v0);
    }
  }

  TEST_CASE("decay 0 changes nothing; a slope made by setHeight without a trigger does not move") {
    TestWorld w;
    TerrainRef t = addAvalancheTerrain(w, 11);
    HeightField& hf = *t->getHeightField();
    for (size_t x = 0; x < 11; ++x) hf.setHeight(x, 5, 0.5 + 0.3 * Real(x));  // 3 m/m: 6 x tan(theta)
    hf.setHeight(5, 8, 2.0);
    const std::vector<Real> h0 = heights(*t);
    SUBCASE("nothing armed: nothing moves") {
      for (int i = 0; i < 30; ++i) w.sim->stepForward();
      CHECK(heights(*t) == h0);
      CHECK(t->getNumArmedVertices() == 0);
    }
    SUBCASE("armed everywhere with decay 0: nothing moves, the life still runs out") {
      t->setAvalancheDecayPercent(0);
      t->setAvalancheStepLifeTime(5);
      t->setAvalancheVertexDistanceExtent(10);
      CHECK(t->armAvalanche(5, 5) == 121);
      for (int i = 0; i < 10; ++i) w.sim->stepForward();
      CHECK(heights(*t) == h0);
      CHECK(t->getNumArmedVertices() == 0);
    }
    SUBCASE("the same arming with decay 0.1 does move it (the set-up can fail)") {
      t->setAvalancheDecayPercent(0.1);
      t->setAvalancheVertexDistanceExtent(10);
      t->armAvalanche(5, 5);
      w.sim->stepForward();
      CHECK(heights(*t) != h0);
    }
  }

  TEST_CASE("an arming lasts exactly the life time; the extent arms exactly the square within it") {
    TestWorld w;
    TerrainRef t = addAvalancheTerrain(w, 11);
    HeightField& hf = *t->getHeightField();
    SUBCASE("life time") {
      t->setAvalancheDecayPercent(0.1);  // slow: far from repose after 3 steps
      t->setAvalancheStepLifeTime(3);
      hf.setHeight(5, 5, 3.0);
      t->armAvalanche(4, 5);
      CHECK(t->getAvalancheStepsLeft(4, 5) == 3);
      std::vector<std::vector<Real>> after;
      after.push_back(heights(*t));
      for (int i = 0; i < 6; ++i) {
        w.sim->stepForward();
        after.push_back(heights(*t));
      }
      CHECK(after[1] != after[0]);
      CHECK(after[2] != after[1]);
      CHECK(after[3] != after[2]);  // still moving in the last step of its life ...
      CHECK(after[4] == after[3]);  // ... and not after it
      CHECK(after[6] == after[3]);
      CHECK(t->getNumArmedVertices() == 0);
      CHECK(worstReposeExcess(*t) > 0.1);  // far from repose: the life, not the slope, stopped it
    }
    SUBCASE("extent") {
      t->setAvalancheVertexDistanceExtent(2);
      t->setAvalancheStepLifeTime(7);
      CHECK(t->armAvalanche(5, 5) == 25);
      for (size_t y = 0; y < 11; ++y)
        for (size_t x = 0; x < 11; ++x) {
          const bool inside = x >= 3 && x <= 7 && y >= 3 && y <= 7;
          CHECK(t->getAvalancheStepsLeft(x, y) == (inside ? 7 : 0));
        }
      CHECK(t->getNumArmedVertices() == 25);
      // Clipped at a corner: x in 0..3, y in 0..2.
      t->setEnableDynamicHeightField(false);  // disarms everything
      CHECK(t->getNumArmedVertices() == 0);
      CHECK(t->armAvalanche(1, 0) == 0);  // off: arms nothing
      t->setEnableDynamicHeightField(true);
      CHECK(t->armAvalanche(1, 0) == 12);
      CHECK(t->getNumArmedVertices() == 12);
      CHECK(t->getAvalancheStepsLeft(3, 2) == 7);
      CHECK(t->getAvalancheStepsLeft(4, 2) == 0);
      CHECK(t->getAvalancheStepsLeft(3, 3) == 0);
    }
  }

  TEST_CASE("wetness: the angle of repose rises linearly with c / c_max, scaled by the wetness") {
    TestWorld w;
    TerrainRef t = addAvalancheTerrain(w, 11);
    TerrainDataInterface& di = t->getDataInterface();
    const Real theta0 = 0.5, d = 1.0;
    di.add(w.material, 0, 0.0, d, theta0);
    const Real cMax = di.getMaxCompression(0, 0);  // log2(16) / 2 = 2
    CHECK(cMax == 2.0);
    const Real cs[3] = {0.0, 0.7, 2.0};
    auto line = [&](Real wet, Real c) { return theta0 + wet * (c / cMax) * (kPi / 2 - theta0) / 2; };
    SUBCASE("wet") {
      const Real wet = 0.6;
      t->setWetnessScale(wet);
      for (Real c : cs) {
        di.setCompression(3, 3, c);
        CHECK(std::abs(t->computeAngleOfRepose(3, 3) - line(wet, c)) <= 1e-9);
      }
      // Beyond c_max (setCompression allows it) the angle stays at the line's end.
      di.setCompression(3, 3, 3.0);
      CHECK(std::abs(t->computeAngleOfRepose(3, 3) - line(wet, cMax)) <= 1e-9);
      // The avalanche uses it: a compressed step (c = 1 at the higher vertex) stops at tan(theta(1)) s.
      di.setCompression(3, 3, 0);
      di.setCompression(5, 5, 1.0);
      t->getHeightField()->setHeight(5, 5, 0.5 + std::tan(line(wet, 1.0)) * 0.1 + 0.1);  // excess 0.1 m
      t->armAvalanche(4, 5);
      w.sim->stepForward();
      const HeightField& hf = *t->getHeightField();
      CHECK(std::abs((hf.getHeight(5, 5) - hf.getHeight(4, 5)) - std::tan(line(wet, 1.0)) * 0.1) <= 1e-12);
      CHECK(di.getCompression(5, 5) == 1.0);  // the giver keeps its c; the receiver was loose already
    }
    SUBCASE("dry: the same angle at every compression") {
      for (Real c : cs) {
        di.setCompression(3, 3, c);
        CHECK(t->computeAngleOfRepose(3, 3) == theta0);
      }
    }
  }

  TEST_CASE("moved soil arrives loose: the receiver's compression falls by the compression rule") {
    TestWorld w;
    TerrainRef t = addAvalancheTerrain(w, 11);
    TerrainDataInterface& di = t->getDataInterface();
    di.add(w.material, 0, 0.0, 1.0);
    di.setCompression(4, 5, 1.5);
    t->getHeightField()->setHeight(5, 5, 1.5);
    const Real h0 = t->getHeightField()->getHeight(4, 5);
    t->armAvalanche(4, 5);
    w.sim->stepForward();
    const Real dz = t->getHeightField()->getHeight(4, 5) - h0;
    CHECK(dz > 0);
    const Real M = di.getMaxCompressionMultiplier(), D = di.getDepthForMaxCompression();
    CHECK(std::abs(di.getCompression(4, 5) - std::max<Real>(0, 1.5 - dz * std::log2(M) / D)) <= 1e-12);
    CHECK(di.getYoungsModulusMultiplier(4, 5) == TerrainDataInterface::multiplier(di.getCompression(4, 5), 1.0, M));
  }

  TEST_CASE("locked borders: border heights bit-identical; with mass loss the soil over the border is booked") {
    TestWorld w;
    TerrainRef t = addAvalancheTerrain(w, 11);
    t->setAvalancheDecayPercent(0.25);
    t->setAvalancheVertexDistanceExtent(1);
    HeightField& hf = *t->getHeightField();
    hf.setHeight(1, 5, 1.5);  // a column next to the x = 0 border
    hf.setHeight(2, 5, 1.0);
    const std::vector<Real> h0 = heights(*t);
    const TerrainVolumeLedger l0 = t->getVolumeLedger();
    auto checkBorders = [&] {
      for (size_t y = 0; y < 11; ++y)
        for (size_t x = 0; x < 11; ++x)
          if (t->isBorderVertex(x, y) && hf.getHeight(x, y) != h0[y * 11 + x]) {
            FAIL_CHECK("border vertex (" << x << ", " << y << ") moved");
            return;
          }
    };
    SUBCASE("mass loss on") {
      t->setEnableLockedBorders(true, true);
      t->armAvalanche(1, 5);
      stepCheckingLedger(w, *t, 60);  // the ledger after every step [1e-9]
      checkBorders();
      const TerrainVolumeLedger& l = t->getVolumeLedger();
      MESSAGE("lost at the border: " << l.lostAtBorder << " m^3");
      CHECK(l.lostAtBorder > 1e-4);
      CHECK(std::abs(l.total() - l0.total()) <= 1e-12 * l0.total());
      CHECK(std::abs((l0.heightField - t->computeHeightFieldVolume()) - l.lostAtBorder) <= 1e-12 * l0.total());
      // avalancheAll finishes the job: everything within repose, border pairs included (the soil left).
      t->avalancheAll();
      checkBorders();
      CHECK(worstReposeExcess(*t) <= 1e-9);
      CHECK(std::abs(t->getVolumeLedger().total() - l0.total()) <= 1e-12 * l0.total());
    }
    SUBCASE("mass loss off: the border holds the soil back, nothing is lost") {
      t->setEnableLockedBorders(true, false);
      t->armAvalanche(1, 5);
      stepCheckingLedger(w, *t, 60);
      checkBorders();
      t->avalancheAll();
      checkBorders();
      CHECK(t->getVolumeLedger().lostAtBorder == 0);
      CHECK(std::abs(t->computeHeightFieldVolume() - l0.heightField) <= 1e-12 * l0.total());
      CHECK(worstReposeExcess(*t, /*skipBorderPairs*/ true) <= 1e-9);
      // Held back: the column's foot stands above the border by more than repose.
      CHECK(hf.getHeight(1, 5) - hf.getHeight(0, 5) > 0.5 * 0.1 + 1e-3);
    }
    SUBCASE("no locked borders: the border vertices take soil like any other") {
      t->armAvalanche(1, 5);
      stepCheckingLedger(w, *t, 60);
      CHECK(hf.getHeight(0, 5) > h0[5 * 11]);
      CHECK(t->getVolumeLedger().lostAtBorder == 0);
    }
  }
  TEST_CASE("merged particles arm avalanches around their vertices; the ledger holds every step") {
    TestWorld w(1.0 / 60);
    w.material->setRollingResistanceCoefficient(0.3);
    TerrainRef t = addFlatTerrain(w, 41, 2.0);  // s = 0.05 m
    t->getParticleAttributes().setParticleRadius(0.02);
    t->setEnableDynamicHeightField(true);
    t->setAvalancheVertexDistanceExtent(2);
    RigidBodyRef bucket = addBucket(w, Vec3(-0.5, 0, 0.03));
    const Real total0 = t->getVolumeLedger().total();
    Real worstLedger = 0, moved = 0;
    size_t merged = 0, mergeSteps = 0, armedAfterMerge = 0, minArmedAfterMerge = size_t(-1);
    auto run = [&](Real seconds, const Vec3& v, const Vec3& omega) {
      bucket->setVelocity(v);
      bucket->setAngularVelocity(omega);
      for (int i = 0; i < int(std::lround(seconds * 60)); ++i) {
        w.sim->stepForward();
        worstLedger = std::max(worstLedger, std::abs(t->getVolumeLedger().total() - total0) / total0);
        moved += t->getLastStepAvalancheStats().volumeMoved;
        if (t->getLastStepDigStats().particlesMerged > 0) {
          merged += t->getLastStepDigStats().particlesMerged;
          ++mergeSteps;
          armedAfterMerge += t->getNumArmedVertices() > 0;
          minArmedAfterMerge = std::min(minArmedAfterMerge, t->getNumArmedVertices());
        }
      }
    };
    run(0.5, Vec3(0, 0, -0.1), Vec3::Zero());   // tip 2 cm into the soil
    run(0.5, Vec3(0.4, 0, 0), Vec3::Zero());    // a short trench: particles on the blade
    run(0.3, Vec3(0, 0, 0.4), Vec3::Zero());    // lift
    run(0.2, Vec3(0, 5.0, 0), Vec3::Zero());    // pulled out sideways from under them (no side walls)
    run(2.0, Vec3::Zero(), Vec3::Zero());       // they land and merge
    MESSAGE(merged << " particles merged in " << mergeSteps << " steps; avalanches moved " << moved
                   << " m^3; ledger drift " << worstLedger);
    REQUIRE(merged > 0);
    CHECK(armedAfterMerge == mergeSteps);  // every merge armed (life time 100 steps: still armed after it)
    CHECK(minArmedAfterMerge >= 25);       // at least one vertex's 5 x 5 extent
    CHECK(moved > 0);  // the merged bumps stood steeper than atan(0.5) and slid (3.7e-5 m^3 measured)
    CHECK(worstLedger <= 1e-9);
  }
}
