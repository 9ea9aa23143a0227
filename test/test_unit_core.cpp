// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Core utilities: logger levels and sink, property container, assert handler, material combination rules.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include <scree/scree.h>

#include "test_build.h"

using namespace scree;

TEST_SUITE("core") {
  TEST_CASE("the logger filters by level and routes to a replaceable sink") {
    std::vector<std::pair<LogLevel, std::string>> got;
    Logger::setSink([&](LogLevel l, const std::string& m) { got.push_back({l, m}); });
    Logger::setLevel(LogLevel::WARNING);
    Logger::info("hidden");
    Logger::warning("shown");
    Logger::setLevel(LogLevel::DEBUG);
    Logger::debug("now shown");
    Logger::setLevel(LogLevel::WARNING);
    Logger::warningOnce("core-test-once", "once");
    Logger::warningOnce("core-test-once", "once");
    const size_t beforeReset = got.size();
    Logger::resetWarningsOnce();  // the key is forgotten: logged once more, then silent again
    Logger::warningOnce("core-test-once", "once again");
    Logger::warningOnce("core-test-once", "once again");
    Logger::setSink(nullptr);
    CHECK(beforeReset == 3);
    REQUIRE(got.size() == 4);
    CHECK(got[0].second == "shown");
    CHECK(got[1].first == LogLevel::DEBUG);
    CHECK(got[2].second == "once");
    CHECK(got[3].second == "once again");
  }

  TEST_CASE("property container stores typed values by name and rejects wrong types") {
    PropertyContainer p;
    p.addPropertyVec3("ShovelUpProperty", Vec3(0, 0, 1));
    p.addPropertyReal("r", 2.5);
    p.addPropertyBool("b", true);
    p.addPropertyString("s", "x");
    p.addPropertyInt("i", 7);
    CHECK(p.hasPropertyVec3("ShovelUpProperty"));
    CHECK(p.getPropertyVec3("ShovelUpProperty") == Vec3(0, 0, 1));
    CHECK(p.getPropertyReal("r") == 2.5);
    CHECK(p.getPropertyInt("i") == 7);
    CHECK_THROWS_AS(p.getPropertyReal("b"), std::invalid_argument);
    CHECK_THROWS_AS(p.getPropertyBool("missing"), std::invalid_argument);
    CHECK(p.removeProperty("r"));
    CHECK_FALSE(p.hasProperty("r"));
  }

  TEST_CASE("the assert handler receives failed checks") {
    int calls = 0;
    auto old = setAssertHandler([&](const char* e, const char*, int) {
      ++calls;
      CHECK(std::string(e) == "x > 0");
    });
    detail::assertFailed("x > 0", __FILE__, __LINE__);
    setAssertHandler(old);
    CHECK(calls == 1);
    CHECK(std::string(getConfigurationString()).find("Scree") == 0);
  }

  TEST_CASE("the configuration string and the compile definition agree on the direct solver") {
    // Tests pick DIRECT cases by the compile definition (test_build.h); the runtime string must say the same.
    const std::string config = getConfigurationString();
    CHECK(config.find(test::kHasDirectSolver ? "SuiteSparse on" : "SuiteSparse off") != std::string::npos);
  }

  TEST_CASE("materials combine as springs in series, geometric means and sums") {
    auto a = std::make_shared<Material>("a"), b = std::make_shared<Material>("b");
    a->setYoungsModulus(1e8);
    b->setYoungsModulus(3e8);
    a->setFrictionCoefficient(0.4);
    b->setFrictionCoefficient(0.9);
    a->setRestitution(0.25);
    b->setRestitution(1.0);
    a->setSurfaceViscosity(1e-9);
    b->setSurfaceViscosity(2e-9);
    a->setAdhesion(3, 0.001);
    b->setAdhesion(4, 0.002);
    MaterialManager mm;
    SurfaceParameters p;
    const FrictionModel* fm = nullptr;
    mm.resolve(a.get(), b.get(), p, &fm);
    CHECK(p.getYoungsModulus() == doctest::Approx(1e8 * 3e8 / 4e8));
    CHECK(p.getFrictionCoefficient() == doctest::Approx(std::sqrt(0.36)));
    CHECK(p.getRestitution() == doctest::Approx(0.5));
    CHECK(p.getSurfaceViscosity() == doctest::Approx(3e-9));
    CHECK(p.getAdhesiveForce() == doctest::Approx(7));
    CHECK(p.getAdhesiveOverlap() == doctest::Approx(0.003));
    REQUIRE(fm != nullptr);
    CHECK(fm->getType() == FrictionModel::ITERATIVE_PROJECTED_CONE);
    // An explicit contact material overrides the combination, in either order.
    auto cm = mm.getOrCreateContactMaterial(b, a);
    cm->setFrictionCoefficient(0.1);
    mm.resolve(a.get(), b.get(), p, &fm);
    CHECK(p.getFrictionCoefficient() == doctest::Approx(0.1));
    // Defaults of docs/design.md section 3.
    Material d("d");
    CHECK(d.getDensity() == 1000);
    CHECK(d.getYoungsModulus() == 4e8);
    CHECK(d.getRestitution() == 0.5);
    CHECK(d.getDamping() == 0.075);
    CHECK(d.getFrictionCoefficient() == 0.41667);
    CHECK(d.getSurfaceViscosity() == 5e-9);
    CHECK(d.getAdhesiveForce() == 0);
  }
}
