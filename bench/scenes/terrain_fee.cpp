// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scenes/terrain_fee.h"

#include <algorithm>
#include <cmath>

namespace scree::scenes {

namespace {
constexpr Real kHalfPi = 1.57079632679489661923;
/// F / (w gamma d^2) = N_gamma + r N_q at failure angle beta (+inf outside the admissible range).
Real feeScaledForce(Real alpha, Real phi, Real delta, Real r, Real beta) {
  const Real D = std::cos(alpha + delta) + std::sin(alpha + delta) / std::tan(beta + phi);
  if (!(D > 0)) return INFINITY;
  const Real c = 1 / std::tan(alpha) + 1 / std::tan(beta);
  return c / (2 * D) + r * c / D;
}
}  // namespace

FeeFactors feeFactors(Real alpha, Real phi, Real delta, Real r) {
  // Golden-section search on (0, pi/2 - phi): the force is unimodal in beta there.
  Real a = 1e-6, b = kHalfPi - phi - 1e-6;
  const Real g = 0.5 * (std::sqrt(5.0) - 1);
  Real x1 = b - g * (b - a), x2 = a + g * (b - a);
  Real f1 = feeScaledForce(alpha, phi, delta, r, x1), f2 = feeScaledForce(alpha, phi, delta, r, x2);
  while (b - a > 1e-9) {
    if (f1 < f2) {
      b = x2, x2 = x1, f2 = f1;
      x1 = b - g * (b - a);
      f1 = feeScaledForce(alpha, phi, delta, r, x1);
    } else {
      a = x1, x1 = x2, f1 = f2;
      x2 = a + g * (b - a);
      f2 = feeScaledForce(alpha, phi, delta, r, x2);
    }
  }
  FeeFactors out;
  out.beta = 0.5 * (a + b);
  const Real D = std::cos(alpha + delta) + std::sin(alpha + delta) / std::tan(out.beta + phi);
  const Real c = 1 / std::tan(alpha) + 1 / std::tan(out.beta);
  out.nGamma = c / (2 * D);
  out.nQ = c / D;
  return out;
}

Real feeHorizontalForce(Real alpha, Real phi, Real delta, Real gamma, Real d, Real w, Real q) {
  const FeeFactors f = feeFactors(alpha, phi, delta, q / (gamma * d));
  return w * (gamma * d * d * f.nGamma + q * d * f.nQ) * std::sin(alpha + delta);
}

TerrainFeeResult runTerrainFee(const TerrainFeeParams& p) {
  Scene s;
  initScene(s, "terrain_fee", p.soilFriction, p.dt, 0);
  s.sim->getSolver().setNumIterations(p.iterations);
  auto soil = s.material;
  soil->setDensity(p.density);
  soil->setFrictionCoefficient(p.soilFriction);
  soil->setRollingResistanceCoefficient(p.rollingResistance);
  soil->setYoungsModulus(p.youngsModulus);
  s.contactMaterial->setYoungsModulus(p.youngsModulus);
  s.contactMaterial->setRollingResistanceCoefficient(p.rollingResistance);

  // Terrain: 2 m along x, 1 m across, 0.5 m of soil, surface at z = 0.
  const Real sx = 2.0, sy = 1.0, thickness = 0.5;
  const size_t nx = size_t(std::lround(sx / p.cell)) + 1, ny = size_t(std::lround(sy / p.cell)) + 1;
  auto hf = std::make_shared<HeightField>(nx, ny, sx, sy);
  hf->setHeights(std::vector<Real>(nx * ny, thickness));
  auto terrain = std::make_shared<Terrain>(hf);
  terrain->getGeometry()->setMaterial(soil);
  terrain->getGeometry()->setPosition(Vec3(0, 0, -thickness));
  s.sim->add(terrain);
  terrain->getDataInterface().add(soil, 0, 0.0, 0.0);  // non-deformable: no compression under the heap
  terrain->getParticleAttributes().setParticleRadius(p.radius);
  terrain->setShovelFailureWedge(p.failureWedge);

  // The blade: a plate, local +x down its slope to the cutting edge, local +z its soil-facing normal. Rotated by
  // alpha about +y, local x -> (cos alpha, 0, -sin alpha), local z -> (sin alpha, 0, cos alpha): it leans back by
  // pi/2 - alpha and faces +x. Blade-soil friction tan(delta): the blade material's mu combines with the soil's as
  // sqrt(mu_blade mu_soil) (the particles' materials copy the soil's), so mu_blade = tan(delta)^2 / mu_soil.
  auto steel = std::make_shared<Material>("blade");
  steel->setFrictionCoefficient(p.bladeFriction * p.bladeFriction / p.soilFriction);
  steel->setRestitution(0);
  steel->setYoungsModulus(p.youngsModulus);
  auto bs = s.sim->getMaterialManager().getOrCreateContactMaterial(steel, soil);
  bs->setFrictionCoefficient(p.bladeFriction);
  bs->setRestitution(0);
  bs->setYoungsModulus(p.youngsModulus);
  auto body = std::make_shared<RigidBody>("blade");
  auto blade = std::make_shared<Geometry>(
      std::make_shared<Box>(Vec3(0.5 * p.bladeLength, 0.5 * p.width, 0.5 * p.bladeThickness)), "blade");
  blade->setMaterial(steel);
  blade->getPropertyContainer().addPropertyVec3(Terrain::ShovelUpProperty, Vec3(0, 0, p.bladeThickness));
  blade->getPropertyContainer().addPropertyVec3(Terrain::ShovelForwardProperty, Vec3(0.5 * p.bladeLength, 0, 0));
  body->add(blade);
  body->setMotionControl(RigidBody::KINEMATICS);
  const Quat q(Eigen::AngleAxis<Real>(p.rake, Vec3::UnitY()));
  const Vec3 tip0(p.start, 0, -p.depth);
  body->setRotation(q);
  body->setPosition(tip0 - q * Vec3(0.5 * p.bladeLength, 0, 0));
  s.sim->add(body);
  body->setVelocity(Vec3(p.speed, 0, 0));

  TerrainFeeResult out;
  const Real total0 = terrain->getVolumeLedger().total();
  const int steps = int(std::lround(p.travel / p.speed / p.dt));
  const GranularBodySystem& gbs = s.sim->getGranularBodySystem();
  Real sumF = 0, sumH = 0, sumV = 0;
  int nWin = 0;
  for (int i = 0; i < steps; ++i) {
    s.sim->stepForward();
    const TerrainShovelStats st = terrain->getShovelStats(*blade);
    TerrainFeeSample smp;
    smp.travel = (i + 1) * p.dt * p.speed;
    smp.force = -st.diggingForce().x();
    smp.vertical = st.diggingForce().z();
    const Real tipX = tip0.x() + smp.travel;
    for (size_t id : terrain->getParticleIds()) {
      const Vec3 x = gbs.getPosition(id);
      if (x.x() > tipX - p.bladeLength && x.x() < tipX + p.bladeLength && std::abs(x.y()) < 0.5 * p.width)
        smp.heapHeight = std::max(smp.heapHeight, x.z() + p.radius);
    }
    smp.particles = gbs.numParticles();
    smp.soilVolume = terrain->getVolumeLedger().particles;
    out.ledgerDrift = std::max(out.ledgerDrift, std::abs(terrain->getVolumeLedger().total() - total0) / total0);
    if (smp.travel > 0.5 * p.travel) {
      sumF += smp.force;
      sumH += smp.heapHeight;
      sumV += smp.soilVolume;
      ++nWin;
    }
    out.samples.push_back(smp);
  }
  out.meanForce = nWin ? sumF / nWin : 0;
  out.meanHeapHeight = nWin ? sumH / nWin : 0;
  out.meanSoilVolume = nWin ? sumV / nWin : 0;
  {
    Real n = 0, ms = 0, mf = 0;
    for (const TerrainFeeSample& x : out.samples)
      if (x.travel > 0.05) n += 1, ms += x.travel, mf += x.force;
    if (n > 1) {
      ms /= n, mf /= n;
      Real sxy = 0, sxx = 0;
      for (const TerrainFeeSample& x : out.samples)
        if (x.travel > 0.05) sxy += (x.travel - ms) * (x.force - mf), sxx += (x.travel - ms) * (x.travel - ms);
      out.pileSlope = sxx > 0 ? sxy / sxx : 0;
      out.force0 = mf - out.pileSlope * ms;
    }
  }
  return out;
}

TerrainFeeResult runTerrainFeeAveraged(const TerrainFeeParams& p, int phases) {
  if (phases < 1) phases = 1;
  TerrainFeeResult out;
  for (int k = 0; k < phases; ++k) {
    TerrainFeeParams q = p;
    q.start = p.start + p.cell * Real(k) / Real(phases);
    const TerrainFeeResult r = runTerrainFee(q);
    if (k == 0) {
      out.samples = r.samples;
    } else {
      for (size_t i = 0; i < out.samples.size() && i < r.samples.size(); ++i) {
        TerrainFeeSample& a = out.samples[i];
        const TerrainFeeSample& b = r.samples[i];
        a.force += b.force, a.vertical += b.vertical, a.heapHeight += b.heapHeight, a.soilVolume += b.soilVolume;
        a.particles += b.particles;
      }
    }
    out.meanForce += r.meanForce / phases;
    out.meanHeapHeight += r.meanHeapHeight / phases;
    out.meanSoilVolume += r.meanSoilVolume / phases;
    out.force0 += r.force0 / phases;
    out.pileSlope += r.pileSlope / phases;
    out.ledgerDrift = std::max(out.ledgerDrift, r.ledgerDrift);
  }
  for (TerrainFeeSample& a : out.samples) {
    a.force /= phases, a.vertical /= phases, a.heapHeight /= phases, a.soilVolume /= phases;
    a.particles = size_t(std::lround(Real(a.particles) / phases));
  }
  return out;
}

}  // namespace scree::scenes
