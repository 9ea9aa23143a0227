// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Terrain: construction checks, d = 0 equals a plain height field bit for bit, the compression multiplier law
// (formula, per-step bound, depth for max compression), locked borders, a rolling wheel's ruts, and the volume
// ledger after every step of every scene.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "terrain_world.h"

using namespace scree;
using namespace scree::test;

namespace {

/// Every vertex's stored multiplier equals the law at its stored compression (capped), 1e-12 relative.
Real worstMultiplierError(const Terrain& t) {
  const TerrainDataInterface& di = t.getDataInterface();
  Real worst = 0;
  for (size_t y = 0; y < di.getResolutionY(); ++y)
    for (size_t x = 0; x < di.getResolutionX(); ++x) {
      const Real expect = TerrainDataInterface::multiplier(di.getCompression(x, y), di.getDeformability(x, y),
                                                           di.getMaxCompressionMultiplier());
      worst = std::max(worst, std::abs(di.getYoungsModulusMultiplier(x, y) - expect) / expect);
    }
  return worst;
}

std::vector<Real> multipliers(const Terrain& t) {
  const TerrainDataInterface& di = t.getDataInterface();
  std::vector<Real> m;
  for (size_t y = 0; y < di.getResolutionY(); ++y)
    for (size_t x = 0; x < di.getResolutionX(); ++x) m.push_back(di.getYoungsModulusMultiplier(x, y));
  return m;
}

}  // namespace

TEST_SUITE("terrain") {
  TEST_CASE("construction checks: a height-field geometry, identity transform on a body, +z against gravity") {
    auto hf = std::make_shared<HeightField>(5, 5, 4.0, 4.0);
    CHECK_THROWS_WITH_AS(Terrain{GeometryRef()}, doctest::Contains("terrainGeometry = null"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(Terrain{std::make_shared<Geometry>(std::make_shared<Box>(Vec3(1, 1, 1)))},
                         doctest::Contains("must be a HeightField"), std::invalid_argument);
    {
      auto body = std::make_shared<RigidBody>();
      auto g = std::make_shared<Geometry>(hf);
      body->add(g);
      g->setLocalPosition(Vec3(0, 0, 0.1));
      CHECK_THROWS_WITH_AS(Terrain{g}, doctest::Contains("local transform must be the identity"),
                           std::invalid_argument);
      g->setLocalPosition(Vec3::Zero());
      CHECK_NOTHROW(Terrain{g});
    }
    // Upside down: rejected when added; the simulation is unchanged.
    TestWorld w;
    auto t = std::make_shared<Terrain>(hf);
    t->getGeometry()->setRotation(Quat(Eigen::AngleAxis<Real>(M_PI, Vec3::UnitX())));
    const size_t listeners = w.sim->getContactEventListeners().size() + w.sim->getStepEventListeners().size();
    const size_t statics = w.sim->getStaticGeometries().size();
    CHECK_THROWS_WITH_AS(w.sim->add(t), doctest::Contains("must point against gravity"), std::invalid_argument);
    CHECK(w.sim->getModels().empty());
    CHECK(w.sim->getStaticGeometries().size() == statics);
    CHECK(w.sim->getContactEventListeners().size() + w.sim->getStepEventListeners().size() == listeners);
    CHECK(t->getSimulation() == nullptr);
    // Placed right, it goes in with its geometry and two listeners, and out again.
    t->getGeometry()->setRotation(Quat::Identity());
    w.sim->add(t);
    CHECK(w.sim->getStaticGeometries().size() == statics + 1);
    CHECK(t->getNumOwned() == 3);
    CHECK(t->getGeometry()->getShape() == t->getHeightField());
    CHECK(t->getVolumeLedger().total() == 0);
    w.sim->remove(t);
    CHECK(w.sim->getStaticGeometries().size() == statics);
  }

  TEST_CASE("d = 0: a terrain is bit-identical to a plain height field and a ball rests m g / E deep") {
    // Two worlds built in the same order, one with a plain HeightField geometry, one with a Terrain whose
    // material (registered, d = 0) is non-deformable: every pose and every height must match bit for bit.
    auto build = [](TestWorld& w, bool terrain) -> TerrainRef {
      w.contactMaterial->setYoungsModulus(1e5);
      TerrainRef t;
      if (terrain) {
        t = addFlatTerrain(w, 41, 8.0);
        t->getDataInterface().add(w.material, 0, 0.0, 0.0);
      } else {
        auto hf = std::make_shared<HeightField>(41, 41, 8.0, 8.0);
        hf->setHeights(std::vector<Real>(41 * 41, 0.5));
        auto g = std::make_shared<Geometry>(hf);
        g->setMaterial(w.material);
        g->setPosition(Vec3(0, 0, -0.5));
        w.sim->add(g);
      }
      w.addBox(Vec3(0.3, 0.2, 0.1), Vec3(0.7, -0.3, 0.3), 20.0,
               Quat(Eigen::AngleAxis<Real>(0.3, Vec3(0.2, 1, 0.1).normalized())));
      w.addSphere(0.1, Vec3(-1.0, 0.5, 0.1), 1.0);
      return t;
    };
    TestWorld a, b;
    build(a, false);
    TerrainRef t = build(b, true);
    const std::vector<Real> h0 = t->getHeightField()->getHeights();
    const Real drift = stepCheckingLedger(b, *t, 180);
    a.steps(180);
    for (size_t k = 0; k < a.sim->getRigidBodies().size(); ++k) {
      const RigidBody& ra = *a.sim->getRigidBodies()[k];
      const RigidBody& rb = *b.sim->getRigidBodies()[k];
      CHECK(ra.getPosition() == rb.getPosition());
      CHECK(ra.getRotation().coeffs() == rb.getRotation().coeffs());
      CHECK(ra.getVelocity() == rb.getVelocity());
    }
    CHECK(t->getHeightField()->getHeights() == h0);
    CHECK(t->getVolumeLedger().compressed == 0);
    CHECK(drift == 0);
    // The ball: one contact point with E = 1e5 N/m at rest is m g / E deep (SPOOK at rest), as on a HeightField
    // (test_analytic_heightfield: 2 % for the damped settling).
    const Real depth = 0.1 - b.sim->getRigidBodies()[1]->getPosition().z();
    MESSAGE("ball depth " << depth << " m, m g / E = " << 9.81 / 1e5);
    CHECK(std::abs(depth - 9.81 / 1e5) / (9.81 / 1e5) < 0.02);
  }

  TEST_CASE("the multiplier is the law at the stored compression, grows at most maxChange a step, and lowering "
            "by D or D/(d+1) reaches M") {
    TestWorld w;
    w.contactMaterial->setYoungsModulus(1e5);  // soil-like: centimetres of yield per second (terrain.h)
    TerrainRef t = addFlatTerrain(w, 21, 4.0);
    TerrainDataInterface& di = t->getDataInterface();
    auto soft = std::make_shared<Material>("soft");
    auto hard = std::make_shared<Material>("hard");
    // Mapped materials other than the geometry's give their own contact parameters (box material, vertex
    // material): soil-like stiffness for both (in series with the box's 4e8: ~2e5 N/m).
    soft->setYoungsModulus(2e5);
    hard->setYoungsModulus(2e5);
    di.add(soft, 0, 0.0, 1.0);
    di.add(hard, 1, 0.0, 3.0);
    for (size_t x = 0; x < 21; ++x)
      for (size_t y = 11; y < 21; ++y) di.setMaterialMapping(x, y, 1);
    di.setMaxYoungsChangePerTimestep(0.02);
    // A heavy box pressing over both materials and rocking: many vertices yield at their per-step bound.
    w.addBox(Vec3(0.5, 0.5, 0.2), Vec3(0.05, 0.1, 0.2), 400.0);
    const Real total0 = t->getVolumeLedger().total();
    Real worstGrowth = 0;
    int stepsWithYield = 0;
    for (int s = 0; s < 120; ++s) {
      const std::vector<Real> before = multipliers(*t);
      w.sim->stepForward();
      const std::vector<Real> after = multipliers(*t);
      for (size_t k = 0; k < after.size(); ++k) worstGrowth = std::max(worstGrowth, after[k] - before[k]);
      stepsWithYield += t->getNumYieldedVertices() > 0;
      CHECK(std::abs(t->getVolumeLedger().total() - total0) <= 1e-9 * total0);
    }
    MESSAGE("largest multiplier growth in a step " << worstGrowth << " (bound 0.02); " << stepsWithYield
                                                   << " steps yielded");
    CHECK(stepsWithYield > 0);
    CHECK(worstGrowth <= 0.02);
    CHECK(worstGrowth > 0.01);  // the bound was reached
    CHECK(worstMultiplierError(*t) <= 1e-12);
    CHECK(t->getVolumeLedger().compressed > 0);

    // Lowering by D gives M for every d; by D/(d+1) too (c reaches c_max exactly there).
    const Real D = di.getDepthForMaxCompression(), M = di.getMaxCompressionMultiplier();
    const Real totalBefore = t->getVolumeLedger().total();
    CHECK(t->pressVertex(2, 2, D));       // d = 1
    CHECK(t->pressVertex(2, 18, D));      // d = 3
    CHECK(t->pressVertex(4, 2, D / 2));   // d = 1: D/(d+1)
    CHECK(t->pressVertex(4, 18, D / 4));  // d = 3: D/(d+1)
    CHECK(t->pressVertex(6, 2, D / 4));   // half way in the exponent: sqrt(M)
    for (auto [x, y] : {std::pair<size_t, size_t>{2, 2}, {2, 18}, {4, 2}, {4, 18}})
      CHECK(std::abs(di.getYoungsModulusMultiplier(x, y) - M) <= 1e-12 * M);
    CHECK(std::abs(di.getYoungsModulusMultiplier(6, 2) - std::sqrt(M)) <= 1e-12 * M);
    CHECK(std::abs(di.getCompression(4, 2) - di.getMaxCompression(4, 2)) <= 1e-12);
    CHECK(std::abs(t->getVolumeLedger().total() - totalBefore) <= 1e-9 * totalBefore);
    CHECK(worstMultiplierError(*t) <= 1e-12);
    // Changing M or d re-caps; still the law everywhere.
    di.setMaxCompressionMultiplier(4);
    CHECK(worstMultiplierError(*t) <= 1e-12);
    CHECK(di.getYoungsModulusMultiplier(2, 2) == 4);
    di.add(soft, 0, 0.0, 0.0);
    CHECK(di.getYoungsModulusMultiplier(2, 2) == 1);
    CHECK(worstMultiplierError(*t) <= 1e-12);
  }

  TEST_CASE("maxChange 0 freezes the ground; d = 0 and M = 1 never yield") {
    for (int mode = 0; mode < 3; ++mode) {
      TestWorld w;
      TerrainRef t = addFlatTerrain(w, 21, 4.0);
      TerrainDataInterface& di = t->getDataInterface();
      di.add(w.material, 0, 0.0, mode == 1 ? 0.0 : 2.0);
      if (mode == 0) di.setMaxYoungsChangePerTimestep(0);
      if (mode == 2) di.setMaxCompressionMultiplier(1);
      const std::vector<Real> h0 = t->getHeightField()->getHeights();
      w.addBox(Vec3(0.5, 0.5, 0.2), Vec3(0, 0, 0.2), 2000.0);
      CHECK(stepCheckingLedger(w, *t, 60) == 0);
      CHECK(t->getHeightField()->getHeights() == h0);
      CHECK(t->getNumLoadedVertices() > 0);
      CHECK(t->getNumYieldedVertices() == 0);
    }
  }

  TEST_CASE("locked borders keep every border height bit-identical while the inside sinks") {
    TestWorld w;
    TerrainRef t = addFlatTerrain(w, 11, 1.0);
    t->getDataInterface().add(w.material, 0, 0.0, 1.0);
    t->setEnableLockedBorders(true);
    CHECK(t->getEnableLockedBorders());
    const std::vector<Real> h0 = t->getHeightField()->getHeights();
    // A plate over every vertex, borders included, pressing at 4 p0.
    auto plate = addSpherePlate(w, *t, 0, 10, 0, 10, 0.02, 1.0);
    const Real p0 = t->getDataInterface().getYieldPressure();
    const Real force = 4 * p0 * 0.1 * 0.1 * 121;
    w.sim->add(std::make_shared<LambdaStepListener>([&](const TimeStamp&) {
      plate->addForce(Vec3(0, 0, -force));
    }));
    stepCheckingLedger(w, *t, 120);
    CHECK_FALSE(t->pressVertex(0, 5, 0.1));
    CHECK_FALSE(t->pressVertex(10, 10, 0.1));
    const HeightField& hf = *t->getHeightField();
    size_t sunk = 0;
    for (size_t y = 0; y < 11; ++y)
      for (size_t x = 0; x < 11; ++x) {
        if (t->isBorderVertex(x, y)) CHECK(hf.getHeight(x, y) == h0[y * 11 + x]);
        else sunk += hf.getHeight(x, y) < h0[y * 11 + x];
      }
    CHECK(sunk > 0);
    MESSAGE(sunk << " of 81 inner vertices sank; borders untouched");
  }

  TEST_CASE("the ledger: trapezoid weights, incremental through compression, direct height edits booked once") {
    TestWorld w;
    TerrainRef t = addFlatTerrain(w, 5, 4.0, 1.0);  // 1 m cells, 4 x 4 m^2 of 1 m thick soil: 16 m^3
    CHECK(t->getVolumeLedger().heightField == 16.0);
    CHECK(t->getVertexArea(0, 0) == 0.25);
    CHECK(t->getVertexArea(0, 2) == 0.5);
    CHECK(t->getVertexArea(2, 2) == 1.0);
    t->getDataInterface().add(w.material, 0, 0.0, 1.0);
    CHECK(t->pressVertex(2, 2, 0.1));  // inner vertex: 0.1 m^3 from heightField to compressed
    CHECK(t->pressVertex(0, 0, 0.2));  // corner: 0.05 m^3
    const TerrainVolumeLedger& l = t->getVolumeLedger();
    CHECK(l.heightField == doctest::Approx(15.85).epsilon(1e-12));
    CHECK(l.compressed == doctest::Approx(0.15).epsilon(1e-12));
    CHECK(l.total() == doctest::Approx(16.0).epsilon(1e-12));
    // A direct HeightField edit is not soil the terrain moved: the account follows it, the total changes by it.
    t->getHeightField()->setHeight(4, 2, 1.5);  // edge vertex: +0.25 m^3
    CHECK(t->getVolumeLedger().heightField == doctest::Approx(16.1).epsilon(1e-12));
    CHECK(t->getVolumeLedger().total() == doctest::Approx(16.25).epsilon(1e-12));
    CHECK(t->getHeightField()->getDirtyRectangle().empty());
    // Nothing touches the terrain: no vertex loaded, no edit, ledger constant.
    stepCheckingLedger(w, *t, 10);
    CHECK(t->getNumLoadedVertices() == 0);
    CHECK(t->getVolumeLedger().heightField == t->computeHeightFieldVolume());
  }

  TEST_CASE("unequal spacing is accepted with a warning; a data-interface subclass can be installed") {
    std::vector<std::string> warnings;
    Logger::setSink([&](LogLevel level, const std::string& m) {
      if (level == LogLevel::WARNING) warnings.push_back(m);
    });
    auto t = std::make_shared<Terrain>(std::make_shared<HeightField>(5, 5, 4.0, 2.0));  // 1 m x 0.5 m cells
    Logger::setSink({});
    REQUIRE(warnings.size() == 1);
    CHECK(warnings[0].find("different x and y scale") != std::string::npos);
    CHECK(t->getVertexArea(2, 2) == 0.5);

    // A subclass that records what is registered (the manual lets users extend the data interface).
    struct Recording : TerrainDataInterface {
      using TerrainDataInterface::TerrainDataInterface;
      std::vector<size_t> added;
      void add(MaterialRef m, size_t index, Real adhesion, Real d, Real angle) override {
        TerrainDataInterface::add(std::move(m), index, adhesion, d, angle);
        added.push_back(index);
      }
    };
    auto rec = std::make_unique<Recording>(*t);
    Recording* r = rec.get();
    t->setDataInterface(std::move(rec));
    CHECK(&t->getDataInterface() == r);
    t->getDataInterface().add(std::make_shared<Material>("sand"), 3, 0.0, 1.0, 0.0);
    CHECK(r->added == std::vector<size_t>{3});
    auto other = std::make_shared<Terrain>(std::make_shared<HeightField>(5, 5, 4.0, 4.0));
    CHECK_THROWS_WITH_AS(t->setDataInterface(std::make_unique<TerrainDataInterface>(*other)),
                         doctest::Contains("built for another terrain"), std::invalid_argument);
    CHECK(t->getVolumeLedger().total() == 0);
  }
}
