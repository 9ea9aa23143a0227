// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Terrain digging (terrain.h, "Digging"): a kinematic bucket digs, lifts, dumps and the heap merges back with the
// volume ledger constant after every step; particle mass = bulk density x particle account; the FCC lattice's
// neighbour overlap r(sqrt2 - 1); particles only above the shovel plane + r; the minimum dig angle; bad input.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <unordered_set>
#include <vector>

#include "scree/core/logger.h"
#include "terrain_world.h"

using namespace scree;
using namespace scree::test;

namespace {

constexpr Real kPi = 3.14159265358979323846;

/// A kinematic bucket: a bottom plate (the shovel geometry; half extents 0.2 x 0.15 x 0.01 m, forward +x to its
/// front edge, up +z of its thickness 0.02 m) and a back plate. Rotation q about the body origin (plate centre).
struct Bucket {
  RigidBodyRef body;
  GeometryRef blade;
};

Bucket addBucket(TestWorld& w, const Vec3& at, const Quat& q = Quat::Identity(), const Vec3& up = Vec3(0, 0, 0.02),
                 const Vec3& forward = Vec3(0.2, 0, 0)) {
  Bucket b;
  b.body = std::make_shared<RigidBody>("bucket");
  b.blade = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.2, 0.15, 0.01)), "blade");
  b.blade->setMaterial(w.material);
  b.blade->getPropertyContainer().addPropertyVec3(Terrain::ShovelUpProperty, up);
  b.blade->getPropertyContainer().addPropertyVec3(Terrain::ShovelForwardProperty, forward);
  b.body->add(b.blade);
  auto back = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.01, 0.15, 0.1)), "back");
  back->setMaterial(w.material);
  back->setLocalPosition(Vec3(-0.21, 0, 0.09));
  b.body->add(back);
  b.body->setMotionControl(RigidBody::KINEMATICS);
  b.body->setPosition(at);
  b.body->setRotation(q);
  w.sim->add(b.body);
  return b;
}

/// Runs after the terrain's pre-collide step (added after it): sees the particles as they are created.
class AfterCut : public StepEventListener {
 public:
  explicit AfterCut(std::function<void()> f) : StepEventListener(PRE_COLLIDE), f_(std::move(f)) {}
  void preCollide(const TimeStamp&) override { f_(); }

 private:
  std::function<void()> f_;
};

Real relMassError(const TestWorld& w, const Terrain& t, Real bulkDensity) {
  const Real expected = bulkDensity * t.getVolumeLedger().particles;
  const Real m = w.sim->getGranularBodySystem().getTotalMass();
  // Relative to the account's mass; once every particle has merged (the account is rounding, ~1e-18 m^3)
  // relative to one particle's mass.
  return std::abs(m - expected) / std::max(expected, bulkDensity * t.getParticleVolume());
}

}  // namespace

TEST_CASE("dig-lift-dump-merge cycle: ledger constant every step, particle mass = density x particle account") {
  TestWorld w(1.0 / 60);
  // Grains with rolling resistance (the particles copy the soil's parameters): without it a sphere pushed by the
  // bucket rolls on over flat ground forever and leaves the field.
  w.material->setRollingResistanceCoefficient(0.3);
  TerrainRef t = addFlatTerrain(w, 41, 2.0);  // s = 0.05 m
  t->getParticleAttributes().setParticleRadius(0.02);
  t->setMergeVelocity(0.1);
  const Real rho = w.material->getDensity();
  Bucket b = addBucket(w, Vec3(-0.6, 0, 0.03));
  int step = 0;
  auto phase = [&](Real seconds, const Vec3& v, const Vec3& omega) {
    b.body->setVelocity(v);
    b.body->setAngularVelocity(omega);
    return int(std::lround(seconds / w.dt));
  };
  const Real total0 = t->getVolumeLedger().total();
  Real worstLedger = 0, worstMass = 0;
  size_t created = 0, merged = 0, maxLive = 0;
  Real dug = 0, mergedVol = 0;
  auto run = [&](int n) {
    for (int i = 0; i < n; ++i, ++step) {
      w.sim->stepForward();
      worstLedger = std::max(worstLedger, std::abs(t->getVolumeLedger().total() - total0) / total0);
      worstMass = std::max(worstMass, relMassError(w, *t, rho));
      const TerrainDigStats& s = t->getLastStepDigStats();
      created += s.particlesCreated, merged += s.particlesMerged;
      dug += s.volumeDug, mergedVol += s.volumeMerged;
      maxLive = std::max(maxLive, w.sim->getGranularBodySystem().numParticles());
    }
  };
  run(phase(0.5, Vec3(0, 0, -0.16), Vec3::Zero()));   // down into the soil: tip 5 cm deep
  run(phase(1.5, Vec3(0.4, 0, 0), Vec3::Zero()));     // the trench: 0.6 m forward
  run(phase(1.0, Vec3(0, 0, 0.4), Vec3::Zero()));     // lift
  const size_t carried = w.sim->getGranularBodySystem().numParticles();
  run(phase(1.0, Vec3(0, 0, 0), Vec3(0, 2.0, 0)));    // dump: the tip turns 2 rad down
  run(phase(6.0, Vec3(0, 0, 0), Vec3::Zero()));       // the heap settles and merges
  MESSAGE("created " << created << ", merged " << merged << ", max live " << maxLive << ", carried after lift "
                     << carried << ", dug " << dug << " m^3, merged " << mergedVol << " m^3, ledger drift "
                     << worstLedger << ", mass error " << worstMass);
  CHECK(created > 50);
  CHECK(carried > 0);
  CHECK(merged > 0);
  CHECK(worstLedger <= 1e-9);
  CHECK(worstMass <= 1e-12);
  CHECK(std::abs(t->getVolumeLedger().heightField - t->computeHeightFieldVolume()) <= 1e-9 * total0);
  // After the heap merged: no particle slower than the merge velocity outside the shovel's non-merge zone.
  const GranularBodySystem& gbs = w.sim->getGranularBodySystem();
  Aabb zone = b.blade->getBoundingBox();
  zone.lo -= Vec3::Constant(0.04), zone.hi += Vec3::Constant(0.04);
  size_t slowOutside = 0, offField = 0;
  for (size_t id : t->getParticleIds()) {
    const Vec3 p = gbs.getPosition(id);
    if (std::abs(p.x()) > 1 || std::abs(p.y()) > 1 || p.z() < -0.5) ++offField;
    const bool inZone = p.x() >= zone.lo.x() && p.x() <= zone.hi.x() && p.y() >= zone.lo.y() &&
                        p.y() <= zone.hi.y() && p.z() >= zone.lo.z() && p.z() <= zone.hi.z();
    if (!inZone && gbs.getVelocity(id).norm() < t->getMergeVelocity()) ++slowOutside;
  }
  MESSAGE("terrain particles left " << t->getParticleIds().size() << ", slow outside a shovel zone " << slowOutside
                                     << ", off the field " << offField);
  CHECK(slowOutside == 0);
  CHECK(offField == 0);
  CHECK(t->getParticleIds().size() < carried / 10);  // the heap has merged back
}

TEST_CASE("FCC placement: neighbour overlap r(sqrt2 - 1), nothing below the shovel plane + r") {
  TestWorld w(1.0 / 60);
  TerrainRef t = addFlatTerrain(w, 41, 2.0);
  const Real r = 0.02;
  t->getParticleAttributes().setParticleRadius(r);
  Bucket b = addBucket(w, Vec3(0, 0, -0.05));  // placed 5 cm deep: the first step cuts the whole footprint
  Real worstOverlap = 0, lowest = std::numeric_limits<Real>::infinity();
  size_t checked = 0;
  w.sim->add(std::make_shared<AfterCut>([&] {
    const GranularBodySystem& gbs = w.sim->getGranularBodySystem();
    const size_t n = t->getLastStepDigStats().particlesCreated;
    if (n == 0) return;
    const std::vector<size_t> ids = t->getParticleIds();
    std::vector<Vec3> fresh;
    for (size_t k = ids.size() - n; k < ids.size(); ++k) fresh.push_back(gbs.getPosition(ids[k]));
    // Lattice neighbours made in one step: each touching pair is at the nearest-neighbour distance.
    // The shovel plane: the cutting plane through the tip, moved up by the blade thickness (world = field +z).
    b.blade->updateTransform();
    const Transform& G = b.blade->getTransform();
    const Vec3 up = G.rotate(Vec3(0, 0, 0.02)), tip = G.p + G.rotate(Vec3(0.2, 0, 0));
    const Vec3 planePoint = tip + up;
    for (size_t a = 0; a < fresh.size(); ++a) {
      lowest = std::min(lowest, (fresh[a] - planePoint).dot(up.normalized()) - r);
      Real nearest = std::numeric_limits<Real>::infinity();
      for (size_t c = 0; c < fresh.size(); ++c)
        if (c != a) nearest = std::min(nearest, (fresh[a] - fresh[c]).norm());
      if (nearest < 2 * r) {  // a particle that touches another made in the same step (not a lone one)
        worstOverlap = std::max(worstOverlap, std::abs((2 * r - nearest) - r * (std::sqrt(2.0) - 1)));
        ++checked;
      }
    }
  }));
  stepCheckingLedger(w, *t, 30);
  MESSAGE("checked " << checked << " particles: max |overlap - r(sqrt2-1)| = " << worstOverlap
                     << " m; lowest (distance above the shovel plane) - r = " << lowest << " m");
  CHECK(checked > 20);
  CHECK(worstOverlap <= 1e-12);
  CHECK(lowest >= -1e-12);
}

TEST_CASE("particle radius above the maximum throws std::invalid_argument and changes nothing") {
  TestWorld w;
  TerrainRef t = addFlatTerrain(w, 11, 0.5);
  CHECK(t->getMaximumParticleRadius() == doctest::Approx(0.05));
  const Real r0 = t->getParticleAttributes().getParticleRadius();
  CHECK(r0 == doctest::Approx(0.05 / (2 * (3 * std::sqrt(2.0) - 2))));
  CHECK_THROWS_AS(t->getParticleAttributes().setParticleRadius(0.05 * (1 + 1e-9)), std::invalid_argument);
  CHECK_THROWS_AS(t->getParticleAttributes().setParticleRadius(0), std::invalid_argument);
  CHECK_THROWS_AS(t->getParticleAttributes().setParticleRadius(std::nan("")), std::invalid_argument);
  CHECK(t->getParticleAttributes().getParticleRadius() == r0);
  t->getParticleAttributes().setParticleRadius(0.05);
  CHECK(t->getParticleAttributes().getParticleRadius() == 0.05);
}

namespace {
/// A blade whose up vector makes `angle` with the horizontal plane (forward tilted down by pi/2 - angle), its
/// tip 10 cm deep; steps 10 times and returns the particles made and the volume dug.
std::pair<size_t, Real> digAtAngle(Real angle) {
  TestWorld w(1.0 / 60);
  TerrainRef t = addFlatTerrain(w, 41, 2.0);
  t->getParticleAttributes().setParticleRadius(0.01);
  const Real beta = kPi / 2 - angle;
  const Quat q(Eigen::AngleAxis<Real>(beta, Vec3::UnitY()));
  const Vec3 tip = q * Vec3(0.2, 0, 0);
  Bucket b = addBucket(w, Vec3(0, 0, -0.1) - tip, q);
  size_t created = 0;
  Real dug = 0;
  for (int i = 0; i < 10; ++i) {
    w.sim->stepForward();
    created += t->getLastStepDigStats().particlesCreated;
    dug += t->getLastStepDigStats().volumeDug;
  }
  return {created, dug};
}
}  // namespace

TEST_CASE("minimum dig angle: just below nothing is dug, just above particles appear") {
  TestWorld w;
  TerrainRef t = addFlatTerrain(w, 11, 0.5);
  CHECK(t->getShovelMinimumDigAngleToHorizontalPlane() == doctest::Approx(kPi / 10));
  const auto below = digAtAngle(kPi / 10 - 0.01);
  const auto above = digAtAngle(kPi / 10 + 0.01);
  MESSAGE("pi/10 - 0.01: " << below.first << " particles, " << below.second << " m^3 dug; pi/10 + 0.01: "
                           << above.first << " particles, " << above.second << " m^3 dug");
  CHECK(below.first == 0);
  CHECK(below.second == 0);
  CHECK(above.first > 0);
}

TEST_CASE("bad input: shovel vectors, merge velocity, dig angle, radius - clear errors, state unchanged") {
  std::vector<std::string> errors;
  Logger::setSink([&](LogLevel l, const std::string& m) {
    if (l == LogLevel::ERROR) errors.push_back(m);
  });
  struct Case {
    Vec3 up, forward;
    const char* expect;
  };
  const Real inf = std::numeric_limits<Real>::infinity();
  const Case cases[] = {{Vec3::Zero(), Vec3(0.2, 0, 0), "zero vector"},
                        {Vec3(0, 0, 0.02), Vec3::Zero(), "zero vector"},
                        {Vec3(0, 0, inf), Vec3(0.2, 0, 0), "not finite"},
                        {Vec3(0, 0, 0.02), Vec3(0.2, 0, std::nan("")), "not finite"},
                        {Vec3(0, 0.001, 0.02), Vec3(0, 0.2, 0), "not orthogonal"}};
  for (const Case& c : cases) {
    errors.clear();
    TestWorld w(1.0 / 60);
    TerrainRef t = addFlatTerrain(w, 41, 2.0);
    t->getParticleAttributes().setParticleRadius(0.02);
    const Real h0 = t->getVolumeLedger().heightField;
    Bucket b = addBucket(w, Vec3(0, 0, -0.05), Quat::Identity(), c.up, c.forward);
    CHECK_FALSE(t->isGeometryShovel(b.blade));
    for (int i = 0; i < 5; ++i) w.sim->stepForward();
    REQUIRE(errors.size() == 1);  // once, naming the geometry and the problem
    CHECK(errors[0].find("\"blade\"") != std::string::npos);
    CHECK(errors[0].find(c.expect) != std::string::npos);
    CHECK(t->getVolumeLedger().heightField == h0);
    CHECK(w.sim->getGranularBodySystem().numParticles() == 0);
  }
  Logger::setSink({});
  TestWorld w;
  TerrainRef t = addFlatTerrain(w, 11, 0.5);
  t->setMergeVelocity(0.2);
  CHECK_THROWS_WITH_AS(t->setMergeVelocity(-0.1), doctest::Contains("Terrain::setMergeVelocity"),
                       std::invalid_argument);
  CHECK_THROWS_AS(t->setMergeVelocity(inf), std::invalid_argument);
  CHECK(t->getMergeVelocity() == 0.2);
  CHECK_THROWS_AS(t->setShovelMinimumDigAngleToHorizontalPlane(-0.1), std::invalid_argument);
  CHECK_THROWS_AS(t->setShovelMinimumDigAngleToHorizontalPlane(2.0), std::invalid_argument);
  CHECK(t->getShovelMinimumDigAngleToHorizontalPlane() == doctest::Approx(kPi / 10));
  CHECK(Terrain::checkShovelVectors(Vec3(0, 0, 1), Vec3(1, 0, 0)).empty());
}

// ---- issue 16: a full bucket (terrain.h, "the cap") ------------------------------------------------------------
TEST_CASE("full bucket: no particle made above the rim, the rest stays pending, the fill stops at the capacity") {
  TestWorld w(1.0 / 60);
  w.material->setRollingResistanceCoefficient(0.3);
  TerrainRef t = addFlatTerrain(w, 41, 2.0);  // s = 0.05 m
  const Real r = 0.02;
  t->getParticleAttributes().setParticleRadius(r);
  // A closed bucket: blade (the shovel; 0.3 x 0.2 x 0.02 m, up +z, forward +x to its front edge), back plate and
  // two sides, all rising to the rim 0.12 m above the blade's top (the shovel plane).
  const Real L = 0.3, W = 0.2, tp = 0.02, inner = 0.12, H = inner + tp;
  auto body = std::make_shared<RigidBody>("bucket");
  auto blade = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.5 * L, 0.5 * W, 0.5 * tp)), "blade");
  blade->getPropertyContainer().addPropertyVec3(Terrain::ShovelUpProperty, Vec3(0, 0, tp));
  blade->getPropertyContainer().addPropertyVec3(Terrain::ShovelForwardProperty, Vec3(0.5 * L, 0, 0));
  body->add(blade);
  auto back = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.5 * tp, 0.5 * W + tp, 0.5 * H)), "back");
  back->setLocalPosition(Vec3(-0.5 * L - 0.5 * tp, 0, 0.5 * H - 0.5 * tp));
  body->add(back);
  for (Real side : {-1.0, 1.0}) {
    auto g = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.5 * L, 0.5 * tp, 0.5 * H)), "side");
    g->setLocalPosition(Vec3(0, side * (0.5 * W + 0.5 * tp), 0.5 * H - 0.5 * tp));
    body->add(g);
  }
  for (const GeometryRef& g : body->getGeometries()) g->setMaterial(w.material);
  body->setMotionControl(RigidBody::KINEMATICS);
  body->setPosition(Vec3(-0.7, 0, 0.03));
  w.sim->add(body);
  // The bucket's capacity: the space over the blade below the rim, 0.0072 m^3. The cap lets sites lie between
  // r above the blade and r below the rim, L W (inner - 2r) = 0.0048 m^3 of lattice, about 212 sites of
  // V = a^3 / 4 = 2.26e-5 m^3 (each site stands for a^3 / 4 of space).
  const Real capacity = L * W * inner, latticeRoom = L * W * (inner - 2 * r);

  // Every particle as it is made (a listener after the terrain's cut): its sphere must lie below the rim.
  const GranularBodySystem& gbs = w.sim->getGranularBodySystem();
  std::unordered_set<size_t> seen;  // ids carry a generation: not an index
  Real worstAboveRim = -1, rim = 0;
  auto check = std::make_shared<AfterCut>([&] {
    rim = -std::numeric_limits<Real>::infinity();
    for (const GeometryRef& g : body->getGeometries()) rim = std::max(rim, g->getBoundingBox().hi.z());
    for (size_t id : t->getParticleIds()) {
      if (!seen.insert(id).second) continue;
      worstAboveRim = std::max(worstAboveRim, gbs.getPosition(id).z() + r - rim);
    }
  });
  w.sim->add(check);

  const Real total0 = t->getVolumeLedger().total();
  Real worstLedger = 0, fillMax = 0, fillAtHalf = 0;
  size_t created = 0;
  auto run = [&](int n, const Vec3& v) {
    body->setVelocity(v);
    for (int i = 0; i < n; ++i) {
      w.sim->stepForward();
      worstLedger = std::max(worstLedger, std::abs(t->getVolumeLedger().total() - total0) / total0);
      created += t->getLastStepDigStats().particlesCreated;
      fillMax = std::max(fillMax, t->getShovelStats(*blade).fillVolume);
    }
  };
  run(30, Vec3(0, 0, -0.16));  // 0.5 s down: the tip 5 cm deep
  run(90, Vec3(0.4, 0, 0));    // 1.5 s, 0.6 m forward
  fillAtHalf = fillMax;
  run(90, Vec3(0.4, 0, 0));    // 0.6 m more: about 0.012 m^3 dug in all
  const TerrainShovelStats s = t->getShovelStats(*blade);
  const TerrainVolumeLedger& l = t->getVolumeLedger();
  MESSAGE("created " << created << ", fill max " << fillMax << " m^3 (" << fillMax / capacity
                     << " of capacity), at half way " << fillAtHalf << ", at the end " << s.fillVolume
                     << ", pending " << l.pending << ", particles " << l.particles << ", worst sphere top - rim "
                     << worstAboveRim << " m, ledger drift " << worstLedger);
  CHECK(worstLedger <= 1e-9);
  // The cap: every particle's sphere is made below the rim (the site's centre at most rim - r; 1e-12 rounding).
  CHECK(worstAboveRim <= 1e-12);
  CHECK(created > 100);
  // The bucket filled: the soil that did not fit waits pending (far more than the lead's strip, about
  // 0.05 x 0.3 x 0.09 m = 0.0014 m^3).
  CHECK(l.pending > 0.003);
  // The fill stays within the room the cap leaves: particles are made only there, at most one per site, each
  // carrying its site's space a^3 / 4; resting at contact (2r > d, no adhesion) they pack looser than the
  // lattice, so no tolerance is needed (measured 0.69 of it; 1.10 before the cap, its column 0.65 m above the rim).
  CHECK(fillMax <= latticeRoom);
  CHECK(fillMax >= 0.5 * latticeRoom);  // it did fill (measured 0.69)
  // It stops growing: the second 0.6 m digs 0.6 x 0.2 x 0.05 = 0.006 m^3 = 1.25 latticeRoom, yet the fill gains
  // little (measured 0.05 latticeRoom: particles settling free a few sites; 0.20 before the cap, when particles
  // falling off the column capped it instead); 0.1 allows for the settling.
  CHECK(fillMax - fillAtHalf <= 0.1 * latticeRoom);
}
