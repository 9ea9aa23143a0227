// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The particle seams of the step: particle contacts reach ContactEventListener::particleContacts with
// per-point overrides (Young's modulus, disable, surface velocity) checked against closed forms; particles
// honour collision groups; particles may be destroyed from a POST_STEP listener while it reads this step's
// particle contacts.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <set>
#include <vector>

#include <scree/scree.h>

#include "test_world.h"

using namespace scree;

namespace {
Real sphereMass(Real rho, Real r) { return rho * 4.0 / 3.0 * std::numbers::pi * r * r * r; }

/// Calls `edit` on every particle-geometry contact of each step (mask ALL_WITH_PARTICLES).
struct ParticleContactEditor : ContactEventListener {
  std::function<void(ParticleContact&)> edit;
  int calls = 0;
  explicit ParticleContactEditor(std::function<void(ParticleContact&)> f, int mask = ALL_WITH_PARTICLES)
      : ContactEventListener(mask), edit(std::move(f)) {}
  void particleContacts(const TimeStamp&, std::vector<ParticleContact>&, std::vector<ParticleContact>& pg) override {
    ++calls;
    for (ParticleContact& c : pg) edit(c);
  }
};
}  // namespace

TEST_SUITE("particle seams") {
  TEST_CASE("a listener's Young's modulus sets a resting particle's overlap to m g / E_new") {
    const Real Ematerial = 1e5, Enew = 4e5, r = 0.05;
    for (bool withBit : {true, false}) {
      CAPTURE(withBit);
      test::TestWorld w(1.0 / 100.0, 9.81, 0.5, 0.0);
      w.addGround();
      w.contactMaterial->setYoungsModulus(Ematerial);
      auto& ps = w.sim->getGranularBodySystem();
      ps.setMaterial(w.material);
      const size_t id = ps.createParticle(Vec3(0, 0, r), r);
      // Without the PARTICLE_CONTACT bit (mask ALL) the listener is never called: the material's E holds.
      auto l = std::make_shared<ParticleContactEditor>(
          [&](ParticleContact& c) { c.youngsModulus = Enew; },
          withBit ? ContactEventListener::ALL_WITH_PARTICLES : ContactEventListener::ALL);
      w.sim->add(l);
      w.stepSeconds(3.0);
      CHECK(l->calls == (withBit ? 300 : 0));
      const Real m = sphereMass(1000, r);
      // SPOOK at rest: a spring of stiffness E per point, lambda / h = E * overlap = m g. 3 s are 40 damping
      // times (the contact's damping time is 0.075 s), so the transient is gone; 1 % covers the PGS residual.
      const Real E = withBit ? Enew : Ematerial;
      CHECK(r - ps.getPosition(id).z() == doctest::Approx(m * 9.81 / E).epsilon(0.01));
      REQUIRE(w.sim->getParticleGeometryContacts().size() == 1);
      CHECK(w.sim->getParticleGeometryContacts()[0].normalForce == doctest::Approx(m * 9.81).epsilon(0.01));
    }
  }

  TEST_CASE("a listener that disables the particle's contacts lets it fall freely") {
    const Real h = 0.01, g = 9.81, r = 0.05;
    test::TestWorld w(h, g, 0.5, 0.0);
    w.addGround();
    auto& ps = w.sim->getGranularBodySystem();
    ps.setMaterial(w.material);
    const size_t id = ps.createParticle(Vec3(0, 0, r), r);
    int disabled = 0;
    w.sim->add(std::make_shared<ParticleContactEditor>([&](ParticleContact& c) {
      c.enabled = false;
      ++disabled;
    }));
    const int n = 30;
    w.steps(n);
    CHECK(disabled > 0);  // the ground was touched (and overlapped) all along
    // Symplectic Euler from rest: v_k = -g h k, z_n = z_0 - g h^2 n (n + 1) / 2, exactly as without ground.
    CHECK(ps.getPosition(id).z() == doctest::Approx(r - g * h * h * n * (n + 1) / 2).epsilon(1e-12));
    CHECK(ps.getVelocity(id).z() == doctest::Approx(-g * h * n).epsilon(1e-12));
  }

  TEST_CASE("a surface velocity drags a resting particle until it rolls with the belt") {
    // A belt moving at u under a solid sphere: friction accelerates the centre (m dv = F dt) and spins it
    // (I dw = F r dt, I = 2/5 m r^2) until the contact point moves with the belt, v + w r = u. With
    // dw r = 5/2 dv from rest, v = 2/7 u. Friction mu 0.5 reaches it within 0.1 s; after 1 s the rows only
    // hold it (no rolling resistance).
    const Real r = 0.05, u = 1.0;
    test::TestWorld w(1.0 / 100.0, 9.81, 0.5, 0.0);
    w.addGround();
    auto& ps = w.sim->getGranularBodySystem();
    ps.setMaterial(w.material);
    const size_t id = ps.createParticle(Vec3(0, 0, r), r);
    w.stepSeconds(0.5);  // settle
    w.sim->add(std::make_shared<ParticleContactEditor>([&](ParticleContact& c) { c.surfaceVelocity = Vec3(u, 0, 0); }));
    w.stepSeconds(1.0);
    // 1 %: the friction rows are solved by PGS to a residual well below that; the sphere is on a flat ground.
    CHECK(ps.getVelocity(id).x() == doctest::Approx(2.0 / 7.0 * u).epsilon(0.01));
    CHECK(std::abs(ps.getVelocity(id).y()) < 1e-9);
    // Rolling: the contact point (at -r z from the centre) moves with the belt, v_x - w_y r = u.
    CHECK(ps.getVelocity(id).x() - ps.getAngularVelocity(id).y() * r == doctest::Approx(u).epsilon(0.01));
  }

  TEST_CASE("particle collision groups: a disabled group pair lets particles fall through a geometry") {
    const Real h = 0.01, g = 9.81, r = 0.05;
    for (bool disabled : {false, true}) {
      CAPTURE(disabled);
      test::TestWorld w(h, g, 0.5, 0.0);
      auto ground = w.addGround();
      ground->getGeometries()[0]->addGroup("floor");
      auto& ps = w.sim->getGranularBodySystem();
      ps.setMaterial(w.material);
      ps.addGroup("sand");
      ps.addGroup(7u);
      if (disabled) w.sim->setEnableCollisions("sand", "floor", false);
      const size_t id = ps.createParticle(Vec3(0, 0, r), r);
      const int n = 30;
      w.steps(n);
      if (disabled) {
        CHECK(w.sim->getParticleGeometryContacts().empty());
        CHECK(ps.getPosition(id).z() == doctest::Approx(r - g * h * h * n * (n + 1) / 2).epsilon(1e-12));
      } else {
        CHECK(w.sim->getParticleGeometryContacts().size() == 1);
        CHECK(ps.getPosition(id).z() > r - 1e-3);
      }
    }
  }

  TEST_CASE("GranularBodySystem groups: add, has, remove; names shared with geometries") {
    GranularBodySystem ps;
    CHECK(ps.getGroups().empty());
    ps.addGroup(3u);
    ps.addGroup(3u);
    CHECK(ps.getGroups().size() == 1);
    CHECK(ps.hasGroup(3u));
    ps.addGroup("gravel");
    CHECK(ps.hasGroup("gravel"));
    CHECK(ps.hasGroup(Geometry::groupId("gravel")));
    CHECK(ps.removeGroup("gravel"));
    CHECK_FALSE(ps.removeGroup("gravel"));
    CHECK(ps.removeGroup(3u));
    CHECK(ps.getGroups().empty());
    CHECK_THROWS_AS(ps.addGroup(std::string()), std::invalid_argument);
  }

  TEST_CASE("a post listener destroys every other particle while reading the particle contacts") {
    const Real r = 0.05;
    test::TestWorld w(1.0 / 100.0, 9.81, 0.5, 0.0);
    w.addGround();
    auto& ps = w.sim->getGranularBodySystem();
    ps.setMaterial(w.material);
    std::set<size_t> all;
    for (int k = 0; k < 20; ++k) all.insert(ps.createParticle(Vec3(0.3 * k, 0, r), r));  // apart: no pairs
    w.stepSeconds(0.2);
    REQUIRE(w.sim->getParticleGeometryContacts().size() == 20);

    struct Destroyer : StepEventListener {
      Simulation* sim;
      bool done = false;
      int stale = 0;
      std::vector<size_t> seen, destroyed;
      explicit Destroyer(Simulation* s) : StepEventListener(POST_STEP), sim(s) {}
      void post(const TimeStamp&) override {
        if (done) return;  // once
        done = true;
        auto& gbs = sim->getGranularBodySystem();
        const auto& pg = sim->getParticleGeometryContacts();
        for (size_t k = 0; k < pg.size(); ++k) {
          // The contact's dense index still names the particle it was found for, destroyed neighbours or not
          // (compacting at each destroy would move the last particle into the gap: later indices would run
          // past the arrays or name another particle).
          if (pg[k].a >= gbs.size() || !gbs.isAliveDense(pg[k].a)) {
            ++stale;
            continue;
          }
          const size_t id = gbs.idOfDense(pg[k].a);
          seen.push_back(id);
          if (k % 2 == 1) {
            gbs.destroyParticle(id);
            destroyed.push_back(id);
          }
        }
      }
    };
    auto d = std::make_shared<Destroyer>(w.sim.get());
    w.sim->add(std::static_pointer_cast<StepEventListener>(d));
    w.steps(1);
    // Every particle was seen exactly once, and the ones destroyed are gone, the others live.
    CHECK(d->stale == 0);
    CHECK(std::set<size_t>(d->seen.begin(), d->seen.end()) == all);
    CHECK(d->seen.size() == all.size());
    REQUIRE(d->destroyed.size() == 10);
    CHECK(ps.numParticles() == 10);
    CHECK(ps.size() == 10);  // compacted after the listener
    std::set<size_t> survivors;
    for (size_t id : all)
      if (std::find(d->destroyed.begin(), d->destroyed.end(), id) == d->destroyed.end()) survivors.insert(id);
    for (size_t id : d->destroyed) CHECK_FALSE(ps.isValid(id));
    for (size_t id : survivors) CHECK(ps.isValid(id));

    // The next step is consistent: one contact per survivor, each naming a live survivor, at rest.
    w.steps(1);
    const auto& pg = w.sim->getParticleGeometryContacts();
    REQUIRE(pg.size() == survivors.size());
    std::set<size_t> touched;
    for (const ParticleContact& c : pg) {
      REQUIRE(c.a < ps.size());
      CHECK(ps.isAliveDense(c.a));
      touched.insert(ps.idOfDense(c.a));
    }
    CHECK(touched == survivors);
    for (size_t id : survivors) {
      CHECK(std::abs(ps.getPosition(id).z() - r) < 1e-3);
      CHECK(ps.getVelocity(id).norm() < 1e-3);
    }
    CHECK(w.sim->getLastStepReport().ok());
  }
}
