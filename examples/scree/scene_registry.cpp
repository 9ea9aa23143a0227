// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scene_registry.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "scenes/particle_scenes.h"
#include "scenes/scenes.h"
#include "scenes/terrain_dig.h"
#include "scenes/terrain_dozer.h"
#include "scenes/terrain_plate.h"
#include "scenes/terrain_vehicle.h"
#include "scenes/vehicle.h"

#include "demo_granular.h"
#include "demo_suction.h"

namespace scree::cli {

namespace {

using namespace scree::scenes;

void line(const char* name, double value, const char* unit) { std::printf("  %-28s %.6g %s\n", name, value, unit); }
void flag(const char* name, bool value) { std::printf("  %-28s %s\n", name, value ? "yes" : "no"); }

/// A docs/scenes.md scene (a Scene subclass built with its own dt): the time step is overridden afterwards.
template <class S>
SceneRun fromScene(std::shared_ptr<S> s, const BuildOptions& o) {
  if (o.dt > 0) s->sim->setTimeStep(o.dt);
  SceneRun r;
  r.sim = s->sim.get();
  r.step = [p = s.get()] { p->step(); };
  r.owner = s;
  return r;
}

/// The ground and scene material of docs/scenes.md in an otherwise empty simulation (for the demo scenes).
std::shared_ptr<Scene> emptyScene(const std::string& name, Real mu, Real dt) {
  auto s = std::make_shared<Scene>();
  initScene(*s, name, mu, dt, 0);
  addGround(*s);
  return s;
}

std::vector<SceneEntry> makeRegistry() {
  std::vector<SceneEntry> e;
  auto pyramid = [](int rows) {
    return [rows](const BuildOptions& o) {
      auto s = std::make_shared<PyramidScene>(buildPyramid(rows));
      SceneRun r = fromScene(s, o);
      r.printMetrics = [s] {
        const PyramidMetrics m = measurePyramid(*s);
        line("largest displacement", m.maxDisplacement, "m");
        line("top cube height change", m.topDz, "m");
        flag("stands", m.stands);
      };
      return r;
    };
  };
  e.push_back({"pyramid20", "210 unit cubes in a 2-D pyramid, bottom row 20 (docs/scenes.md)", 10.0, pyramid(20)});
  e.push_back({"pyramid40", "820 unit cubes in a 2-D pyramid, bottom row 40 (docs/scenes.md)", 10.0, pyramid(40)});
  e.push_back({"tower10", "ten unit cubes stacked in one column (docs/scenes.md)", 10.0, [](const BuildOptions& o) {
                 auto s = std::make_shared<TowerScene>(buildTower10());
                 SceneRun r = fromScene(s, o);
                 r.printMetrics = [s] {
                   const TowerMetrics m = measureTower(*s);
                   line("top cube horizontal", m.topHorizontal, "m");
                   line("top cube vertical", m.topVertical, "m");
                   line("largest displacement", m.maxDisplacement, "m");
                   flag("every cube within 1 cm", m.maxDisplacement < 0.01);
                 };
                 return r;
               }});
  e.push_back({"mass_ratio", "a 1000 kg cube resting on a 1 kg cube (docs/scenes.md)", 10.0, [](const BuildOptions& o) {
                 auto s = std::make_shared<MassRatioScene>(buildMassRatio());
                 auto obs = std::make_shared<MassRatioObserver>(*s);
                 SceneRun r = fromScene(s, o);
                 r.step = [s, obs] {
                   s->step();
                   obs->observe();
                 };
                 r.printMetrics = [obs] {
                   const MassRatioMetrics m = obs->result();
                   line("heavy cube height error", m.heavyError, "m");
                   line("worst height error", m.heavyErrorWorst, "m");
                   line("overlap at the end", m.overlap, "m");
                   line("worst overlap", m.overlapWorst, "m");
                   flag("light cube squeezed out", m.squeezed);
                 };
                 return r;
               }});
  e.push_back({"chain20", "20 links and a 100 kg ball on ball joints, released horizontally (docs/scenes.md)", 10.0,
               [](const BuildOptions& o) {
                 auto s = std::make_shared<Chain20Scene>(buildChain20());
                 auto obs = std::make_shared<ChainObserver>(*s);
                 SceneRun r = fromScene(s, o);
                 r.step = [s, obs] {
                   s->step();
                   obs->observe();
                 };
                 r.printMetrics = [obs] {
                   const ChainMetrics m = obs->result();
                   line("largest joint separation", m.maxSeparation, "m");
                   line("mean joint separation", m.meanSeparation, "m");
                   line("separation at the end", m.finalSeparation, "m");
                   line("first above 10 cm", m.firstAbove10cm, "s (-1: never)");
                 };
                 return r;
               }});
  e.push_back({"slide", "a cube sliding to rest from 5 m/s, mu 0.3 (docs/scenes.md)", 3.0, [](const BuildOptions& o) {
                 auto s = std::make_shared<SlideScene>(buildSlide());
                 auto obs = std::make_shared<SlideObserver>(*s);
                 SceneRun r = fromScene(s, o);
                 r.step = [s, obs] {
                   s->step();
                   obs->observe();
                 };
                 r.printMetrics = [obs, s] {
                   const SlideMetrics m = obs->result();
                   line("distance", m.distance, "m");
                   line("distance error", m.distanceErr, "(relative to v^2/(2 mu g))");
                   line("stop time", m.stopTime, "s (-1: still moving)");
                   line("stop time error", m.timeErr, "(relative to v/(mu g))");
                 };
                 return r;
               }});
  auto incline = [](Real mu) {
    return [mu](const BuildOptions& o) {
      auto s = std::make_shared<InclineScene>(buildIncline(mu));
      SceneRun r = fromScene(s, o);
      r.printMetrics = [s] {
        const InclineMetrics m = measureIncline(*s);
        line("displacement along the slope", m.displacement, "m");
        line("closed form (2 s)", m.analytic, "m");
        line("error", m.error, m.analytic > 0 ? "(relative)" : "m");
      };
      return r;
    };
  };
  e.push_back({"incline_mu05", "a cube on a 30 degree slope, mu 0.5: slides 1.3143 m in 2 s (docs/scenes.md)", 2.0,
               incline(0.5)});
  e.push_back({"incline_mu06", "a cube on a 30 degree slope, mu 0.6: sticks (docs/scenes.md)", 2.0, incline(0.6)});
  e.push_back({"spheres10k_jitter", "10,000 rigid spheres dropped in a box, jittered lattice (docs/scenes.md)", 3.0,
               [](const BuildOptions& o) {
                 auto s = std::make_shared<SpheresScene>(buildSpheres10kJitter());
                 SceneRun r = fromScene(s, o);
                 r.printMetrics = [s] {
                   const SpheresMetrics m = measureSpheres(*s);
                   line("kinetic energy", m.kineticEnergy, "J");
                   line("largest penetration", m.maxPenetration, "m");
                   line("mean height", m.meanHeight, "m");
                   line("escaped", double(m.escaped), "spheres");
                 };
                 return r;
               }});
  e.push_back({"particles10k", "spheres10k_jitter as 10,000 granular particles (bench/scenes/particle_scenes.h)", 3.0,
               [](const BuildOptions& o) {
                 auto s = std::make_shared<ParticleScene>(buildParticles10kJitter());
                 SceneRun r = fromScene(s, o);
                 r.printMetrics = [s] {
                   const ParticleMetrics m = measureParticles(*s);
                   line("particles", double(m.count), "");
                   line("kinetic energy", m.kineticEnergy, "J");
                   line("largest penetration", m.maxPenetration, "m");
                   line("mean height", m.meanHeight, "m");
                   line("escaped", double(m.escaped), "particles");
                 };
                 return r;
               }});
  e.push_back({"vehicle", "four-wheeled vehicle on TwoBodyTireModel tires over an 8 cm bump at 2 m/s", 4.0,
               [](const BuildOptions& o) {
                 VehicleParams p;
                 p.speed = 2.0;
                 p.bump = true;
                 if (o.dt > 0) p.dt = o.dt;
                 auto s = std::make_shared<VehicleScene>(buildVehicle(p));
                 SceneRun r = fromScene(s, BuildOptions{});
                 auto peak = std::make_shared<Real>(0);
                 r.step = [s, peak] {
                   s->step();
                   for (const auto& t : s->tireModels) *peak = std::max(*peak, t->getRadialDeflection());
                 };
                 r.printMetrics = [s, peak] {
                   line("chassis x", s->chassis->getPosition().x(), "m");
                   line("chassis speed", s->chassis->getVelocity().x(), "m/s (motor target 2)");
                   line("largest radial tire deflection", *peak, "m");
                 };
                 return r;
               }});
  e.push_back({"suction", "suction gripper picks a 4 kg box, carries it 1 m and releases it (demo_suction.h)", 8.0,
               [](const BuildOptions& o) {
                 auto s = emptyScene("suction", 0.5, o.dt > 0 ? o.dt : 1.0 / 60);
                 s->sim->getSolver().setNumIterations(16);  // as scree_demo
                 auto demo = SuctionPickPlace::build(*s->sim, s->material, Vec3::Zero());
                 SceneRun r = fromScene(s, BuildOptions{});
                 r.printMetrics = [demo] {
                   std::printf("  ");
                   demo->printSummary();
                 };
                 r.owner = std::make_shared<std::pair<std::shared_ptr<Scene>, std::shared_ptr<SuctionPickPlace>>>(s, demo);
                 return r;
               }});
  e.push_back({"pile", "granular pile: 2,000 particles (r 3 cm) poured from a nozzle onto the ground (demo_granular.h)",
               20.0, [](const BuildOptions& o) {
                 auto s = emptyScene("pile", 0.5, o.dt > 0 ? o.dt : 1.0 / 60);
                 s->sim->getSolver().setNumIterations(16);  // as scree_demo
                 auto pile = std::make_shared<demo::GranularPile>(*s->sim, s->material);
                 s->sim->add(StepEventListenerRef(pile));
                 // The pile sets this material at its first pour; set now, a recording lists it from the start.
                 s->sim->getGranularBodySystem().setMaterial(pile->getGrainMaterial());
                 SceneRun r = fromScene(s, BuildOptions{});
                 r.printMetrics = [pile] {
                   std::printf("  ");
                   pile->printSummary();
                 };
                 return r;
               }});
  e.push_back({"terrain_vehicle", "the vehicle driving at 2 m/s on a deformable Terrain, 12 m square (demo_terrain.h)",
               5.0, [](const BuildOptions& o) {
                 TerrainVehicleParams p;  // the scree_demo configuration: 0.1 m cells
                 p.resolution = 121;
                 p.size = 12.0;
                 p.offsetX = 2.0;
                 p.vehicle.speed = 2.0;
                 if (o.dt > 0) p.vehicle.dt = o.dt;
                 auto s = std::make_shared<TerrainVehicleScene>(buildTerrainVehicle(p));
                 const Real total0 = s->terrain->getVolumeLedger().total();
                 SceneRun r;
                 r.sim = s->vehicle.sim.get();
                 r.terrains = {s->terrain.get()};
                 r.step = [s] { s->step(); };
                 r.printMetrics = [s, total0, p] {
                   line("chassis x", s->vehicle.chassis->getPosition().x(), "m");
                   line("deepest rut", p.thickness - s->terrain->getHeightField()->getMinHeight(), "m");
                   line("soil ledger drift", (s->terrain->getVolumeLedger().total() - total0) / total0, "(relative)");
                 };
                 r.owner = s;
                 return r;
               }});
  e.push_back({"terrain_plate", "11 x 11 pistons press a Terrain at 20 kPa (bench/scenes/terrain_plate.h)", 2.0,
               [](const BuildOptions& o) {
                 TerrainPlateParams p;
                 if (o.dt > 0) p.dt = o.dt;
                 auto s = std::make_shared<TerrainPlateScene>(buildTerrainPlate(p));
                 SceneRun r = fromScene(s, BuildOptions{});
                 r.terrains = {s->terrain.get()};
                 r.printMetrics = [s] { line("mean inner sinkage", s->meanInnerSinkage(), "m"); };
                 return r;
               }});
  e.push_back({"dig", "a bucket digs a trench in a Terrain, dumps the soil, the heap merges (terrain_dig.h)", 0.0,
               [](const BuildOptions& o) {
                 TerrainDigParams p;
                 if (o.dt > 0) p.dt = o.dt;
                 auto s = std::make_shared<TerrainDigScene>(buildTerrainDig(p));
                 const Real total0 = s->terrain->getVolumeLedger().total();
                 SceneRun r;
                 r.sim = s->sim.get();
                 r.terrains = {s->terrain.get()};
                 r.step = [s] { s->step(); };
                 r.printMetrics = [s, total0] {
                   const size_t k = s->currentPhase();
                   std::printf("  %-28s %s\n", "phase", k < s->phases.size() ? s->phases[k].name.c_str() : "done");
                   line("live particles", double(s->sim->getGranularBodySystem().numParticles()), "");
                   const TerrainShovelStats st = s->terrain->getShovelStats(*s->blade);
                   line("digging force |F|", st.diggingForce().norm(), "N");
                   line("bucket fill", 1e3 * st.fillVolume, "L");
                   line("soil ledger drift", (s->terrain->getVolumeLedger().total() - total0) / total0, "(relative)");
                 };
                 r.owner = s;
                 return r;
               }});
  e.push_back({"dozer", "a 2 m blade pushes soil into a berm that slumps to its angle of repose (terrain_dozer.h)",
               0.0, [](const BuildOptions& o) {
                 TerrainDozerParams p;
                 if (o.dt > 0) p.dt = o.dt;
                 auto s = std::make_shared<TerrainDozerScene>(buildTerrainDozer(p));
                 const Real total0 = s->terrain->getVolumeLedger().total();
                 SceneRun r = fromScene(s, BuildOptions{});
                 r.terrains = {s->terrain.get()};
                 r.printMetrics = [s, total0] {
                   line("blade x", s->blade->getPosition().x(), "m");
                   line("berm height", s->bermHeight(), "m");
                   line("steepest berm slope", s->bermSlope() * 180 / M_PI, "deg");
                   line("soil ledger drift", (s->terrain->getVolumeLedger().total() - total0) / total0, "(relative)");
                 };
                 return r;
               }});
  // The phase-driven terrain scenes last as long as their phases (the phase list of terrain_dig.cpp:
  // lower 0.5 s, dig trenchLength / digSpeed, lift 1 s, dump 1 s, settle; terrain_dozer.h: push, rest).
  for (SceneEntry& s : e) {
    if (s.name == "dig") {
      const TerrainDigParams p;
      s.defaultTime = 0.5 + p.trenchLength / p.digSpeed + 2.0 + p.settleSeconds;
    } else if (s.name == "dozer") {
      const TerrainDozerParams p;
      s.defaultTime = p.pushSeconds + p.restSeconds;
    }
  }
  return e;
}

}  // namespace

const std::vector<SceneEntry>& sceneRegistry() {
  static const std::vector<SceneEntry> registry = makeRegistry();
  return registry;
}

const SceneEntry* findScene(const std::string& name) {
  for (const SceneEntry& e : sceneRegistry())
    if (e.name == name) return &e;
  return nullptr;
}

}  // namespace scree::cli
