// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// terrain_dig_trench: the trench scene of bench/scenes/terrain_dig.h - a kinematic bucket (blade, back plate and
// sides) digs an 8 cm deep, 0.7 m long trench in a Terrain, lifts the soil, dumps it by turning its tip down, and
// the heap merges back into the height field. Prints per phase the particles created and merged, the live
// particles, and the soil-volume ledger (its total stays constant: digging moves soil heightField -> pending ->
// particles -> heightField, it never creates or loses any).
//
//   build/examples/terrain_dig_trench [DIR]   with DIR: after each phase writes DIR/<phase>_surface.dat (x, z of
//   the terrain surface along y = 0), DIR/<phase>_particles.dat (x, z of the particles with |y| < 0.1 m) and
//   DIR/<phase>_bucket.dat (the blade, back plate and a side plate outlines in the x-z plane); docs/terrain/dig.gp
//   plots them.
#include <cmath>
#include <cstdio>
#include <string>

#include "scenes/terrain_dig.h"

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : "";
  using namespace scree;
  scenes::TerrainDigParams params;
  params.steelBucket = true;  // the manual's set-up: a steel bucket registered as an external material
  scenes::TerrainDigScene s = scenes::buildTerrainDig(params);
  Terrain& terrain = *s.terrain;
  const HeightField& hf = *s.field;
  std::printf("blade is a shovel: %s; particle radius %.3g m, volume %.3g m^3\n",
              terrain.isGeometryShovel(s.blade) ? "yes" : "no", terrain.getParticleAttributes().getParticleRadius(),
              terrain.getParticleVolume());
  const Real total0 = terrain.getVolumeLedger().total();
  std::printf("%-7s %8s %8s %6s %12s %12s %12s %12s %10s\n", "phase", "created", "merged", "live", "heightField",
              "pending", "particles", "total", "drift");
  for (size_t k = 0; k < s.phases.size(); ++k) {
    size_t created = 0, merged = 0;
    for (int i = 0; i < s.phaseSteps(k); ++i) {
      s.step();
      created += terrain.getLastStepDigStats().particlesCreated;
      merged += terrain.getLastStepDigStats().particlesMerged;
    }
    const TerrainVolumeLedger& l = terrain.getVolumeLedger();
    const char* name = s.phases[k].name.c_str();
    std::printf("%-7s %8zu %8zu %6zu %12.6f %12.6f %12.6f %12.6f %10.1e\n", name, created, merged,
                s.sim->getGranularBodySystem().numParticles(), l.heightField, l.pending, l.particles, l.total(),
                (l.total() - total0) / total0);
    if (dir.empty()) continue;
    // Side view (x-z plane through y = 0) of this phase's end: surface, particles, bucket.
    const std::string base = dir + "/" + name;
    if (std::FILE* f = std::fopen((base + "_surface.dat").c_str(), "w")) {
      for (size_t i = 0; i < hf.getResolutionX(); ++i) {
        const Vec3 v = terrain.getGeometry()->getTransform().apply(hf.getVertex(i, hf.getResolutionY() / 2));
        std::fprintf(f, "%.4f %.4f\n", v.x(), v.z());
      }
      std::fclose(f);
    }
    if (std::FILE* f = std::fopen((base + "_particles.dat").c_str(), "w")) {
      s.sim->getGranularBodySystem().forEachParticle([&](size_t id) {
        const Vec3 x = s.sim->getGranularBodySystem().getPosition(id);
        if (std::abs(x.y()) < 0.1) std::fprintf(f, "%.4f %.4f\n", x.x(), x.z());
      });
      std::fclose(f);
    }
    if (std::FILE* f = std::fopen((base + "_bucket.dat").c_str(), "w")) {
      for (const GeometryRef& g : s.bucket->getGeometries()) {
        if (g->getName() == "side -y") continue;  // the two sides coincide in this view
        const Vec3 he = static_cast<const Box&>(*g->getShape()).getHalfExtents();
        for (int c = 0; c <= 4; ++c) {
          const Real sx = (c == 1 || c == 2) ? 1 : -1, sz = (c >= 2 && c <= 3) ? 1 : -1;
          const Vec3 p = g->getTransform().apply(Vec3(sx * he.x(), 0, sz * he.z()));
          std::fprintf(f, "%.4f %.4f\n", p.x(), p.z());
        }
        std::fprintf(f, "\n");
      }
      std::fclose(f);
    }
  }
  return 0;
}
