// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Narrowphase cost per pair type: ns per collideGeometries call (one thread), for resting configurations — the
// upper shape overlaps the lower by 1 mm and is tilted by 0.01 rad so that no case is exactly symmetric. The
// reported time is ns per pair (one call per iteration); the counter "points" is the number of contact points the call returns (the manifold's size).
//
// Cases (shape 0 on top of shape 1):
//   box_box            0.5 m cube on a 1 m cube, faces together (the analytic SAT + clip path, box_box.cpp)
//   box_box_edge       cube rotated 45 deg about two axes, an edge on the other's edge (SAT edge axis)
//   box_plane, sphere_sphere, sphere_box, capsule_capsule (parallel), capsule_box (lying)
//   cylinder_box_cap   cylinder standing on a box (the analytic cap-on-face path, cylinder_box.cpp)
//   cylinder_box_side  cylinder lying on a box (a wheel on a ramp)
//   cylinder_cylinder_cap, cylinder_cylinder_side, cylinder_convex_cap, convex_cylinder_cap,
//   capsule_cylinder, capsule_convex, sphere_convex, convex_convex, convex_box, cylinder_plane
// docs/design.md (collision section, "Contact manifolds for every convex pair") records the before/after table.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <memory>
#include <utility>
#include <vector>

#include <scree/scree.h>

using namespace scree;

namespace {

constexpr Real kPi = 3.14159265358979323846;

ShapeRef cube(Real half) { return std::make_shared<Box>(Vec3(half, half, half)); }

ShapeRef hull(Real half) {
  std::vector<Vec3> p;
  for (int k = 0; k < 8; ++k) p.emplace_back((k & 1) ? half : -half, (k & 2) ? half : -half, (k & 4) ? half : -half);
  return std::make_shared<Convex>(p);
}

/// Axis of a cylinder or capsule (local y) along world z.
Quat upright() { return Quat(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitX())); }
/// Axis along world x (lying).
Quat lying() { return Quat(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitZ())); }
Quat tilt() { return Quat(Eigen::AngleAxis<Real>(0.01, Vec3(1, 1, 0).normalized())); }

/// Shape 0 with its lowest point at z = -1 mm (centre at zc - 1e-3), shape 1 with its top at z = 0.
void runPair(benchmark::State& state, ShapeRef top, Real topHalfHeight, Quat qTop, ShapeRef bottom,
             Real bottomHalfHeight, Quat qBottom) {
  Geometry g0(top), g1(bottom);
  g0.setRotation(tilt() * qTop);
  g0.setPosition(Vec3(0.01, -0.02, topHalfHeight - 1e-3));
  g1.setRotation(qBottom);
  g1.setPosition(Vec3(0, 0, -bottomHalfHeight));
  std::vector<ContactPoint> out;
  out.reserve(16);
  int points = 0;
  for (auto _ : state) {
    out.clear();
    points = collideGeometries(g0, g1, 0.005, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["points"] = points;
}

const Quat I = Quat::Identity();

void BM_box_box(benchmark::State& s) { runPair(s, cube(0.25), 0.25, I, cube(0.5), 0.5, I); }
void BM_box_box_edge(benchmark::State& s) {
  const Quat q = Quat(Eigen::AngleAxis<Real>(kPi / 4, Vec3::UnitX())) * Quat(Eigen::AngleAxis<Real>(kPi / 4, Vec3::UnitY()));
  Geometry g0(cube(0.25)), g1(cube(0.5));
  g1.setPosition(Vec3(0, 0, -0.5));
  // Rotated about x then y: put the lowest vertex/edge 1 mm into the lower box's top face.
  g0.setRotation(q);
  const Vec3 low = std::static_pointer_cast<Box>(g0.getShape())->support(g0.getRotation().inverse() * Vec3(0, 0, -1));
  g0.setPosition(Vec3(0.01, 0.02, -(g0.getRotation() * low).z() - 1e-3));
  std::vector<ContactPoint> out;
  int points = 0;
  for (auto _ : s) {
    out.clear();
    points = collideGeometries(g0, g1, 0.005, out);
    benchmark::DoNotOptimize(out.data());
  }
  s.counters["points"] = points;
}
void BM_box_plane(benchmark::State& s) {
  runPair(s, cube(0.25), 0.25, I, std::make_shared<Plane>(Vec3(0, 0, 1), 0), 0, I);
}
void BM_sphere_sphere(benchmark::State& s) {
  runPair(s, std::make_shared<Sphere>(0.2), 0.2, I, std::make_shared<Sphere>(0.3), 0.3, I);
}
void BM_sphere_box(benchmark::State& s) { runPair(s, std::make_shared<Sphere>(0.2), 0.2, I, cube(0.5), 0.5, I); }
void BM_sphere_convex(benchmark::State& s) { runPair(s, std::make_shared<Sphere>(0.2), 0.2, I, hull(0.5), 0.5, I); }
void BM_capsule_capsule(benchmark::State& s) {
  runPair(s, std::make_shared<Capsule>(0.1, 0.6), 0.1, lying(), std::make_shared<Capsule>(0.1, 0.6), 0.1, lying());
}
void BM_capsule_box(benchmark::State& s) {
  runPair(s, std::make_shared<Capsule>(0.1, 0.6), 0.1, lying(), cube(0.5), 0.5, I);
}
void BM_capsule_convex(benchmark::State& s) {
  runPair(s, std::make_shared<Capsule>(0.1, 0.6), 0.1, lying(), hull(0.5), 0.5, I);
}
void BM_capsule_cylinder(benchmark::State& s) {
  runPair(s, std::make_shared<Capsule>(0.1, 0.6), 0.1, lying(), std::make_shared<Cylinder>(0.4, 0.4), 0.2,
          upright());
}
void BM_cylinder_box_cap(benchmark::State& s) {
  runPair(s, std::make_shared<Cylinder>(0.2, 0.4), 0.2, upright(), cube(0.5), 0.5, I);
}
void BM_cylinder_box_side(benchmark::State& s) {
  runPair(s, std::make_shared<Cylinder>(0.1, 0.2), 0.1, lying(), cube(0.5), 0.5, I);
}
void BM_cylinder_plane(benchmark::State& s) {
  runPair(s, std::make_shared<Cylinder>(0.2, 0.4), 0.2, upright(), std::make_shared<Plane>(Vec3(0, 0, 1), 0), 0, I);
}
void BM_cylinder_cylinder_cap(benchmark::State& s) {
  runPair(s, std::make_shared<Cylinder>(0.2, 0.4), 0.2, upright(), std::make_shared<Cylinder>(0.2, 0.4), 0.2,
          upright());
}
void BM_cylinder_cylinder_side(benchmark::State& s) {
  runPair(s, std::make_shared<Cylinder>(0.1, 0.4), 0.1, lying(), std::make_shared<Cylinder>(0.1, 0.4), 0.1, lying());
}
void BM_cylinder_convex_cap(benchmark::State& s) {
  runPair(s, std::make_shared<Cylinder>(0.2, 0.4), 0.2, upright(), hull(0.5), 0.5, I);
}
void BM_convex_cylinder_cap(benchmark::State& s) {
  runPair(s, hull(0.15), 0.15, I, std::make_shared<Cylinder>(0.2, 0.4), 0.2, upright());
}
void BM_convex_convex(benchmark::State& s) { runPair(s, hull(0.25), 0.25, I, hull(0.5), 0.5, I); }
void BM_convex_box(benchmark::State& s) { runPair(s, hull(0.25), 0.25, I, cube(0.5), 0.5, I); }

}  // namespace

// SCREE_NP_ITERATIONS=N fixes every case's iteration count, so that instruction counts (valgrind --tool=callgrind,
// N = 1 and N = 2001, difference / 2000) compare builds on a loaded machine where wall times do not.
int main(int argc, char** argv) {
  const std::pair<const char*, void (*)(benchmark::State&)> cases[] = {
      {"box_box", BM_box_box},
      {"box_box_edge", BM_box_box_edge},
      {"box_plane", BM_box_plane},
      {"sphere_sphere", BM_sphere_sphere},
      {"sphere_box", BM_sphere_box},
      {"sphere_convex", BM_sphere_convex},
      {"capsule_capsule", BM_capsule_capsule},
      {"capsule_box", BM_capsule_box},
      {"capsule_convex", BM_capsule_convex},
      {"capsule_cylinder", BM_capsule_cylinder},
      {"cylinder_box_cap", BM_cylinder_box_cap},
      {"cylinder_box_side", BM_cylinder_box_side},
      {"cylinder_plane", BM_cylinder_plane},
      {"cylinder_cylinder_cap", BM_cylinder_cylinder_cap},
      {"cylinder_cylinder_side", BM_cylinder_cylinder_side},
      {"cylinder_convex_cap", BM_cylinder_convex_cap},
      {"convex_cylinder_cap", BM_convex_cylinder_cap},
      {"convex_convex", BM_convex_convex},
      {"convex_box", BM_convex_box},
  };
  const char* fixed = std::getenv("SCREE_NP_ITERATIONS");
  for (const auto& [name, fn] : cases) {
    auto* b = benchmark::RegisterBenchmark(name, fn);
    if (fixed) b->Iterations(std::atoll(fixed));
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
