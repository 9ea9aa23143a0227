// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Digging force against the fundamental earthmoving equation (FEE; docs/terrain.md, "Digging force against the
// fundamental earthmoving equation"; scene: bench/scenes/terrain_fee.h). A flat kinematic blade is pushed 0.3 m at
// constant depth d and speed through cohesionless terrain that digs into particles, for d = 3, 5, 7 cm, widths
// w = 0.2, 0.3 m and rakes 45 and 60 degrees, the cut taking the FEE failure wedge (Terrain::setShovelFailureWedge).
// Two measures of the horizontal force are compared with the FEE's gamma d^2 w N_gamma sin(alpha + delta): the
// mean over the second half of the push (wedge + the dug soil pushed so far, the FEE's surcharge term) and F0, the
// force extrapolated to zero travel from the least-squares line F(s) = F0 + k_s s (the wedge term alone; k_s s is
// the pile's, reported in the messages). Each setting is pushed from 4 start positions spread over one height-field
// cell and the results averaged (runTerrainFeeAveraged: the lattice's pulses, not the cut, otherwise decide F0).
// 48 pushes, about 50 s of CPU in Release on one thread.
#include <doctest/doctest.h>

#include <cmath>

#include "scenes/terrain_fee.h"
#include "scree/core/parallel.h"
#include "terrain_world.h"
#include "test_world.h"

using namespace scree;
using namespace scree::scenes;
using namespace scree::test;

namespace {

constexpr Real kPi = 3.14159265358979323846;
constexpr Real kRakes[2] = {45, 60};
constexpr Real kDepths[3] = {0.03, 0.05, 0.07};
constexpr Real kWidths[2] = {0.2, 0.3};
constexpr int kPhases = 4;  // start positions averaged per setting (runTerrainFeeAveraged)

struct Study {
  Real force[2][2][3] = {};  // [rake][width][depth], N
  Real fee[2][2][3] = {};
  Real force0[2][2][3] = {};  // F0 (N): the line's intercept
  Real slope[2][2][3] = {};   // k_s (N/m)
  Real worstLedger = 0;
};

const Study& study() {
  static const Study s = [] {
    Study out;
    setNumThreads(1);  // results do not depend on the thread count; one thread is fastest on a loaded machine
    const TerrainFeeParams base;
    const Real phi = std::atan(base.soilFriction), delta = std::atan(base.bladeFriction);
    for (int a = 0; a < 2; ++a)
      for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 3; ++j) {
          TerrainFeeParams p = base;
          p.rake = kRakes[a] * kPi / 180;
          p.width = kWidths[k];
          p.depth = kDepths[j];
          const TerrainFeeResult r = runTerrainFeeAveraged(p, kPhases);
          out.force[a][k][j] = r.meanForce;
          out.force0[a][k][j] = r.force0;
          out.slope[a][k][j] = r.pileSlope;
          out.fee[a][k][j] = feeHorizontalForce(p.rake, phi, delta, p.density * 9.81, p.depth, p.width);
          out.worstLedger = std::max(out.worstLedger, r.ledgerDrift);
          // The soil-blade friction the push mobilises: the blade's force, normal N and friction mu' N up its face,
          // has V / H = (cos alpha - mu' sin alpha) / (sin alpha + mu' cos alpha) (V downward on the blade), over
          // the whole push after the first 2 cm. The FEE assumes mu' = tan(delta) = 0.364 (20 deg).
          Real sumH = 0, sumV = 0;
          for (const TerrainFeeSample& x : r.samples)
            if (x.travel > 0.02) sumH += x.force, sumV += -x.vertical;
          const Real vh = sumV / sumH, ca = std::cos(p.rake), sa = std::sin(p.rake);
          const Real deltaEff = std::atan((ca - vh * sa) / (sa + vh * ca)) * 180 / kPi;
          MESSAGE("rake " << kRakes[a] << " deg, w " << kWidths[k] << " m, d " << kDepths[j] << " m: F = "
                          << r.meanForce << " N, FEE = " << out.fee[a][k][j] << " N, ratio "
                          << r.meanForce / out.fee[a][k][j] << "; F0 = " << r.force0 << " N (F0 / FEE "
                          << r.force0 / out.fee[a][k][j] << "), k_s = " << r.pileSlope << " N/m; V / H = " << vh
                          << ", mobilised blade friction angle " << deltaEff << " deg");
        }
    setNumThreads(0);
    return out;
  }();
  return s;
}

/// Least-squares slope of ln F against ln d.
Real depthExponent(const Real (&f)[3]) {
  Real mx = 0, my = 0;
  for (int j = 0; j < 3; ++j) mx += std::log(kDepths[j]) / 3, my += std::log(f[j]) / 3;
  Real sxy = 0, sxx = 0;
  for (int j = 0; j < 3; ++j) {
    const Real dx = std::log(kDepths[j]) - mx;
    sxy += dx * (std::log(f[j]) - my);
    sxx += dx * dx;
  }
  return sxy / sxx;
}

}  // namespace

TEST_CASE("FEE factors: McKyes' worked case and Rankine's passive coefficient") {
  const Real deg = kPi / 180;
  // phi = 35, delta = 20, alpha = 60 deg: beta* = 28.105 deg, N_gamma = 1.8196, N_q = 3.6392 (worked by hand from
  // the wedge's force balance, docs/terrain.md); the 4-digit values bound the search to 5e-5.
  const FeeFactors f = feeFactors(60 * deg, 35 * deg, 20 * deg);
  CHECK(f.beta / deg == doctest::Approx(28.105).epsilon(5e-5));
  CHECK(f.nGamma == doctest::Approx(1.8196).epsilon(5e-5));
  CHECK(f.nQ == doctest::Approx(3.6392).epsilon(5e-5));
  // Vertical smooth blade: N_gamma = K_p / 2, K_p = tan^2(45 deg + phi / 2), failure plane at 45 deg - phi / 2.
  const FeeFactors r = feeFactors(90 * deg, 35 * deg, 0);
  const Real kp = std::pow(std::tan(45 * deg + 17.5 * deg), 2);
  CHECK(r.nGamma == doctest::Approx(kp / 2).epsilon(1e-9));
  CHECK(r.beta / deg == doctest::Approx(27.5).epsilon(1e-6));
  // The model's own search (Terrain::failureWedgeAngle, the cut's failure plane) finds the same beta*.
  CHECK(Terrain::failureWedgeAngle(60 * deg, 35 * deg, 20 * deg) == doctest::Approx(f.beta).epsilon(1e-8));
  CHECK(Terrain::failureWedgeAngle(90 * deg, 35 * deg, 0) == doctest::Approx(27.5 * deg).epsilon(1e-8));
  CHECK_THROWS_AS(Terrain::failureWedgeAngle(NAN, 0.6, 0.3), std::invalid_argument);
  CHECK_THROWS_AS(Terrain::failureWedgeAngle(1.0, 2.0, 0.3), std::invalid_argument);
  CHECK_THROWS_AS(Terrain::failureWedgeAngle(1.0, 0.6, -0.1), std::invalid_argument);
  // Horizontal draft of the worked case, gamma = 16 kN/m^3, d = 0.2 m, w = 1 m: 1146.9 N.
  CHECK(feeHorizontalForce(60 * deg, 35 * deg, 20 * deg, 16e3, 0.2, 1.0) == doctest::Approx(1146.9).epsilon(1e-4));
}

TEST_CASE("FEE digging-force study: force proportional to width, within a factor 2 of the FEE at d = 5 cm") {
  const Study& s = study();
  CHECK(s.worstLedger <= 1e-9);  // the ledger invariant holds through the dig
  for (int a = 0; a < 2; ++a) {
    for (int k = 0; k < 2; ++k)
      MESSAGE("rake " << kRakes[a] << ", w " << kWidths[k] << ": fitted exponent of d = " << depthExponent(s.force[a][k])
                      << " (FEE: 2)");
    for (int j = 0; j < 3; ++j) {
      // Proportional to w: F(0.3) / F(0.2) = 1.5 within 20 % (the bound: the blade's edges add force -
      // soil spilling round them - that does not scale with w).
      const Real ratio = s.force[a][1][j] / s.force[a][0][j];
      CHECK_MESSAGE(std::abs(ratio / 1.5 - 1) <= 0.2, "rake " << kRakes[a] << ", d " << kDepths[j] << ": F(w = 0.3) / F(w = 0.2) = " << ratio);
    }
    // The middle depth: within a factor 2 of the FEE (the bound) at both widths.
    for (int k = 0; k < 2; ++k) {
      const Real ratio = s.force[a][k][1] / s.fee[a][k][1];
      CHECK_MESSAGE(ratio >= 0.5, "rake " << kRakes[a] << ", w " << kWidths[k] << ": F / FEE = " << ratio);
      CHECK_MESSAGE(ratio <= 2.0, "rake " << kRakes[a] << ", w " << kWidths[k] << ": F / FEE = " << ratio);
      // The wedge term alone, F0 (zero travel: no dug soil pushed yet), within the same factor 2 of the FEE
      // without surcharge. Measured 0.62-0.83 (4 start positions averaged, docs/terrain.md); without the failure wedge it was 0.02-0.25 at
      // this depth (the cut cleared the ground ahead at no cost), so this fails if the wedge is not taken.
      const Real r0 = s.force0[a][k][1] / s.fee[a][k][1];
      CHECK_MESSAGE(r0 >= 0.5, "rake " << kRakes[a] << ", w " << kWidths[k] << ": F0 / FEE = " << r0);
      CHECK_MESSAGE(r0 <= 2.0, "rake " << kRakes[a] << ", w " << kWidths[k] << ": F0 / FEE = " << r0);
    }
  }
}

// The bound on the depth exponent, applied to the wedge term F0 (docs/terrain.md, "The failure wedge":
// the window mean also holds the pile of dug soil, the FEE's surcharge term, linear in d, so its exponent is not
// the FEE's d^2 one; it is printed too). F0 is the mean over kPhases start positions within one cell
// (runTerrainFeeAveraged): one push's F0 moves by up to +-1.5 N with a 5 mm shift of the start (the force comes
// in pulses as batches of particles are made), which moved one series' exponent by +-0.6 (45 degrees, w 0.2 m:
// 1.6-2.9 over four starts). Measured with the phases averaged: 2.12, 1.92 (45 degrees), 1.68, 1.62 (60 degrees;
// 1.71, 1.63 with 8 phases). The 60 degree series sit near the bound's edge: F0 / FEE falls with d there (0.83,
// 0.70, 0.63 at w 0.2 m) because the blade's friction is less mobilised in deeper cuts (the force's
// vertical-to-horizontal ratio gives an effective soil-blade friction angle of 6-8 degrees at 3 cm, 3-4 at 5
// and 7 cm, against 9-11 at 45 degrees; FEE assumes the full 20), docs/terrain.md.
TEST_CASE("FEE digging-force study: fitted exponent of d is 2 +- 0.4") {
  const Study& s = study();
  for (int a = 0; a < 2; ++a)
    for (int k = 0; k < 2; ++k) {
      const Real e = depthExponent(s.force0[a][k]);
      MESSAGE("rake " << kRakes[a] << ", w " << kWidths[k] << ": exponent of F0 " << e << ", of the window mean "
                      << depthExponent(s.force[a][k]));
      CHECK_MESSAGE(std::abs(e - 2) <= 0.4, "rake " << kRakes[a] << ", w " << kWidths[k] << ": exponent " << e);
    }
}

// The failure wedge's geometry (terrain.h, "The failure wedge"), one step of a resting blade: ahead of the lead
// the ground is lowered to the plane rising at beta* from the box's lowest point at the lead's front, and left
// alone beyond it; the ledger holds; with the option off nothing ahead of the lead is touched.
TEST_CASE("failure wedge: the cut follows the FEE failure plane ahead of the lead") {
  for (const bool on : {false, true}) {
    TestWorld w(1.0 / 100, 9.81, 0.7);
    w.material->setFrictionCoefficient(0.7);
    TerrainRef t = addFlatTerrain(w, 51, 1.0);  // 0.02 m cells, surface at z = 0, x and y in [-0.5, 0.5]
    t->getParticleAttributes().setParticleRadius(0.01);
    t->setShovelFailureWedge(on);
    CHECK(t->getShovelFailureWedge() == on);
    auto steel = std::make_shared<Material>("blade");
    steel->setFrictionCoefficient(0.19);
    w.sim->getMaterialManager().getOrCreateContactMaterial(steel, w.material)->setFrictionCoefficient(0.364);
    const Real rake = 60 * kPi / 180, d = 0.05, len = 0.4, width = 0.2, thick = 0.002;
    auto body = std::make_shared<RigidBody>("blade");
    auto blade = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.5 * len, 0.5 * width, 0.5 * thick)), "blade");
    blade->setMaterial(steel);
    blade->getPropertyContainer().addPropertyVec3(Terrain::ShovelUpProperty, Vec3(0, 0, thick));
    blade->getPropertyContainer().addPropertyVec3(Terrain::ShovelForwardProperty, Vec3(0.5 * len, 0, 0));
    body->add(blade);
    body->setMotionControl(RigidBody::KINEMATICS);
    const Quat q(Eigen::AngleAxis<Real>(rake, Vec3::UnitY()));
    const Vec3 tip(-0.2, 0, -d);
    body->setRotation(q);
    body->setPosition(tip - q * Vec3(0.5 * len, 0, 0));
    w.sim->add(body);
    const Real total0 = t->getVolumeLedger().total();
    w.sim->stepForward();
    CHECK(std::abs(t->getVolumeLedger().total() - total0) <= 1e-9 * total0);
    blade->updateTransform();
    const Real low = blade->getBoundingBox().lo.z();
    const Real lead = 0.02 + 2 * 0.01;
    const Real beta = Terrain::failureWedgeAngle(rake, std::atan(0.7), std::atan(0.364));
    const HeightField& hf = *t->getHeightField();
    int checked = 0, lowered = 0;
    for (size_t i = 0; i < 51; ++i) {
      const Real x = -0.5 + 0.02 * Real(i), xi = x - tip.x();
      if (!(xi > lead + 1e-9)) continue;  // the wedge region only (the box and lead are the plain cut's)
      const size_t j = 25;                  // y = 0, the blade's middle
      const Real z = hf.getHeight(i, j) - 0.5;  // the field sits at z = -0.5 (addFlatTerrain)
      const Real expect = on ? std::min<Real>(0, low + (xi - lead) * std::tan(beta)) : 0;
      CHECK_MESSAGE(z == doctest::Approx(expect).epsilon(1e-12), "x " << x << ": z " << z << ", expected " << expect);
      ++checked;
      if (expect < 0) ++lowered;
    }
    CHECK(checked > 10);
    if (on) CHECK(lowered >= 3);  // d cot(beta*) = 9.4 cm: the wedge spans several cells
    if (on) CHECK(t->getLastStepDigStats().particlesCreated > 0);
  }
}
