// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// VtkExporter::writeFrame cost (scree/io/vtk_export.h). BM_VtkParticles/N: N particles (random in a 1 m cube)
// and the docs/scenes.md ground box; BM_VtkFull adds a 129 x 129 terrain and a 16^3 granular field grid
// (velocity, mass, momentum, kinetic stress) to 10,000 particles. Counters: bytes per frame. Files go to a
// directory under the system temp dir (page cache: this measures building the arrays and the write calls, not
// the disk), removed at the end. SCREE_VTK_BENCH_KEEP=dir keeps the frames there instead (to open in ParaView).
#include <benchmark/benchmark.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <random>

#include "scenes/scenes.h"
#include "scree/io/vtk_export.h"
#include "scree/model/granular_field_post_processor.h"
#include "scree/model/terrain.h"

using namespace scree;
namespace fs = std::filesystem;

namespace {

struct Setup {
  scenes::Scene s;
  TerrainRef terrain;
  std::shared_ptr<GranularFieldPostProcessor> gpp;
  fs::path dir;
  bool keep = false;

  Setup(int n, bool full) {
    scenes::initScene(s, "vtk", 0.5, 1.0 / 60.0, 0);
    scenes::addGround(s);
    auto& gbs = s.sim->getGranularBodySystem();
    gbs.setMaterial(s.material);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<Real> u(-0.5, 0.5), rad(0.004, 0.007), vu(-1, 1);
    for (int i = 0; i < n; ++i)
      gbs.createParticle(Vec3(u(rng), u(rng), 1 + u(rng)), rad(rng), Vec3(vu(rng), vu(rng), vu(rng)));
    if (full) {
      auto hf = std::make_shared<HeightField>(129, 129, 10.0, 10.0);
      terrain = std::make_shared<Terrain>(hf);
      terrain->getGeometry()->setMaterial(s.material);
      s.sim->add(terrain);
      gpp = std::make_shared<GranularFieldPostProcessor>(gbs, GranularFieldPostProcessor::Shape{16, 16, 16},
                                                         Vec3(1.1, 1.1, 1.1));
      gpp->setPosition(Vec3(0, 0, 1));
      gpp->addField(GranularField::VELOCITY);
      gpp->addField(GranularField::KINETIC_STRESS);
      gpp->calculateFields();
    }
    if (const char* k = std::getenv("SCREE_VTK_BENCH_KEEP")) {
      dir = k;
      keep = true;
    } else {
      dir = fs::temp_directory_path() / ("scree_vtk_bench_" + std::to_string(::getpid()));
    }
  }
  ~Setup() {
    if (!keep) {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  }
};

void run(benchmark::State& state, int n, bool full) {
  Setup setup(n, full);
  io::VtkExporter ex(setup.dir.string(), full ? "full" : "particles");
  if (setup.terrain) ex.addTerrain(*setup.terrain);
  if (setup.gpp) ex.addGranularFields(*setup.gpp);
  double t = 0;
  for (auto _ : state) {
    ex.writeFrame(*setup.s.sim, t);
    t += 1.0 / 60.0;
  }
  state.counters["bytes_per_frame"] = double(ex.getLastFrameBytes());
  state.counters["particles"] = n;
}

void BM_VtkParticles(benchmark::State& state) { run(state, int(state.range(0)), false); }
void BM_VtkFull(benchmark::State& state) { run(state, 10000, true); }

}  // namespace

BENCHMARK(BM_VtkParticles)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_VtkFull)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
