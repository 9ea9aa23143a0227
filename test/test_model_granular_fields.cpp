// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// GranularFieldPostProcessor (manual §25.3): mass conservation, exact partial weights (corner 1/8, face 1/2,
// boundary fractions, Monte Carlo), momentum and velocity of a translating cloud, custom buffers, solid volume
// fraction and kinetic stress against closed forms, the documented layout and placement, determinism over
// thread counts, export files and the step listener. Particles are created in a GranularBodySystem without
// stepping, so these tests do not depend on the particle solver (except the listener case).
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#ifdef SCREE_WITH_OPENMP
#include <omp.h>
#endif

#include "scree/core/granular_body_system.h"
#include "scree/core/logger.h"
#include "scree/core/material.h"
#include "scree/model/granular_field_post_processor.h"
#include "scree/solver/simulation.h"

using namespace scree;

namespace {

constexpr Real kPi = std::numbers::pi_v<Real>;

Real ballVol(Real r) { return 4.0 / 3.0 * kPi * r * r * r; }
/// Cap of height hc of a ball of radius r.
Real capVol(Real r, Real hc) { return kPi * hc * hc * (3 * r - hc) / 3; }

Real sum(const GranularField& f, int component = 0) {
  Real s = 0;
  const size_t nc = size_t(f.getNumComponents());
  for (size_t v = 0; v < f.getDataSize() / nc; ++v) s += f.getFieldData()[v * nc + size_t(component)];
  return s;
}

/// A system whose particles have density 2500 kg/m^3.
struct Cloud {
  GranularBodySystem gbs;
  Cloud() {
    auto m = std::make_shared<Material>("sand");
    m->setDensity(2500);
    gbs.setMaterial(m);
  }
};

}  // namespace

TEST_SUITE("model.granular_fields") {

TEST_CASE("the mass field sums to the mass of the particles inside the volume") {
  Cloud c;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<Real> u(-0.5, 0.5), rad(0.005, 0.02);
  // Cuboid 1 x 0.8 x 0.6 m in 20 x 16 x 12 voxels of 0.05 m (>= the largest diameter 0.04 m).
  GranularFieldPostProcessor gpp(c.gbs, {20, 16, 12}, Vec3(1.0, 0.8, 0.6));
  auto massField = gpp.addField(std::make_shared<GranularMassField>());
  Real insideMass = 0;
  for (int p = 0; p < 3000; ++p) {
    const Real r = rad(rng);
    const Vec3 x(u(rng) * (1.0 - 2 * r), u(rng) * (0.8 - 2 * r), u(rng) * (0.6 - 2 * r));  // fully inside
    insideMass += c.gbs.getMass(c.gbs.createParticle(x, r));
  }
  for (int p = 0; p < 300; ++p)  // fully outside: ignored
    c.gbs.createParticle(Vec3(0.53 + 0.4 * std::abs(u(rng)), u(rng), u(rng)), 0.02);
  gpp.calculateFields();
  CHECK(gpp.getNumParticlesInside() == 3000);
  // Each interior particle's weights sum to 1 up to a few ulp (the split pieces are an inclusion–exclusion of
  // O(1) terms), so the total is exact to ~1e-15 relative; 1e-12 is the bound.
  const Real err = std::abs(sum(*massField) - insideMass) / insideMass;
  MESSAGE("mass conservation, relative error: " << err);
  CHECK(err < 1e-12);
}

TEST_CASE("a particle straddling the boundary contributes exactly its inside fraction") {
  Cloud c;
  GranularFieldPostProcessor gpp(c.gbs, {4, 4, 4}, Vec3(1, 1, 1));
  gpp.addField(GranularField::MASS);
  const Real r = 0.1;
  // Centre 0.04 m inside the +x face: the outside part is a cap of height r - 0.04.
  const size_t a = c.gbs.createParticle(Vec3(0.46, 0.1, -0.2), r);
  gpp.calculateFields();
  const Real m = c.gbs.getMass(a);
  const Real expectA = m * (1 - capVol(r, r - 0.04) / ballVol(r));
  CHECK(sum(*gpp.getField(GranularField::MASS)) == doctest::Approx(expectA).epsilon(1e-13));
  // Centred on the +x face: half; on the cuboid's corner: an eighth.
  c.gbs.destroyParticle(a);
  c.gbs.createParticle(Vec3(0.5, 0.1, -0.2), r);
  gpp.calculateFields();
  CHECK(sum(*gpp.getField("mass")) == doctest::Approx(0.5 * m).epsilon(1e-14));
  c.gbs.clear();
  c.gbs.createParticle(Vec3(-0.5, 0.5, -0.5), r);
  gpp.calculateFields();
  CHECK(sum(*gpp.getField("mass")) == doctest::Approx(0.125 * m).epsilon(1e-14));
  CHECK(gpp.getField("mass")->getValue(0, 3, 0) == doctest::Approx(0.125 * m).epsilon(1e-14));
}

TEST_CASE("a particle on a voxel corner gives 1/8 to each of its eight voxels, on a face 1/2 to each of two") {
  Cloud c;
  GranularFieldPostProcessor gpp(c.gbs, {4, 4, 4}, Vec3(2, 2, 2));  // voxels 0.5 m, corners at -1, -0.5, 0, ...
  auto mass = gpp.addField(GranularField::MASS);
  const Real r = 0.2;
  const size_t id = c.gbs.createParticle(Vec3(0, 0.5, -0.5), r);  // corner shared by voxels i 1..2, j 2..3, k 0..1
  const Real m = c.gbs.getMass(id);
  gpp.calculateFields();
  // Octant volumes come from the closed form at offsets 0: pi r^3/6 up to rounding.
  for (size_t k = 0; k < 4; ++k)
    for (size_t j = 0; j < 4; ++j)
      for (size_t i = 0; i < 4; ++i) {
        const bool touched = (i == 1 || i == 2) && (j == 2 || j == 3) && (k == 0 || k == 1);
        CHECK(mass->getValue(i, j, k) == doctest::Approx(touched ? m / 8 : 0.0).epsilon(1e-14).scale(m));
      }
  c.gbs.setPosition(id, Vec3(0.25, -0.25, 0.0));  // on the face between voxels (2,1,1) and (2,1,2)
  gpp.calculateFields();
  CHECK(mass->getValue(2, 1, 1) == doctest::Approx(m / 2).epsilon(1e-14));
  CHECK(mass->getValue(2, 1, 2) == doctest::Approx(m / 2).epsilon(1e-14));
  CHECK(sum(*mass) == doctest::Approx(m).epsilon(1e-14));
}

TEST_CASE("weights at random positions match a Monte Carlo estimate") {
  Cloud c;
  GranularFieldPostProcessor gpp(c.gbs, {5, 5, 5}, Vec3(1, 1, 1));  // voxel 0.2 m
  auto mass = gpp.addField(GranularField::MASS);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<Real> u(-0.4, 0.4), unit(-1, 1);
  const Real r = 0.09;
  const int samples = 200000;
  Real worst = 0;
  for (int trial = 0; trial < 6; ++trial) {
    c.gbs.clear();
    const Vec3 x(u(rng), u(rng), u(rng));
    const size_t id = c.gbs.createParticle(x, r);
    const Real m = c.gbs.getMass(id);
    gpp.calculateFields();
    // Uniform points in the ball by rejection, binned into voxels.
    std::vector<Real> hist(125, 0);
    int accepted = 0;
    while (accepted < samples) {
      const Vec3 s(unit(rng), unit(rng), unit(rng));
      if (s.squaredNorm() > 1) continue;
      ++accepted;
      const Vec3 q = x + r * s + Vec3::Constant(0.5);
      const int i = int(std::floor(q.x() / 0.2)), j = int(std::floor(q.y() / 0.2)), k = int(std::floor(q.z() / 0.2));
      if (i >= 0 && i < 5 && j >= 0 && j < 5 && k >= 0 && k < 5) hist[size_t(i + 5 * (j + 5 * k))] += 1;
    }
    for (size_t v = 0; v < 125; ++v) {
      const Real mc = hist[v] / samples, w = mass->getFieldData()[v] / m;
      worst = std::max(worst, std::abs(mc - w));
      // 0.5 % of the particle: the standard error of a binned fraction is <= sqrt(0.25/2e5) = 0.0011, so the
      // bound is >= 4.5 sigma (false alarm < 1e-5 per voxel).
      CHECK(std::abs(mc - w) < 0.005);
    }
  }
  MESSAGE("largest |weight - Monte Carlo| over 6 particles: " << worst);
}

TEST_CASE("a rigidly translating cloud gives a uniform velocity field and momentum sum m v") {
  Cloud c;
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<Real> u(-0.45, 0.45), rad(0.01, 0.025);
  GranularFieldPostProcessor gpp(c.gbs, {10, 10, 10}, Vec3(1, 1, 1));
  gpp.addField(std::make_shared<GranularVelocityField>());  // adds mass and momentum
  CHECK(gpp.hasField(GranularField::MASS));
  CHECK(gpp.hasField(GranularField::MOMENTUM));
  const Vec3 vel(1.5, -0.3, 2.25);
  Vec3 p = Vec3::Zero();
  for (int i = 0; i < 2000; ++i) {
    const size_t id = c.gbs.createParticle(Vec3(u(rng), u(rng), u(rng)), rad(rng), vel);
    p += c.gbs.getMass(id) * vel;
  }
  gpp.calculateFields();
  const GranularField& velocity = *gpp.getField(GranularField::VELOCITY);
  const GranularField& mass = *gpp.getField(GranularField::MASS);
  int filled = 0;
  for (size_t v = 0; v < gpp.getNumVoxels(); ++v) {
    if (mass.getFieldData()[v] <= 0) continue;
    ++filled;
    for (int a = 0; a < 3; ++a)  // p/m of sums of the same m w terms times v: a few ulp
      CHECK(velocity.getFieldData()[3 * v + size_t(a)] == doctest::Approx(vel[a]).epsilon(1e-13));
  }
  CHECK(filled > 900);
  const GranularField& momentum = *gpp.getField("momentum");
  for (int a = 0; a < 3; ++a) CHECK(sum(momentum, a) == doctest::Approx(p[a]).epsilon(1e-12));
}

TEST_CASE("momentum sums to sum m v of the interior particles for random velocities") {
  Cloud c;
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<Real> u(-0.45, 0.45), vu(-3, 3);
  GranularFieldPostProcessor gpp(c.gbs, {8, 8, 8}, Vec3(1, 1, 1));
  auto momentum = gpp.addField(GranularField::MOMENTUM);
  Vec3 p = Vec3::Zero();
  for (int i = 0; i < 1000; ++i) {
    const Vec3 v(vu(rng), vu(rng), vu(rng));
    const size_t id = c.gbs.createParticle(Vec3(u(rng), u(rng), u(rng)), 0.02, v);
    p += c.gbs.getMass(id) * v;
  }
  gpp.calculateFields();
  // Cancellation between +- velocities: compare against the scale sum m |v| <= M * 3 sqrt(3).
  const Real scale = c.gbs.getTotalMass() * 3 * std::sqrt(3.0);
  for (int a = 0; a < 3; ++a) CHECK(std::abs(sum(*momentum, a) - p[a]) < 1e-12 * scale);
  // Velocity was not requested: no mass field either.
  CHECK_FALSE(gpp.hasField(GranularField::MASS));
}

TEST_CASE("a custom concentration buffer gives the weighted sum; an unknown name is a clear error") {
  Cloud c;
  c.gbs.addCustomBufferReal("concentration");
  GranularFieldPostProcessor gpp(c.gbs, {4, 4, 4}, Vec3(2, 2, 2));
  auto conc = gpp.addField(std::make_shared<GranularCustomBufferField>("concentration"));
  CHECK(gpp.getField(GranularField::CUSTOM) == conc);
  // One particle on a voxel corner (1/8 each), one inside voxel (0,0,0) (all of it).
  const size_t a = c.gbs.createParticle(Vec3(0, 0, 0), 0.2);
  const size_t b = c.gbs.createParticle(Vec3(-0.75, -0.75, -0.75), 0.1);
  c.gbs.setCustomReal("concentration", a, 0.8);
  c.gbs.setCustomReal("concentration", b, 0.3);
  gpp.calculateFields();
  CHECK(conc->getValue(1, 1, 1) == doctest::Approx(0.1).epsilon(1e-14));
  CHECK(conc->getValue(2, 2, 2) == doctest::Approx(0.1).epsilon(1e-14));
  CHECK(conc->getValue(0, 0, 0) == doctest::Approx(0.3).epsilon(1e-15));
  CHECK(sum(*conc) == doctest::Approx(1.1).epsilon(1e-14));
  CHECK(gpp.getField("concentration") == conc);
  try {
    gpp.getField("temperature");
    FAIL("no exception");
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    CHECK(what.find("temperature") != std::string::npos);
    CHECK(what.find("concentration") != std::string::npos);  // lists what exists
  }
  CHECK_THROWS_AS(gpp.getField(GranularField::VELOCITY), std::invalid_argument);
}

TEST_CASE("solid volume fraction of a simple cubic packing is pi/6") {
  Cloud c;
  // One sphere of diameter = voxel side per voxel, centred: each voxel is filled to pi/6 (the simple cubic
  // packing fraction) exactly, the boundary voxels too.
  const Real side = 0.1;
  GranularFieldPostProcessor gpp(c.gbs, {6, 5, 4}, Vec3(0.6, 0.5, 0.4));
  auto phi = gpp.addField(GranularField::SOLID_VOLUME_FRACTION);
  for (size_t k = 0; k < 4; ++k)
    for (size_t j = 0; j < 5; ++j)
      for (size_t i = 0; i < 6; ++i) c.gbs.createParticle(gpp.getVoxelCenter(i, j, k), side / 2);
  gpp.calculateFields();
  for (size_t v = 0; v < gpp.getNumVoxels(); ++v) CHECK(phi->getFieldData()[v] == doctest::Approx(kPi / 6).epsilon(1e-13));
  // Shift the lattice by half a voxel along x: every interior voxel still holds pi/6 (two halves), the first
  // column half of it.
  for (size_t id : c.gbs.getParticleIds()) c.gbs.setPosition(id, c.gbs.getPosition(id) + Vec3(side / 2, 0, 0));
  gpp.calculateFields();
  CHECK(phi->getValue(0, 2, 1) == doctest::Approx(kPi / 12).epsilon(1e-13));
  CHECK(phi->getValue(3, 2, 1) == doctest::Approx(kPi / 6).epsilon(1e-13));
}

TEST_CASE("kinetic stress: zero for rigid motion, sum m u^2 / V for counter-moving particles") {
  Cloud c;
  GranularFieldPostProcessor gpp(c.gbs, {2, 2, 2}, Vec3(1, 1, 1));
  auto stress = gpp.addField(GranularField::KINETIC_STRESS);
  CHECK(gpp.hasField(GranularField::VELOCITY));
  const Real u = 2.0, r = 0.05;
  // Voxel (0,0,0) spans [-0.5, 0]^3: two equal particles inside it moving at +-u along x, plus rigid motion
  // w. The fluctuation about the voxel's mean velocity is +-u x: s_xx = 2 m u^2 / V_vox, all else 0.
  const Vec3 w(0.7, -1.1, 0.4);
  const size_t a = c.gbs.createParticle(Vec3(-0.3, -0.3, -0.3), r, w + Vec3(u, 0, 0));
  c.gbs.createParticle(Vec3(-0.15, -0.35, -0.2), r, w - Vec3(u, 0, 0));
  // Voxel (1,1,1): a rigidly moving group.
  for (int i = 0; i < 4; ++i) c.gbs.createParticle(Vec3(0.1 + 0.1 * i, 0.25, 0.25), r, w);
  gpp.calculateFields();
  const Real m = c.gbs.getMass(a), Vvox = 0.125;
  const Real sxx = 2 * m * u * u / Vvox;
  // Second moment minus m vbar vbar^T: cancellation of terms of size m |w + u|^2, so ~1e-15 of that.
  const Real tol = 1e-12 * sxx;
  CHECK(std::abs(stress->getValue(0, 0, 0, 0) - sxx) < tol);
  for (int comp = 1; comp < 6; ++comp) CHECK(std::abs(stress->getValue(0, 0, 0, comp)) < tol);
  for (int comp = 0; comp < 6; ++comp) CHECK(std::abs(stress->getValue(1, 1, 1, comp)) < tol);
}

TEST_CASE("layout: x fastest, components adjacent; placement by a rotated transform") {
  Cloud c;
  GranularFieldPostProcessor gpp(c.gbs, {4, 3, 5}, Vec3(0.4, 0.3, 0.5));  // voxel 0.1 m
  auto velocity = gpp.addField(GranularField::VELOCITY);
  auto mass = gpp.getField(GranularField::MASS);
  CHECK(mass->getDataSize() == 60);
  CHECK(velocity->getDataSize() == 180);
  CHECK(gpp.voxelIndex(2, 1, 3) == 2 + 4 * (1 + 3 * 3));
  const size_t id = c.gbs.createParticle(gpp.getVoxelCenter(2, 1, 3), 0.03, Vec3(1, 2, 3));
  gpp.calculateFields();
  const Real m = c.gbs.getMass(id);
  const size_t v = 2 + 4 * (1 + 3 * 3);
  CHECK(mass->getFieldData()[v] == doctest::Approx(m).epsilon(1e-15));
  CHECK(velocity->getFieldData()[3 * v + 0] == doctest::Approx(1));
  CHECK(velocity->getFieldData()[3 * v + 1] == doctest::Approx(2));
  CHECK(velocity->getFieldData()[3 * v + 2] == doctest::Approx(3));
  CHECK(sum(*mass) == doctest::Approx(m).epsilon(1e-15));

  // Rotate the cuboid 90 degrees about z and move it: local +x is world +y.
  Transform t;
  t.p = Vec3(10, -3, 2);
  t.q = Quat(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitZ()));
  gpp.setTransform(t);
  // Local voxel (3, 0, 0) has centre (0.15, -0.1, -0.2) locally: world (10 + 0.1, -3 + 0.15, 2 - 0.2).
  const Vec3 centre = gpp.getVoxelCenter(3, 0, 0);
  CHECK((centre - Vec3(10.1, -2.85, 1.8)).norm() < 1e-12);
  c.gbs.setPosition(id, centre);
  gpp.calculateFields();
  CHECK(mass->getValue(3, 0, 0) == doctest::Approx(m).epsilon(1e-15));
  // Velocity components stay in world axes.
  CHECK(velocity->getValue(3, 0, 0, 1) == doctest::Approx(2));
}

TEST_CASE("fields are bit-identical on one and two threads") {
#ifdef SCREE_WITH_OPENMP
  Cloud c;
  c.gbs.addCustomBufferReal("temperature");
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<Real> u(-0.6, 0.6), vu(-1, 1);
  for (int i = 0; i < 20000; ++i) {
    const size_t id = c.gbs.createParticle(Vec3(u(rng), u(rng), u(rng)), 0.008, Vec3(vu(rng), vu(rng), vu(rng)));
    c.gbs.setCustomReal("temperature", id, 300 + 10 * vu(rng));
  }
  GranularFieldPostProcessor gpp(c.gbs, {32, 32, 32}, Vec3(1, 1, 1));
  gpp.addField(GranularField::KINETIC_STRESS);
  gpp.addField(GranularField::SOLID_VOLUME_FRACTION);
  gpp.addField(std::make_shared<GranularCustomBufferField>("temperature"));
  const int before = omp_get_max_threads();
  auto run = [&](int threads) {
    omp_set_num_threads(threads);
    gpp.calculateFields();
    std::vector<std::vector<Real>> out;
    for (const auto& f : gpp.getFields()) out.emplace_back(f->getFieldData(), f->getFieldData() + f->getDataSize());
    return out;
  };
  const auto one = run(1), two = run(2);
  omp_set_num_threads(before);
  REQUIRE(one.size() == 6);
  for (size_t f = 0; f < one.size(); ++f) CHECK(one[f] == two[f]);
#else
  MESSAGE("built without OpenMP: one thread only");
#endif
}

TEST_CASE("VTK image and CSV slice exports hold the field values") {
  Cloud c;
  GranularFieldPostProcessor gpp(c.gbs, {3, 2, 2}, Vec3(0.3, 0.2, 0.2));
  gpp.addField(GranularField::VELOCITY);
  const size_t id = c.gbs.createParticle(gpp.getVoxelCenter(1, 0, 1), 0.04, Vec3(0.5, 0, -1));
  gpp.calculateFields();
  const Real m = c.gbs.getMass(id);
  const std::string vti = "granular_fields_test.vti", csv = "granular_fields_test.csv";
  gpp.writeVti(vti);
  {
    std::ifstream in(vti);
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string text = ss.str();
    CHECK(text.find("<VTKFile type=\"ImageData\"") != std::string::npos);
    CHECK(text.find("WholeExtent=\"0 3 0 2 0 2\"") != std::string::npos);
    CHECK(text.find("Name=\"mass\" NumberOfComponents=\"1\"") != std::string::npos);
    CHECK(text.find("Name=\"velocity\" NumberOfComponents=\"3\"") != std::string::npos);
    // The mass array: 12 values, the 1 + 3 * (0 + 2 * 1) = 7th (0-based) is m.
    const size_t at = text.find("Name=\"mass\"");
    std::istringstream arr(text.substr(text.find('>', at) + 1));
    std::vector<Real> values(12);
    for (Real& x : values) arr >> x;
    CHECK(values[7] == doctest::Approx(m).epsilon(1e-15));
    CHECK(values[6] == 0.0);
  }
  gpp.writeCsvSlice(csv, 2, 1);  // the k = 1 layer: 3 x 2 rows
  {
    std::ifstream in(csv);
    std::string header, line;
    std::getline(in, header);
    CHECK(header == "i,j,k,x,y,z,mass,momentum_x,momentum_y,momentum_z,velocity_x,velocity_y,velocity_z");
    int rows = 0;
    bool found = false;
    while (std::getline(in, line)) {
      ++rows;
      if (line.rfind("1,0,1,", 0) == 0) {
        found = true;
        std::vector<Real> cols;
        std::stringstream ls(line);
        std::string cell;
        while (std::getline(ls, cell, ',')) cols.push_back(std::stod(cell));
        REQUIRE(cols.size() == 13);
        CHECK(cols[6] == doctest::Approx(m).epsilon(1e-15));
        CHECK(cols[10] == doctest::Approx(0.5));
        CHECK(cols[12] == doctest::Approx(-1));
      }
    }
    CHECK(rows == 6);
    CHECK(found);
  }
  std::remove(vti.c_str());
  std::remove(csv.c_str());
}

TEST_CASE("voxels smaller than the largest particle diameter are refused; fields stay unchanged") {
  Cloud c;
  GranularFieldPostProcessor gpp(c.gbs, {10, 10, 10}, Vec3(1, 1, 1));  // voxel 0.1 m
  auto mass = gpp.addField(GranularField::MASS);
  c.gbs.createParticle(Vec3(0, 0, 0), 0.05);  // diameter == voxel: allowed
  gpp.calculateFields();
  const std::vector<Real> before(mass->getFieldData(), mass->getFieldData() + mass->getDataSize());
  const size_t big = c.gbs.createParticle(Vec3(0.2, 0.2, 0.2), 0.06);
  try {
    gpp.calculateFields();
    FAIL("no exception");
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    CHECK(what.find("particle id " + std::to_string(big)) != std::string::npos);
    CHECK(what.find("diameter 0.12") != std::string::npos);
    CHECK(what.find("voxel side 0.1") != std::string::npos);
  }
  CHECK(std::vector<Real>(mass->getFieldData(), mass->getFieldData() + mass->getDataSize()) == before);
  CHECK(gpp.getNumCalculations() == 1);
  // A large particle outside the cuboid does not matter.
  c.gbs.setPosition(big, Vec3(3, 0, 0));
  CHECK_NOTHROW(gpp.calculateFields());
}

TEST_CASE("a step listener computes the fields every N steps") {
  Simulation sim;
  GranularBodySystem& gbs = sim.getGranularBodySystem();
  const size_t id = gbs.createParticle(Vec3(0, 0, 0.3), 0.02, Vec3(0.5, 0, -1));
  auto gpp = std::make_shared<GranularFieldPostProcessor>(gbs, GranularFieldPostProcessor::Shape{4, 4, 4}, Vec3(1, 1, 1));
  gpp->addField(GranularField::VELOCITY);
  std::vector<size_t> calls;
  sim.add(std::make_shared<GranularFieldStepListener>(gpp, 3, [&](const GranularFieldPostProcessor& g, size_t step) {
    calls.push_back(step);
    // The fields describe the particle as it is after this step (whatever the particle solver did to it).
    const Vec3 v = gbs.getVelocity(id);
    CHECK(sum(*g.getField("momentum"), 0) == doctest::Approx(gbs.getMass(id) * v.x()).epsilon(1e-12));
    CHECK(sum(*g.getField("momentum"), 2) == doctest::Approx(gbs.getMass(id) * v.z()).epsilon(1e-12));
  }));
  for (int s = 0; s < 7; ++s) sim.stepForward();
  CHECK(gpp->getNumCalculations() == 2);
  CHECK(calls == std::vector<size_t>{3, 6});
  // A particle too large for the voxels: the listener logs and skips, the step goes on.
  gbs.createParticle(Vec3(0.1, 0.1, 0.1), 0.2);
  std::vector<std::string> errors;
  Logger::setSink([&](LogLevel level, const std::string& m) {
    if (level == LogLevel::ERROR) errors.push_back(m);
  });
  for (int s = 0; s < 3; ++s) CHECK_NOTHROW(sim.stepForward());
  Logger::setSink({});
  CHECK(gpp->getNumCalculations() == 2);
  REQUIRE(errors.size() == 1);
  CHECK(errors[0].find("diameter 0.4") != std::string::npos);
}

}  // TEST_SUITE
