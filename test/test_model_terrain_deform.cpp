// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Terrain deformers (terrain.h, "Dynamic height field: deformers"; manual 25.1.2.15-25.1.2.18): the generated
// vertical contact's Young's modulus E max(1, A/s_v) for two overlap areas; a deformer box resting with
// useContactDepth true settles at the depth its vertical contacts' compliance predicts, with false its vertical
// contacts have zero depth; a blade pushed through soil faster than the cut-off velocity builds a berm ahead with
// the ledger exact after every step, harder to push the deeper it cuts, its horizontal points of zero depth with
// E_h = E max(1, A_h / s_h); below the cut-off nothing moves; a
// blade turning in place deforms only above the angular cut-off.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "terrain_world.h"

using namespace scree;
using namespace scree::test;

namespace {

/// A 41 x 41 terrain (4 m, cells 0.1 m, 0.5 m of soil, surface at z = 0) with the dynamic height field on.
TerrainRef addDeformTerrain(TestWorld& w) {
  TerrainRef t = addFlatTerrain(w, 41, 4.0, 0.5);
  t->setEnableDynamicHeightField(true);
  return t;
}

RigidBodyRef addDeformerBox(TestWorld& w, const Vec3& half, const Vec3& pos, Real mass, bool useContactDepth) {
  RigidBodyRef b = w.addBox(half, pos, mass);
  b->getGeometries().front()->getPropertyContainer().addPropertyBool(Terrain::DeformerProperty, useContactDepth);
  return b;
}

/// The contact between the terrain and a geometry in the simulation's last contact list.
const GeometryContact* findContact(TestWorld& w, const Terrain& t) {
  for (const GeometryContact& c : w.sim->getContacts())
    if (c.geometry(0) == t.getGeometry().get() || c.geometry(1) == t.getGeometry().get()) return &c;
  return nullptr;
}

}  // namespace

TEST_CASE("deformer contacts: E_v = E max(1, A / s_v) for two overlap areas, and the resting depth") {
  // Boxes of half width 0.25 and 0.45 m centred on a vertex cover 5 x 5 and 9 x 9 vertices: A_v = 0.25 and
  // 0.81 m^2, so with s_v = 0.01 E_v = 25 E and 81 E. E = 100 N/m per point (contact material), so 10 kg on the
  // 4 corner points rests about a centimetre deep. The box settles where its weight is carried by the vertical
  // points (E_v depth each) and the very soft original points (1e-3 E depth each): depth = m g / (N (E_v +
  // 1e-3 E)), N = the number of original points [2 %].
  for (Real half : {0.25, 0.45}) {
    CAPTURE(half);
    TestWorld w;
    w.contactMaterial->setYoungsModulus(100);
    TerrainRef t = addDeformTerrain(w);
    const Real mass = 10;
    RigidBodyRef box = addDeformerBox(w, Vec3(half, half, 0.1), Vec3(0, 0, 0.1 - 0.005), mass, true);
    stepCheckingLedger(w, *t, 240);
    const auto& infos = t->getLastStepDeformerContacts();
    REQUIRE(infos.size() == 1);
    const auto& info = infos.front();
    const Real expectedArea = std::pow(std::floor(half / 0.1) * 2 + 1, 2) * 0.01;
    CHECK(info.verticalArea == doctest::Approx(expectedArea).epsilon(1e-12));
    CHECK(info.youngsModulus == doctest::Approx(100).epsilon(1e-12));
    const Real Ev = 100 * std::max<Real>(1, info.verticalArea / t->getVerticalYoungsModulusAreaScaler());
    CHECK(std::abs(info.verticalYoungsModulus - Ev) <= 1e-9 * Ev);
    CHECK(std::abs(t->computeVerticalYoungsModulus(100, info.verticalArea) - Ev) <= 1e-9 * Ev);
    // The contact holds the original points (soft) and one vertical point each; at rest no horizontal ones.
    const GeometryContact* c = findContact(w, *t);
    REQUIRE(c);
    size_t nOrig = 0, nV = 0;
    for (const ContactPoint& p : c->points()) {
      if (p.youngsModulus == Ev) ++nV;
      else if (std::abs(p.youngsModulus - 100 * Terrain::kDeformerSoftness) < 1e-12) ++nOrig;
    }
    CHECK(nOrig == info.numOriginalPoints);
    CHECK(nV == info.numVerticalPoints);
    Real horizontalForce = 0;
    for (const ContactPoint& p : c->points())
      if (p.frictionCoefficient == 0 && std::abs(p.normal.z()) < 1e-9) horizontalForce += p.normalForce;
    CHECK(horizontalForce <= 1e-6 * mass * 9.81);
    // At rest: the vertical points' friction (mu of their load) holds the box; the PGS residual of those rows
    // leaves it creeping at most ~1e-7 m/s (measured 9.8e-8 and 1.3e-10 m/s), and a horizontal point built along
    // that creep (d is any nonzero horizontal velocity) carries nothing that matters: < 1e-6 of the weight.
    const Vec3 vh(box->getVelocity().x(), box->getVelocity().y(), 0);
    CHECK(vh.norm() <= 1e-6);
    REQUIRE(nOrig > 0);
    const Real predicted = mass * 9.81 / (Real(nOrig) * (Ev + 100 * Terrain::kDeformerSoftness));
    const Real depth = -(box->getPosition().z() - 0.1);
    CAPTURE(depth);
    CAPTURE(predicted);
    MESSAGE("resting depth " << depth << " m, predicted " << predicted << " m, " << nOrig << " points");
    CHECK(std::abs(depth - predicted) <= 0.02 * predicted);
    // At rest (below the cut-offs) the heights are untouched.
    for (Real hgt : t->getHeightField()->getHeights()) REQUIRE(hgt == 0.5);
  }
}

TEST_CASE("deformer contacts: useContactDepth false gives vertical contacts of zero depth") {
  TestWorld w;
  w.contactMaterial->setYoungsModulus(100);
  TerrainRef t = addDeformTerrain(w);
  addDeformerBox(w, Vec3(0.25, 0.25, 0.1), Vec3(0, 0, 0.1 - 0.01), 10, false);
  size_t seen = 0;
  for (int i = 0; i < 30; ++i) {
    w.sim->stepForward();
    const GeometryContact* c = findContact(w, *t);
    if (!c || t->getLastStepDeformerContacts().empty()) continue;
    const Real Ev = t->getLastStepDeformerContacts().front().verticalYoungsModulus;
    for (const ContactPoint& p : c->points())
      if (p.youngsModulus == Ev && std::abs(p.normal.z()) == 1) {  // the vertical points (exactly +-z)
        ++seen;
        CHECK(p.depth == 0);
      }
  }
  CHECK(seen > 0);
}

namespace {

struct PushResult {
  std::vector<Real> bermHeights;  ///< highest soil ahead of the blade at each sample distance, m above 0.5
  Real meanResistance = 0;        ///< mean horizontal contact force on the blade, N
  Real worstDrift = 0;
  size_t pushed = 0;
  size_t maxArmed = 0;  ///< most vertices armed for avalanches at once
  size_t horizontalPoints = 0;      ///< horizontal points seen (friction 0, horizontal normal)
  size_t horizontalNonzeroDepth = 0;  ///< of which with a depth other than 0
  Real worstEh = 0;  ///< max over steps of |E_h - E max(1, A_h / s_h)| / E_h (DeformerContactInfo)
  Real largestAh = 0;  ///< m^2
};

/// A blade (0.1 m thick along x, 1 m wide, 0.4 m tall box; a deformer with useContactDepth false) driven through
/// the soil at 0.5 m/s along +x with its bottom `depth` below the surface: each pre step its position height and
/// velocity are reset, so its velocity loss in a step is the soil's horizontal impulse. Samples the berm at 0.3,
/// 0.9 and 1.8 m pushed.
PushResult pushBlade(Real depth, Real speed = 0.5, Real cutOff = Terrain::defaultDynamicHeightFieldCutOffVelocity) {
  TestWorld w;
  w.contactMaterial->setYoungsModulus(1e3);
  TerrainRef t = addDeformTerrain(w);
  t->setDynamicHeightFieldCutOffVelocity(cutOff);
  t->setDynamicHeightFieldCutOffAngularVelocity(1e9);
  const Real halfH = 0.2;
  const Real x0 = -1.2;
  RigidBodyRef blade = addDeformerBox(w, Vec3(0.05, 0.5, halfH), Vec3(x0, 0, halfH - depth), 1000, false);
  auto driver = std::make_shared<LambdaStepListener>([&](const TimeStamp&) {
    Vec3 p = blade->getPosition();
    p.z() = halfH - depth;
    p.y() = 0;
    blade->setPosition(p);
    blade->setRotation(Quat::Identity());
    blade->setVelocity(Vec3(speed, 0, 0));
    blade->setAngularVelocity(Vec3::Zero());
  });
  w.sim->add(StepEventListenerRef(driver));
  PushResult r;
  const Real total0 = t->getVolumeLedger().total();
  const Real samples[3] = {0.3, 0.9, 1.8};  // m pushed
  size_t next = 0;
  Real force = 0;
  int forceSteps = 0;
  const HeightField& hf = *t->getHeightField();
  for (int s = 1; s <= 3000 && next < 3; ++s) {
    w.sim->stepForward();
    const Real drift = std::abs(t->getVolumeLedger().total() - total0) / total0;
    r.worstDrift = std::max(r.worstDrift, drift);
    r.pushed += t->getLastStepDeformStats().verticesPushed;
    r.maxArmed = std::max(r.maxArmed, t->getNumArmedVertices());
    const Real travelled = blade->getPosition().x() - x0;
    // The horizontal points: zero depth (manual 25.1.2.18), E_h = E max(1, A_h / s_h) as for the vertical law.
    if (const GeometryContact* c = findContact(w, *t))
      for (const ContactPoint& p : c->points())
        if (p.frictionCoefficient == 0 && std::abs(p.normal.z()) < 1e-9) {
          ++r.horizontalPoints;
          if (p.depth != 0) ++r.horizontalNonzeroDepth;
        }
    for (const auto& info : t->getLastStepDeformerContacts()) {
      if (info.numHorizontalPoints == 0) continue;
      const Real Eh = info.youngsModulus * std::max<Real>(1, info.horizontalArea / t->getHorizontalYoungsModulusAreaScaler());
      r.worstEh = std::max(r.worstEh, std::abs(info.horizontalYoungsModulus - Eh) / Eh);
      r.largestAh = std::max(r.largestAh, info.horizontalArea);
    }
    // Horizontal points of the deformer contact (friction 0, normal horizontal), once the berm has formed.
    if (travelled > samples[0]) {
      ++forceSteps;
      if (const GeometryContact* c = findContact(w, *t))
        for (const ContactPoint& p : c->points())
          if (p.frictionCoefficient == 0 && std::abs(p.normal.z()) < 1e-9) force += p.normalForce;
    }
    if (travelled >= samples[next]) {
      // Berm height: over the rows across the blade (|y| < 0.4 m), the highest soil within 1 m ahead of its
      // front, averaged over the rows (the peak of a single row jumps as the blade pushes it vertex by vertex).
      const Real front = blade->getPosition().x() + 0.05;
      Real sum = 0;
      int rows = 0;
      for (size_t j = 0; j < hf.getResolutionY(); ++j) {
        const Real y = Real(j) * 0.1 - 2.0;
        if (std::abs(y) > 0.4) continue;
        Real top = 0;
        for (size_t i = 0; i < hf.getResolutionX(); ++i) {
          const Real x = Real(i) * 0.1 - 2.0;
          if (x > front && x < front + 1.0) top = std::max(top, hf.getHeight(i, j) - 0.5);
        }
        sum += top;
        ++rows;
      }
      r.bermHeights.push_back(sum / rows);
      ++next;
    }
  }
  r.meanResistance = forceSteps ? force / Real(forceSteps) : 0;
  CHECK(std::abs(t->getVolumeLedger().heightField - t->computeHeightFieldVolume()) <= 1e-9 * total0);
  return r;
}

}  // namespace

TEST_CASE("deformer blade: the ledger is exact every step, a berm grows ahead, deeper is harder to push") {
  const PushResult shallow = pushBlade(0.05);
  const PushResult deep = pushBlade(0.1);
  for (const PushResult* r : {&shallow, &deep}) {
    CHECK(r->worstDrift <= 1e-9);
    CHECK(r->pushed > 0);
    CHECK(r->maxArmed > 0);  // moved vertices arm avalanches (the berm slumps)
    CHECK(r->horizontalPoints > 0);
    CHECK(r->horizontalNonzeroDepth == 0);
    CHECK(r->worstEh <= 1e-9);
    // A_h = 1 m x (at least the cut depth) > s_h = 0.005 m^2: the scaled branch of the law is the one checked.
    CHECK(r->largestAh > 10 * Terrain::defaultHorizontalYoungsModulusAreaScaler);
    REQUIRE(r->bermHeights.size() == 3);
    MESSAGE("berm heights " << r->bermHeights[0] << " " << r->bermHeights[1] << " " << r->bermHeights[2]
                            << ", resistance " << r->meanResistance << " N");
    CHECK(r->bermHeights[0] > 0);
    CHECK(r->bermHeights[1] > r->bermHeights[0]);
    CHECK(r->bermHeights[2] > r->bermHeights[1]);
  }
  CHECK(deep.meanResistance > shallow.meanResistance);
  CHECK(shallow.meanResistance > 0);
}

TEST_CASE("deformer blade below the cut-off velocity: heights bit-identical") {
  // No gravity: the blade's velocity after the solve is then the driven 0.04 m/s or less (with gravity its
  // fall through the zero-depth vertical contacts would add a vertical speed above the cut-off).
  TestWorld w(1.0 / 60, 0.0);
  w.contactMaterial->setYoungsModulus(1e3);
  TerrainRef t = addDeformTerrain(w);
  const std::vector<Real> before = t->getHeightField()->getHeights();
  const Real speed = 0.04;  // below the default cut-off 0.05 m/s
  RigidBodyRef blade = addDeformerBox(w, Vec3(0.05, 0.5, 0.2), Vec3(-1.2, 0, 0.2 - 0.1), 1000, false);
  auto driver = std::make_shared<LambdaStepListener>([&](const TimeStamp&) {
    blade->setPosition(Vec3(blade->getPosition().x(), 0, 0.1));
    blade->setRotation(Quat::Identity());
    blade->setVelocity(Vec3(speed, 0, 0));
    blade->setAngularVelocity(Vec3::Zero());
  });
  w.sim->add(StepEventListenerRef(driver));
  size_t contacts = 0;
  for (int i = 0; i < 120; ++i) {
    w.sim->stepForward();
    contacts += t->getLastStepDeformerContacts().size();
    CHECK(t->getLastStepDeformStats().verticesPushed == 0);
  }
  CHECK(contacts > 0);  // it did touch the soil
  CHECK(t->getHeightField()->getHeights() == before);
}

TEST_CASE("deformer turning in place: above the angular cut-off it pushes soil (ledger exact), below it nothing") {
  // A 1 m x 0.1 m blade spinning about z at 1 rad/s over the origin, its bottom 5 cm deep: its centre does not
  // move (below the velocity cut-off), so only the angular cut-off can start deformation.
  for (Real cutOffW : {0.5, 2.0}) {
    CAPTURE(cutOffW);
    TestWorld w(1.0 / 60, 0.0);
    w.contactMaterial->setYoungsModulus(1e3);
    TerrainRef t = addDeformTerrain(w);
    t->setDynamicHeightFieldCutOffAngularVelocity(cutOffW);
    const std::vector<Real> before = t->getHeightField()->getHeights();
    RigidBodyRef blade = addDeformerBox(w, Vec3(0.5, 0.05, 0.2), Vec3(0.03, 0.03, 0.15), 1000, false);
    auto driver = std::make_shared<LambdaStepListener>([&](const TimeStamp&) {
      blade->setPosition(Vec3(0.03, 0.03, 0.15));
      blade->setVelocity(Vec3::Zero());
      blade->setAngularVelocity(Vec3(0, 0, 1));
    });
    w.sim->add(StepEventListenerRef(driver));
    const Real worst = stepCheckingLedger(w, *t, 60);
    CHECK(worst <= 1e-9);
    CHECK(!t->getLastStepDeformerContacts().empty());
    if (cutOffW < 1) {
      CHECK(t->getHeightField()->getHeights() != before);
      CHECK(t->getNumArmedVertices() > 0);
    } else {
      CHECK(t->getHeightField()->getHeights() == before);
    }
  }
}
