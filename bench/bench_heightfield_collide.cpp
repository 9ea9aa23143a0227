// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Narrowphase cost of shapes against a HeightField (collide/src/heightfield_collide.cpp): ns per call of
// collideGeometries for one shape-height-field pair, one thread. Each case cycles through 64 poses (a wheel rolling
// along x over the cells, the axis turned by the case's angle relative to the grid) so the cost is averaged over
// the positions within a cell. Counters: points = mean contact points per call.
//
// Cases (field 0.1 m cells, as in the terrain_vehicle scene):
//   cylinder_lying_flat/A   tire-sized cylinder (r 0.35 m, width 0.2 m) lying on a flat field, 1 cm deep,
//                           axis at A degrees to the grid's y axis
//   cylinder_lying_bumpy/A  the same on a field of 2 cm sine bumps (every join non-flat), 1 cm below the top
//   cylinder_lying_ramp     wheel r 0.1 m, width 0.1 m on a 20 degree ramp, axis at 30 degrees to the grid
//   cylinder_upright_flat   the tire standing on its cap on the flat field, 1 cm deep
//   sphere_flat             sphere r 0.35 m, 1 cm deep (the exact sphere path, for scale)
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <vector>

#include <scree/scree.h>

using namespace scree;

namespace {

constexpr Real kPi = 3.14159265358979323846;

std::shared_ptr<Geometry> makeField(Real (*height)(Real, Real)) {
  const size_t n = 101;
  const Real size = 10.0;
  auto hf = std::make_shared<HeightField>(n, n, size, size);
  std::vector<Real> h(n * n);
  for (size_t j = 0; j < n; ++j)
    for (size_t i = 0; i < n; ++i)
      h[j * n + i] = height(-size / 2 + Real(i) * size / Real(n - 1), -size / 2 + Real(j) * size / Real(n - 1));
  hf->setHeights(h);
  return std::make_shared<Geometry>(hf);
}

Real flatH(Real, Real) { return 0; }
Real bumpyH(Real x, Real y) { return 0.01 * (std::sin(7.3 * x) * std::cos(5.9 * y) + 1); }
Real rampH(Real x, Real) { return -std::tan(20 * kPi / 180) * x; }

/// Poses of a shape moved along a line over the field: 64 steps of 3.7 mm, so all positions within a cell occur.
void runPairs(benchmark::State& state, const std::shared_ptr<Geometry>& field, const std::shared_ptr<Geometry>& shape,
              const Quat& q, Real (*height)(Real, Real), Real centreAbove, const Vec3& dir) {
  std::vector<Transform> poses;
  for (int k = 0; k < 64; ++k) {
    const Vec3 xy = Vec3(0.013, 0.021, 0) + dir * (0.0037 * k);
    poses.push_back({Vec3(xy.x(), xy.y(), height(xy.x(), xy.y()) + centreAbove), q});
  }
  std::vector<ContactPoint> out;
  out.reserve(64);
  size_t k = 0, points = 0, calls = 0;
  for (auto _ : state) {
    shape->setPosition(poses[k].p);
    shape->setRotation(poses[k].q);
    k = (k + 1) & 63;
    out.clear();
    points += size_t(collideGeometries(*shape, *field, 0.01, out));
    ++calls;
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["points"] = double(points) / double(calls);
}

/// Cylinder lying with its axis (local y) horizontal at `deg` degrees to the grid's y axis.
Quat lying(Real deg) {
  return Quat(Eigen::AngleAxis<Real>(deg * kPi / 180, Vec3::UnitZ()));
}

void BM_cylinder_lying_flat(benchmark::State& state) {
  const Real deg = Real(state.range(0));
  auto field = makeField(flatH);
  auto cyl = std::make_shared<Geometry>(std::make_shared<Cylinder>(0.35, 0.2));
  const Quat q = lying(deg);
  runPairs(state, field, cyl, q, flatH, 0.34, q * Vec3::UnitX());
}
BENCHMARK(BM_cylinder_lying_flat)->Arg(0)->Arg(30);

void BM_cylinder_lying_bumpy(benchmark::State& state) {
  const Real deg = Real(state.range(0));
  auto field = makeField(bumpyH);
  auto cyl = std::make_shared<Geometry>(std::make_shared<Cylinder>(0.35, 0.2));
  const Quat q = lying(deg);
  runPairs(state, field, cyl, q, [](Real, Real) { return Real(0.02); }, 0.34, q * Vec3::UnitX());
}
BENCHMARK(BM_cylinder_lying_bumpy)->Arg(0)->Arg(30);

void BM_cylinder_lying_ramp(benchmark::State& state) {
  auto field = makeField(rampH);
  auto cyl = std::make_shared<Geometry>(std::make_shared<Cylinder>(0.1, 0.1));
  // Axis horizontal at 30 degrees to the grid; the centre 0.099 m above the slope along its normal.
  const Real a = 20 * kPi / 180;
  const Quat q = Quat(Eigen::AngleAxis<Real>(a, Vec3::UnitY())) * lying(30);
  const Real above = 0.099 / std::cos(a);
  runPairs(state, field, cyl, q, rampH, above, Vec3(1, 0.4, 0).normalized());
}
BENCHMARK(BM_cylinder_lying_ramp);

void BM_cylinder_upright_flat(benchmark::State& state) {
  auto field = makeField(flatH);
  auto cyl = std::make_shared<Geometry>(std::make_shared<Cylinder>(0.35, 0.2));
  const Quat q(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitX()));
  runPairs(state, field, cyl, q, flatH, 0.09, Vec3(1, 0.4, 0).normalized());
}
BENCHMARK(BM_cylinder_upright_flat);

void BM_sphere_flat(benchmark::State& state) {
  auto field = makeField(flatH);
  auto s = std::make_shared<Geometry>(std::make_shared<Sphere>(0.35));
  runPairs(state, field, s, Quat::Identity(), flatH, 0.34, Vec3(1, 0.4, 0).normalized());
}
BENCHMARK(BM_sphere_flat);

}  // namespace

BENCHMARK_MAIN();
